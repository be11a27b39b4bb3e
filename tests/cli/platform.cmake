# GL platforms: the EGL context (VOXLAB_GL=egl) against OSMesa, and a bad VOXLAB_GL value
# (tests/platform/egl_matches_osmesa.sh; skipped only where EGL itself is unavailable).
add_test(NAME platform.egl_matches_osmesa
  COMMAND ${CMAKE_SOURCE_DIR}/tests/platform/egl_matches_osmesa.sh $<TARGET_FILE:voxlab>
          ${CMAKE_BINARY_DIR}/platform-out/egl)
set_tests_properties(platform.egl_matches_osmesa PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77)
