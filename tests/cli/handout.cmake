# Handouts and the gallery (src/handout/handout.h, src/app/cmd_handout.cpp, src/app/cmd_gallery.cpp).
#
# handout.browser: every lesson to HTML at reduced picture size, then headless Chromium checks the
# index and the first handout (tests/cli/handout/browser_check.sh; skipped only without chromium).
add_test(NAME handout.browser
  COMMAND ${CMAKE_SOURCE_DIR}/tests/cli/handout/browser_check.sh $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/browser)
set_tests_properties(handout.browser PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600)

# gallery.cornell_box: the gallery's numbers for every technique at its defaults are docs/fidelity.md's.
add_test(NAME gallery.cornell_box
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/cli/handout/gallery_check.py $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/gallery)
set_tests_properties(gallery.cornell_box PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 600)

# gallery.sponza: the same against docs/fidelity.md's Sponza table. A long check (every technique
# at 512x512 on Sponza: MEASURED here), so it is skipped (exit 77) unless VOXLAB_LONG_CHECKS=1.
add_test(NAME gallery.sponza
  COMMAND sh -c "[ \"$VOXLAB_LONG_CHECKS\" = 1 ] || { echo 'long check: skipped unless VOXLAB_LONG_CHECKS=1'; exit 77; }; exec python3 \"$0\" \"$@\""
          ${CMAKE_SOURCE_DIR}/tests/cli/handout/gallery_check.py $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/gallery-sponza sponza)
set_tests_properties(gallery.sponza PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 3600)

voxlab_cli_case(handout_needs_lesson 2 "handout needs a lesson file \\(voxlab handout LESSON\\.md --out DIR\\) or --all"
  "handout --out @OUT@")
voxlab_cli_case(handout_lesson_and_all 2 "give either --all or a lesson file, not both"
  "handout @ROOT@/lessons/01-voxel-cone-tracing.md --all --out @OUT@")
voxlab_cli_case(handout_missing_lesson 2 "lesson file '.*no-such-lesson\\.md' does not exist"
  "handout @ROOT@/lessons/no-such-lesson.md --out @OUT@")
voxlab_cli_case(handout_invalid_lesson 2 "bad-lesson-stage\\.md:3: .*voxelise.*voxelize"
  "handout @ROOT@/tests/viewer/bad-lesson-stage.md --out @OUT@")
voxlab_cli_case(handout_unrenderable_step 2
  "unrenderable-level\\.md:12: output vct-grid/inject/radiance-injected has levels 0\\.\\.0, not 9"
  "handout @ROOT@/tests/cli/handout/unrenderable-level.md --size 64x64 --out @OUT@")
voxlab_cli_case(handout_bad_size 2 "--size" "handout --all --size 0x5 --out @OUT@")
voxlab_cli_case(gallery_unknown_scene 2 "no-such-scene"
  "gallery --scene no-such-scene --out @OUT@")
voxlab_cli_case(gallery_needs_scene 2 "'gallery' needs --scene"
  "gallery --out @OUT@")

# handout.progress_bar: the bar on a pseudo-terminal, none on a pipe (tests/cli/handout/progress_bar.sh).
add_test(NAME handout.progress_bar
  COMMAND ${CMAKE_SOURCE_DIR}/tests/cli/handout/progress_bar.sh $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/progress)
set_tests_properties(handout.progress_bar PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 120)

# handout.viewer_match: every picture of a lesson's handout is what the viewer's view shows at that
# step (tests/cli/handout/viewer_match.sh under Xvfb; skipped only without xvfb-run), for every
# lesson: a handout picture is the view the output's visualiser draws (the technique's own, e.g.
# lpv's occlusion plates and clipmap's atlas), as in the viewer. Measured on 2 shared cores (load
# average 3 to 5): 01, 06 and 02 took 68 s together, 03 38 s, 04 12 s, 07 19 s; 09 (its steps play
# frames: the handout renders each step's frames, the viewer plays them) 151 s at load average 4 to
# 10, hence the timeout above 900 s.
add_test(NAME handout.viewer_match
  COMMAND ${CMAKE_SOURCE_DIR}/tests/cli/handout/viewer_match.sh $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/viewer_match 01-voxel-cone-tracing 06-near-field 02-voxelization 03-volumetric-light
          04-sparse-voxel-octree 05-light-propagation-volumes 07-layered-reflective-shadow-maps 08-clipmaps
          09-motion)
set_tests_properties(handout.viewer_match PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 1200 RESOURCE_LOCK xvfb)

# handout.sweep: a lesson step's sweep in its handout: the measured errors under the step and the
# sweep's slider page in a frame whose slider works (tests/cli/handout/sweep_check.py; skipped only
# without chromium).
add_test(NAME handout.sweep
  COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/cli/handout/sweep_check.py $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/handout-out/sweep)
set_tests_properties(handout.sweep PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 300)
