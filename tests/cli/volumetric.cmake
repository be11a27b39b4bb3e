# volumetric: out-of-range medium and size parameters are refused before anything is allocated.
voxlab_cli_case(volumetric_anisotropy_one 2 "medium.anisotropy='1' is not valid; valid: -0.99..0.99"
  "run --technique volumetric --set medium.anisotropy=1 --out @OUT@")
voxlab_cli_case(volumetric_too_many_particles 2 "particles.count='5000000' is not valid; valid: 0..4000000"
  "run --technique volumetric --set particles.count=5000000 --out @OUT@")
voxlab_cli_case(volumetric_grid_not_power_of_two 2 "density.resolution='48' is not valid; valid: 8..256 .power of two."
  "run --technique volumetric --set density.resolution=48 --out @OUT@")
voxlab_cli_case(volumetric_too_many_steps 2 "march.steps='300' is not valid; valid: 1..256"
  "run --technique volumetric --set march.steps=300 --out @OUT@")
voxlab_cli_case(volumetric_lesson_check_ok 0 "^$"
  "lesson --check @ROOT@/lessons/03-volumetric-light.md --no-render")

# The ray record as the generic probe shows it: a click sets probe.x/probe.y, the march re-runs
# and the record is checked by its visualiser (src/techniques/volumetric/views/volumetric_ray.cpp).
add_test(NAME viewer.probe_volumetric
  COMMAND ${CMAKE_SOURCE_DIR}/tests/viewer/run_viewer_test.sh $<TARGET_FILE:voxlab>
          ${CMAKE_SOURCE_DIR}/tests/viewer/probe_volumetric.txt ${CMAKE_BINARY_DIR}/viewer-out/probe_volumetric)
set_tests_properties(viewer.probe_volumetric PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK xvfb)
