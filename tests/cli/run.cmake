# voxlab run/list/bench: bad arguments give one line naming what is wrong and what is valid, exit 2.
voxlab_cli_case(run_unknown_technique 2 "unknown technique 'vct-nope'; valid techniques: .*vct-grid"
  "run --technique vct-nope --out @OUT@")
voxlab_cli_case(run_unknown_stage 2 "no stage 'shade'; valid stages: voxelize-static, voxelize, triangle-axes, light, shadow-map, inject, occlusion-fix, mipmap, bounce, gbuffer, cone-trace, composite"
  "run --technique vct-grid --until shade --out @OUT@")
voxlab_cli_case(run_bounces_out_of_range 2 "bounces=.4. is not valid; valid: 1..3"
  "run --technique vct-grid --set bounces=4 --out @OUT@")
voxlab_cli_case(run_half_float_voxels_with_compare_and_swap 2 "inject.average=compare-and-swap needs voxel.format=rgba8"
  "run --technique vct-grid --set voxel.format=rgba16f --set inject.average=compare-and-swap --set voxel.resolution=32 --size 64x64 --out @OUT@")
voxlab_cli_case(run_unknown_parameter 2 "unknown parameter 'voxel.size'; valid parameters: .*voxel.resolution"
  "run --technique vct-grid --set voxel.size=3 --out @OUT@")
voxlab_cli_case(run_parameter_out_of_range 2 "voxel.resolution=.1024. is not valid; valid: 16..512 .power of two."
  "run --technique vct-grid --set voxel.resolution=1024 --out @OUT@")
voxlab_cli_case(run_parameter_not_power_of_two 2 "voxel.resolution=.100. is not valid; valid: 16..512 .power of two."
  "run --technique vct-grid --set voxel.resolution=100 --out @OUT@")
voxlab_cli_case(run_parameter_bad_choice 2 "mipmap.mode='fancy' is not valid; valid: one of isotropic, anisotropic"
  "run --technique vct-grid --set mipmap.mode=fancy --out @OUT@")
voxlab_cli_case(run_set_without_value 2 "--set 'voxel.resolution' is not NAME=VALUE"
  "run --technique vct-grid --set voxel.resolution --out @OUT@")
voxlab_cli_case(run_bad_size 2 "--size '512' is not WIDTHxHEIGHT"
  "run --technique vct-grid --size 512 --out @OUT@")
voxlab_cli_case(run_unknown_option 2 "'run' has no option '--frobnicate'; valid options: .*--technique"
  "run --technique vct-grid --frobnicate --out @OUT@")
voxlab_cli_case(run_missing_out 2 "'run' needs --out" "run --technique vct-grid")
voxlab_cli_case(run_bad_camera 2 "camera 7 does not exist in cornell-box; valid: 0..0"
  "run --technique vct-grid --camera 7 --out @OUT@")
voxlab_cli_case(unknown_command 2 "unknown command 'frobnicate'; valid commands: .*run" "frobnicate")
voxlab_cli_case(bench_unknown_technique 2 "unknown technique 'nope'" "bench --technique nope --process-runs 0")
# bench --frames: a moving object (the scene's animation) re-runs the moving triangles'
# voxelization first, never the still ones' (voxelize-static); a light move starts at the light
# stage (voxelize and the G-buffer do not read the light); a camera move voxelizes nothing.
voxlab_cli_case_output(bench_frames 0 "^$"
  "bench --technique vct-grid --scene cornell-box-moving --set voxel.resolution=16 --size 16x16 --runs 1 --process-runs 0 --frames 2"
  "[|] light move [|] light.0.azimuth turned by 2 degrees a frame [|] light, shadow-map, inject.*[|] camera move [|] [^|]* [|] triangle-axes, gbuffer, cone-trace, composite [|].*[|] moving object [|] the scene's animation played over the frames [|] voxelize, triangle-axes, shadow-map"
  "" 0 "" "")
voxlab_cli_case(run_only_bad_address 2 "output address 'mipmap/radiance' is not technique/stage/output"
  "run --technique vct-grid --only mipmap/radiance --out @OUT@")
voxlab_cli_case(run_only_unknown_output 2 "vct-grid/mipmap has no output 'glow'; valid outputs: radiance, opacity"
  "run --technique vct-grid --only vct-grid/mipmap/glow --out @OUT@")
voxlab_cli_case(run_only_after_until 2 "--only vct-grid/mipmap/radiance is after --until inject"
  "run --technique vct-grid --until inject --only vct-grid/mipmap/radiance --out @OUT@")
voxlab_cli_case(run_only_level_out_of_range 2 "output vct-grid/mipmap/radiance has levels 0..4, not 9"
  "run --technique vct-grid --until mipmap --set voxel.resolution=16 --only vct-grid/mipmap/radiance@9 --out @OUT@")
voxlab_cli_case(run_look_from_alone 2 "--look-from and --look-at go together; give both or neither"
  "run --technique vct-grid --look-from 0,1,3 --out @OUT@")
voxlab_cli_case(run_look_at_bad_vector 2 "--look-at '0,1' is not three numbers X,Y,Z"
  "run --technique vct-grid --look-from 0,1,3 --look-at 0,1 --out @OUT@")
voxlab_cli_case(run_look_from_equals_look_at 2 "--look-from and --look-at are the same point"
  "run --technique vct-grid --look-from 0,1,3 --look-at 0,1,3 --out @OUT@")
# A run that changes the scene's physics (light.0.*, sky.radiance: parameters declared
# groundTruth()) is not compared with the reference images, which are of the default; it says so.
voxlab_cli_case_output(run_physics_changed_skips_references 0 ""
  "run --technique vct-grid --set voxel.resolution=32 --set sky.radiance=0.5 --only vct-grid/cone-trace/indirect-diffuse --out @OUT@"
  "not compared with the reference images: the run sets sky.radiance=0.5; the references are of the scene's own light and sky"
  "@OUT@/manifest.json" 0 "" "")
# A reference mode that follows a parameter (voxel-path-tracing's indirect-{paths.bounces}) whose
# image the scene does not store (the Cornell box has indirect-1 and indirect-2, not indirect-7):
# the output is not compared with another mode, and the run says so in one line.
voxlab_cli_case_output(run_reference_mode_missing 0 ""
  "run --technique voxel-path-tracing --set voxel.resolution=64 --set paths.count=1 --set paths.bounces=7 --size 64x64 --only voxel-path-tracing/paths/indirect --out @OUT@"
  "voxel-path-tracing/paths/indirect not compared: no reference image of mode indirect-7 \\(tests/golden/reference/cornell-box/indirect-7.exr\\); make it with voxlab reference --mode indirect-7"
  "@OUT@/manifest.json" 0 "" "")

# voxlab run --frames / --animate (run/frames.h): bad input is one line and exit 2; a run of frames
# re-runs per frame only the stages its change invalidates, and measures the change
# (tests/cli/frames/frames_check.py).
voxlab_cli_case(run_animate_without_frames 2 "--animate needs --frames N"
  "run --technique vct-grid --animate light.0.azimuth=0:90 --out @OUT@")
voxlab_cli_case(run_animate_bad_form 2 "--animate 'light.0.azimuth': expected NAME=FROM:TO"
  "run --technique vct-grid --frames 2 --animate light.0.azimuth --out @OUT@")
voxlab_cli_case(run_animate_unknown_parameter 2 "unknown parameter 'light.9.azimuth'; valid parameters: .*light.0.azimuth"
  "run --technique vct-grid --frames 2 --animate light.9.azimuth=0:90 --out @OUT@")
voxlab_cli_case(run_animate_choice 2 "--animate mipmap.mode: a choice .one of isotropic, anisotropic.*. cannot be animated; valid: a number parameter"
  "run --technique vct-grid --frames 2 --animate mipmap.mode=0:1 --out @OUT@")
voxlab_cli_case(run_animate_out_of_range 2 "light.0.elevation=120 is out of range; valid: -90..90"
  "run --technique vct-grid --frames 2 --animate light.0.elevation=0:120 --out @OUT@")
voxlab_cli_case(run_frames_out_of_range 2 "--frames.*1..1000"
  "run --technique vct-grid --frames 0 --out @OUT@")
voxlab_cli_case(run_time_range_without_frames 2 "--time-range needs --frames N"
  "run --technique vct-grid --scene cornell-box-moving --time-range 0:1 --out @OUT@")
voxlab_cli_case(run_time_range_bad_form 2 "--time-range '1': expected FROM:TO in seconds"
  "run --technique vct-grid --scene cornell-box-moving --frames 2 --time-range 1 --out @OUT@")
voxlab_cli_case(run_time_range_still_scene 2 "--time-range: scene 'cornell-box' has no animation"
  "run --technique vct-grid --frames 2 --time-range 0:1 --size 16x16 --out @OUT@")
add_test(NAME cli.run_frames
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/cli/frames/frames_check.py $<TARGET_FILE:voxlab> ${CMAKE_BINARY_DIR}/cli-out/run_frames)
set_tests_properties(cli.run_frames PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}")
