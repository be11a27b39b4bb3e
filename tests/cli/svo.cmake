# svo: a deliberately undersized node pool stops the build with one line naming the pool and the size it needs.
voxlab_cli_case(svo_node_pool_overflow 2 "svo-build: node pool overflow at level 1: it holds 4 nodes, the level needs 9" "run --technique svo --set voxel.resolution=16 --set svo.node-pool-fraction=0.5 --final-only --out @OUT@")
# The budget passes the estimate (pools at their starting size) but the pools sized from the scene's
# counts do not fit: the blackboard stops the run with one line naming the resource (at 256^3 on the
# Cornell box the estimate is 198 MiB; a --final-only run allocates no dense views, and the
# directional bricks sized from the counts take it to 251 MiB).
voxlab_cli_case(svo_pool_past_memory_budget 2 "svo-directional-bricks needs [0-9]+ MiB, which takes the run's GPU resources to [0-9]+ MiB, over gpu.memory-budget=220 MiB \\(sized from the scene's counts"
  "run --technique svo --set voxel.resolution=256 --set gpu.memory-budget=220 --final-only --out @OUT@")
