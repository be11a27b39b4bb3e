# voxlab fidelity (src/app/cmd_fidelity.cpp): bad input gets one line and exit 2; a band that a
# number misses gets exit 1 and a line naming the number; the whole suite at reduced size against
# tests/fidelity/bands.json, with its page checked in headless Chromium (fidelity.suite, run once,
# in the second ctest pass, and not in the sanitized one: scripts/test.sh).
voxlab_cli_case(fidelity_needs_out 2 "'fidelity' needs --out" "fidelity --scene cornell-box")
voxlab_cli_case(fidelity_unknown_scene 2 "unknown scene 'no-such-scene'" "fidelity --scene no-such-scene --out @OUT@")
voxlab_cli_case(fidelity_unknown_technique 2 "unknown technique 'vct-nope'; valid techniques: .*vct-grid"
  "fidelity --technique vct-nope --out @OUT@")
voxlab_cli_case(fidelity_set_nobody_declares 2
  "--set voxel.size=3: no technique of this run declares voxel.size"
  "fidelity --technique vct-grid --set voxel.size=3 --out @OUT@")
voxlab_cli_case(fidelity_bad_bands 2 "--check: .*bad-bands.json band 1: output 'glow' is not valid; valid: direct, indirect, full"
  "fidelity --technique vct-grid --check @ROOT@/tests/fidelity/bad-bands.json --out @OUT@")
# A band no run can meet (the direct light at most half the reference's): exit 1, the number named.
voxlab_cli_case(fidelity_number_outside_band 1
  "vct-grid on cornell-box: direct \\(vct-grid/composite/direct, direct\\) mean_ratio [0-9.]+ outside \\[0, 0\\.5\\]"
  "fidelity --technique vct-grid --scene cornell-box --size 64x64 --set voxel.resolution=32 --check @ROOT@/tests/fidelity/unmeetable-band.json --out @OUT@")

add_test(NAME fidelity.suite
  COMMAND ${CMAKE_SOURCE_DIR}/tests/fidelity/check_suite.sh $<TARGET_FILE:voxlab> ${CMAKE_SOURCE_DIR}
          ${CMAKE_BINARY_DIR}/fidelity-out/suite)
set_tests_properties(fidelity.suite PROPERTIES
  ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" SKIP_RETURN_CODE 77 TIMEOUT 1500 COST 1000)

# fidelity --frames: the animated scene over two frames against the path tracer's animation at
# the same size; writes the flicker table (fidelity.md, fidelity.json).
voxlab_cli_case_output(fidelity_frames 0 "^$"
  "fidelity --frames 2 --scene cornell-box-moving --technique lrsm --size 16x16 --reference-spp 2 --out @OUT@"
  "1 techniques x 1 animated scenes, 2 frames each" "@OUT@/fidelity.md;@OUT@/fidelity.json" 0 "" "")
