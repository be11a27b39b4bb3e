# clipmap: the shaders hold cells in int32, so a level origin beyond 2^30 cells of the world origin
# is refused with one line (exit 2) before any voxel is written: a camera far away (2e7 m at 1 cm
# voxels: 2e9 cells), and a path that ends far away (one move of 1e6 m at 0.1 mm voxels: 1e10 cells).
voxlab_cli_case(clipmap_far_camera_refused 2 "clipmap: a level origin .* lies beyond 2.30 cells of the world origin; move the camera .or the path. closer, or raise clipmap.voxel-size" "run --technique clipmap --look-from 2e7,0.27,0 --look-at 2e7,0.27,1 --set clipmap.voxel-size=0.01 --final-only --out @OUT@")
voxlab_cli_case(clipmap_far_path_refused 2 "clipmap: a level origin .* lies beyond 2.30 cells of the world origin" "run --technique clipmap --set clipmap.voxel-size=0.0001 --set clipmap.path-moves=1 --set clipmap.path-step.x=1e6 --final-only --out @OUT@")
# Accumulator overflow is detected and reported, never silent: each fragment adds its light times
# 2^b to a cell's 32-bit fixed-point sums (b = clipmap.fixed-point-bits), and the voxelizer counts
# every addition that wraps a sum (the update stage says so in one line and in the statistic
# accumulator_overflows). Only real wraps count: a crowded cell whose light fits is not reported
# (Sponza's default run used to warn about its 2 cells of 4,096 fragments or more, whose sums were
# far from 2^32). On the Cornell box with 2 levels of 8^3 (a fast run), b = 30 leaves 4 W/(m^2 sr)
# per sum, which the cells by the lamp pass: 14 wraps (measured 2026-12-06); b = 26 and below, none.
voxlab_cli_case_output(clipmap_accumulator_overflow_reported 0
  "^voxlab warning: clipmap/update: [1-9][0-9]* fixed-point light sums overflowed 32 bits .clipmap.fixed-point-bits=30.; lower clipmap.fixed-point-bits, or clipmap.voxel-size so that fewer triangles share a cell$"
  "run --technique clipmap --set clipmap.fixed-point-bits=30 --set clipmap.resolution=8 --set clipmap.levels=2 --size 32x32 --final-only --out @OUT@"
  "" "@OUT@/manifest.json" 0 "" "")
voxlab_cli_case_output(clipmap_accumulator_no_overflow_at_default 0 "^$"
  "run --technique clipmap --set clipmap.resolution=8 --set clipmap.levels=2 --size 32x32 --final-only --out @OUT@"
  "" "@OUT@/manifest.json" 0 "" "")
voxlab_cli_case(clipmap_fixed_point_bits_out_of_range 2 "clipmap.fixed-point-bits='31' is not valid; valid: 8..30"
  "run --technique clipmap --set clipmap.fixed-point-bits=31 --final-only --out @OUT@")
# clipmap.path-step is a vector parameter (ParamSet::parseText): X,Y,Z sets its three components,
# as in `voxlab run --look-from P --set clipmap.path-step=D --set clipmap.path-moves=K`;
# a wrong count or a bad component is one line naming the form, exit 2.
voxlab_cli_case_output(clipmap_path_step_as_one_parameter 0 "^$"
  "run --technique clipmap --look-from 0.1,1,3 --look-at 0.1,1,0 --set clipmap.path-step=0.25,0,-0.5 --set clipmap.path-moves=2 --set clipmap.resolution=8 --set clipmap.levels=2 --until anchor --out @OUT@"
  "" "@OUT@/manifest.json" 0 "" "")
voxlab_cli_case(clipmap_path_step_two_values 2 "parameter clipmap.path-step='1,2' has 2 values; valid: three comma-separated values X,Y,Z .e.g. clipmap.path-step=1.5,0,-2. for clipmap.path-step.x/.y/.z, each -1e.06..1e.06 m"
  "run --technique clipmap --set clipmap.path-step=1,2 --final-only --out @OUT@")
voxlab_cli_case(clipmap_path_step_not_a_number 2 "parameter clipmap.path-step='1,north,0': 'north' is not a valid clipmap.path-step.y; valid: three comma-separated values X,Y,Z"
  "bench --technique clipmap --set clipmap.path-step=1,north,0 --process-runs 0")
