# The resource budget through the command line (src/graph/resource_budget.h): a run that does
# not fit gpu.memory-budget exits 2 with one line naming the parameter and the largest value that
# fits, before any stage allocates; the budget itself is range-checked like every parameter.
# 6.2 GiB at 512^3: the dense volumes and their mips, the fragment lists (the still triangles'
# list is kept apart from the merged one) and the injection's slot per voxel.
voxlab_cli_case(budget_refuses_resolution_512 2 "needs 6\\.2 GiB of GPU memory, over gpu\\.memory-budget=1024 MiB; voxel\\.resolution=512 is too large, the largest voxel\\.resolution that fits is 256"
  "run --technique vct-grid --set voxel.resolution=512 --set gpu.memory-budget=1024 --out @OUT@")
voxlab_cli_case(budget_out_of_range 2 "gpu\\.memory-budget.*64\\.\\.1048576"
  "run --technique vct-grid --set gpu.memory-budget=1 --out @OUT@")
