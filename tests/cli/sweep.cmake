# voxlab sweep (src/app/cmd_sweep.cpp): bad input gets one line naming what is wrong and what is
# valid, exit 2, before anything runs; a small sweep writes sweep.json, the plots and sweep.html;
# every technique of `voxlab list --json` swept over one parameter (tests/sweep/every_technique.py);
# sweep.html's slider in headless Chromium (tests/sweep/browser_check.py); the progress bar on a
# terminal, and a refused sweep writing nothing (tests/sweep/progress_and_refusal.sh).
voxlab_cli_case(sweep_needs_param 2 "'sweep' needs one or two --param NAME=V1,V2,\\.\\.\\. \\(or NAME=FROM:TO:STEPS\\); got 0"
  "sweep --technique vct-grid --out @OUT@")
voxlab_cli_case(sweep_unknown_param 2 "--param: unknown parameter 'cone.nope'; valid parameters: .*cone\\.aperture"
  "sweep --technique vct-grid --param cone.nope=1,2 --out @OUT@")
voxlab_cli_case(sweep_value_out_of_range 2
  "--param cone.aperture=30,500: parameter cone.aperture='500' is not valid; valid: 5\\.\\.120"
  "sweep --technique vct-grid --param cone.aperture=30,500 --out @OUT@")
voxlab_cli_case(sweep_malformed_range 2 "--param cone.aperture=30:60: a range is FROM:TO:STEPS with STEPS an integer 2\\.\\.64"
  "sweep --technique vct-grid --param cone.aperture=30:60 --out @OUT@")
voxlab_cli_case(sweep_range_bad_steps 2 "--param cone.aperture=30:60:x: STEPS 'x' is not an integer 2\\.\\.64"
  "sweep --technique vct-grid --param cone.aperture=30:60:x --out @OUT@")
voxlab_cli_case(sweep_range_repeats 2
  "--param voxel.resolution=16:64:5: 5 steps from 16 to 64 repeat values \\(voxel.resolution is 16\\.\\.512 \\(power of two\\)\\)"
  "sweep --technique vct-grid --param voxel.resolution=16:64:5 --out @OUT@")
voxlab_cli_case(sweep_range_of_choice 2 "--param cone.layout=a:b:2: cone.layout is a choice \\(valid: one of .*\\); a range needs"
  "sweep --technique vct-grid --param cone.layout=a:b:2 --out @OUT@")
voxlab_cli_case(sweep_set_of_swept 2 "--set cone.aperture=40: cone.aperture is the swept parameter \\(--param\\); drop one of them"
  "sweep --technique vct-grid --param cone.aperture=30,60 --set cone.aperture=40 --out @OUT@")
voxlab_cli_case(sweep_bad_error 2 "--error 'psnr' is not valid; valid: ssim \\(1 - SSIM\\), energy"
  "sweep --technique vct-grid --param cone.aperture=30,60 --error psnr --out @OUT@")
voxlab_cli_case(sweep_bad_repeat 2 "--repeat '0' is not an integer in 1\\.\\.15"
  "sweep --technique vct-grid --param cone.aperture=30,60 --repeat 0 --out @OUT@")
# A reduced sweep (64x64, a 32^3 grid; about a second): the files, then sweep.json holds three runs.
voxlab_cli_case_output(sweep_small 0 ""
  "sweep --technique vct-grid --scene cornell-box --param cone.aperture=30,45,60 --set voxel.resolution=32 --size 64x64 --out @OUT@"
  "3 runs in .*error = 1 - SSIM of vct-grid/cone-trace/indirect-diffuse"
  "@OUT@/sweep.json|@OUT@/sweep.html|@OUT@/error-by-value.svg|@OUT@/time-by-value.svg|@OUT@/error-by-time.svg|@OUT@/runs/02/composite.final.png|@OUT@/reference/indirect-1.png"
  0 "" "")

add_test(NAME sweep.every_technique
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/sweep/every_technique.py $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/sweep-out/every-technique)
set_tests_properties(sweep.every_technique PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 600)
add_test(NAME sweep.browser
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/sweep/browser_check.py $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/sweep-out/browser)
set_tests_properties(sweep.browser PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600)
add_test(NAME sweep.progress_and_refusal
  COMMAND ${CMAKE_SOURCE_DIR}/tests/sweep/progress_and_refusal.sh $<TARGET_FILE:voxlab> ${CMAKE_BINARY_DIR}/sweep-out/progress)
set_tests_properties(sweep.progress_and_refusal PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 120)
