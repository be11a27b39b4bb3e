# voxlab figure (src/app/cmd_figure.cpp, src/inspect/figure.h): bad input is one line naming what is
# valid, exit 2; good input writes a labelled SVG whose title, notes, pictures, captions and colour
# bar are checked (tests/figure/figure_check.py).
voxlab_cli_case(figure_not_svg 2 "--out '.*x\\.png': a figure is written as SVG; valid: a path ending in \\.svg"
  "figure --technique vct-grid --out @OUT@/x.png")
voxlab_cli_case(figure_unknown_output 2 "vct-grid/cone-trace has no output 'nope'; valid outputs: indirect-diffuse"
  "figure --technique vct-grid --output cone-trace/nope --out @OUT@/x.svg")
voxlab_cli_case(figure_unknown_technique 2 "no-such.*valid.*vct-grid"
  "figure --technique no-such --out @OUT@/x.svg")
voxlab_cli_case(figure_bad_width 2 "--width '10' is not an integer in 64\\.\\.4096"
  "figure --technique vct-grid --width 10 --out @OUT@/x.svg")
voxlab_cli_case(figure_bad_exposure 2 "--exposure 'bright' is not valid; valid: a number above 0"
  "figure --technique vct-grid --exposure bright --out @OUT@/x.svg")
voxlab_cli_case(figure_missing_level 2 "output vct-grid/inject/radiance-injected has levels 0\\.\\.0, not 3"
  "figure --technique vct-grid --set voxel.resolution=32 --size 64x64 --output inject/radiance-injected@3 --out @OUT@/x.svg")

add_test(NAME figure.labelled_svg
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/figure/figure_check.py $<TARGET_FILE:voxlab> ${CMAKE_BINARY_DIR}/figure-out)
set_tests_properties(figure.labelled_svg PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 300)
