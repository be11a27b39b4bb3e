# clipmap: the shaders hold cells in int32, so a level origin beyond 2^30 cells of the world origin
# is refused with one line (exit 2) before any voxel is written: a camera far away (2e7 m at 1 cm
# voxels: 2e9 cells), and a path that ends far away (one move of 1e6 m at 0.1 mm voxels: 1e10 cells).
voxlab_cli_case(clipmap_far_camera_refused 2 "clipmap: a level origin .* lies beyond 2.30 cells of the world origin; move the camera .or the path. closer, or raise clipmap.voxel-size" "run --technique clipmap --look-from 2e7,0.27,0 --look-at 2e7,0.27,1 --set clipmap.voxel-size=0.01 --final-only --out @OUT@")
voxlab_cli_case(clipmap_far_path_refused 2 "clipmap: a level origin .* lies beyond 2.30 cells of the world origin" "run --technique clipmap --set clipmap.voxel-size=0.0001 --set clipmap.path-moves=1 --set clipmap.path-step.x=1e6 --final-only --out @OUT@")
