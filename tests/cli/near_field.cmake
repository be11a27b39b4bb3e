# near-field and lrsm: their lessons validate against the declarations (`voxlab lesson --check`),
# and near-field's probe records reach the generic probe (tests/viewer/probe_near_field.txt).
voxlab_cli_case(near_field_lesson_check_ok 0 "^$"
  "lesson --check @ROOT@/lessons/06-near-field.md --no-render")
voxlab_cli_case(lrsm_lesson_check_ok 0 "^$"
  "lesson --check @ROOT@/lessons/07-layered-reflective-shadow-maps.md --no-render")

add_test(NAME viewer.probe_near_field
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/probe_near_field.txt ${CMAKE_BINARY_DIR}/viewer-out/probe_near_field)
set_tests_properties(viewer.probe_near_field PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)
