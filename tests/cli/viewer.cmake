# Viewer tests: scripted runs of `voxlab view` under Xvfb (tests/viewer/*.txt, driven by
# tests/viewer/run_viewer_test.sh; skipped only when xvfb-run is missing), plus command-line
# cases for bad scripts and lessons, which fail before any window opens.
foreach(script walk_stages every_lesson probe probe_lrsm probe_lpv probe_chain_vct_grid probe_chain_svo probe_chain_lrsm
               probe_chain_lpv probe_chain_near_field probe_chain_clipmap on_demand lesson lesson_near_field lesson_volumetric lesson_light scene_error view3d camera_overlay presenter presenter_taps presenter_probe light clipmap_fly clipmap_sponza_fly bounces
               budget_gl_log soak lesson_sweep frames)
  add_test(NAME viewer.${script}
    COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
            ${CMAKE_SOURCE_DIR}/tests/viewer/${script}.txt ${CMAKE_BINARY_DIR}/viewer-out/${script})
  set_tests_properties(viewer.${script} PROPERTIES
    ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)
endforeach()

voxlab_cli_case(view_script_unknown_action 2 "bad_verb\\.txt:2: unknown action 'frobnicate'; valid: technique"
  "view --script @ROOT@/tests/viewer/bad_verb.txt")
voxlab_cli_case(view_bad_ui_scale 2 "--ui-scale '9' is not a number in 0.75..3"
  "view --ui-scale 9 --script @ROOT@/tests/viewer/probe.txt")
voxlab_cli_case(view_script_missing 2 "script file '.*no-such-script\\.txt' does not exist"
  "view --script @ROOT@/tests/viewer/no-such-script.txt")
voxlab_cli_case(lesson_check_ok 0 "^$"
  "lesson --check @ROOT@/lessons/01-voxel-cone-tracing.md --no-render")
voxlab_cli_case(lesson_check_voxelization_ok 0 "^$"
  "lesson --check @ROOT@/lessons/02-voxelization.md --no-render")
voxlab_cli_case(lesson_unknown_param 2 "bad-lesson-param\\.md:9: unknown parameter 'mipmap\\.no-such-knob'|bad-lesson-param\\.md:9: .*mipmap\\.no-such-knob"
  "lesson --check @ROOT@/tests/viewer/bad-lesson-param.md")
voxlab_cli_case(lesson_unknown_stage 2 "bad-lesson-stage\\.md:3: .*voxelise.*voxelize"
  "lesson --check @ROOT@/tests/viewer/bad-lesson-stage.md")

# The compare view on the final image against the Cornell reference: run_viewer_test.sh checks that
# the RMSE the viewer reports equals `voxlab compare`'s on the same files.
add_test(NAME viewer.compare
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/compare.txt ${CMAKE_BINARY_DIR}/viewer-out/compare)
set_tests_properties(viewer.compare PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)

# Test-only plug-ins: a technique with a volume-space probe and visualisers for test-only
# semantics (tests/viewer/plugins/), linked into a test build of the viewer only; the shipped
# voxlab, `voxlab list`, the snapshot suite and walk_stages never see them.
file(GLOB VOXLAB_TEST_PLUGIN_SOURCES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/viewer/plugins/*.cpp)
add_executable(voxlab_test_viewer ${CMAKE_SOURCE_DIR}/src/app/main.cpp ${VOXLAB_TEST_PLUGIN_SOURCES})
target_link_libraries(voxlab_test_viewer PRIVATE voxlab_core)
add_test(NAME viewer.plugins
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab_test_viewer>
          ${CMAKE_SOURCE_DIR}/tests/viewer/plugins.txt ${CMAKE_BINARY_DIR}/viewer-out/plugins)
set_tests_properties(viewer.plugins PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)

# Lesson 05 (lpv) played to its end, propagation stepped one iteration at a time.
add_test(NAME viewer.lesson_lpv
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/lesson_lpv.txt ${CMAKE_BINARY_DIR}/viewer-out/lesson_lpv)
set_tests_properties(viewer.lesson_lpv PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)

# Lesson 08 (clipmap) played to its end, the update stage stopped after its first and second move.
add_test(NAME viewer.lesson_clipmap
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/lesson_clipmap.txt ${CMAKE_BINARY_DIR}/viewer-out/lesson_clipmap)
set_tests_properties(viewer.lesson_clipmap PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)

# Scripts whose checks must fail on a deliberately wrong input (tests/viewer/failing/*.txt, each
# with its expected message): an image pair one pixel apart, a flat 3D view (exposure 0), a word
# that does not parse as its verb's argument (the line names the usage).
add_test(NAME viewer.failing_checks
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/failing ${CMAKE_BINARY_DIR}/viewer-out/failing)
set_tests_properties(viewer.failing_checks PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 300 RESOURCE_LOCK xvfb)
