# Command-line cases for 'voxlab reference' and 'voxlab compare' (see tests/cli_cases.cmake).
# tests/data/reference/: constant float EXRs, grey50_4x4 (0.5), grey25_4x4 (0.25), grey50_4x3.
set(_refdata "@ROOT@/tests/data/reference")
voxlab_cli_case(reference_unknown_mode 2 "unknown mode 'fancy'; valid modes: full, direct, one-bounce, two-bounce, indirect, indirect-K \\(K = 1..8: K indirect bounces\\), ao"
  "reference --scene cornell-box --spp 1 --mode fancy --out @OUT@/x.exr")
# indirect-K exists for K = 1..8 only: one past the range, zero and a leading zero are refused alike.
voxlab_cli_case(reference_indirect_bounces_range 2 "unknown mode 'indirect-9'; valid modes: .*indirect-K \\(K = 1..8"
  "reference --scene cornell-box --spp 1 --mode indirect-9 --out @OUT@/x.exr")
voxlab_cli_case(reference_indirect_bounces_zero 2 "unknown mode 'indirect-0'; valid modes: "
  "reference --scene cornell-box --spp 1 --mode indirect-0 --out @OUT@/x.exr")
voxlab_cli_case(reference_spp_range 2 "--spp '0' is not an integer in 1..1000000"
  "reference --scene cornell-box --spp 0 --out @OUT@/x.exr")
voxlab_cli_case(reference_unknown_camera 2 "has no camera 'nope'; its cameras: "
  "reference --scene cornell-box --spp 1 --camera nope --out @OUT@/x.exr")
voxlab_cli_case(reference_out_not_exr 2 "--out '.*x.png' must end in .exr"
  "reference --scene cornell-box --spp 1 --out @OUT@/x.png")
voxlab_cli_case(reference_ao_radius_needs_ao 2 "--ao-radius only applies to --mode ao"
  "reference --scene cornell-box --spp 1 --ao-radius 0.5 --out @OUT@/x.exr")
# A tiny render: it reports what it wrote, and the file is an 8x6 EXR (compare reads it and names
# its size when refusing a 4x4 partner).
voxlab_cli_case_output(reference_tiny_render 0 "^$"
  "reference --scene cornell-box --size 8x6 --spp 2 --quiet --out @OUT@/tiny.exr"
  "wrote [^\n]*tiny\\.exr \\(8x6, 2 spp, mode full, camera 'camera'\\)"
  "@OUT@/tiny.exr|@OUT@/tiny.stderr.exr"
  2 "image sizes differ: A is 8x6, B is 4x4"
  "compare @OUT@/tiny.exr ${_refdata}/grey50_4x4.exr")
voxlab_cli_case(compare_size_mismatch 2 "image sizes differ: A is 4x4, B is 4x3"
  "compare ${_refdata}/grey50_4x4.exr ${_refdata}/grey50_4x3.exr")
voxlab_cli_case(compare_unknown_metric 2 "unknown metric 'l2'; valid metrics: rmse, mae, mre, max_abs, dssim"
  "compare ${_refdata}/grey50_4x4.exr ${_refdata}/grey25_4x4.exr --fail-above l2=1")
voxlab_cli_case(compare_missing_file 2 "cannot read image '.*nothere.exr'"
  "compare ${_refdata}/grey50_4x4.exr @ROOT@/tests/data/reference/nothere.exr")
# Constant images 0.5 vs 0.25: rmse is exactly 0.25 > 0.1 -> exit 1, one line naming the metric.
voxlab_cli_case(compare_fail_above 1 "rmse = 0.25 is above the limit 0.1"
  "compare ${_refdata}/grey50_4x4.exr ${_refdata}/grey25_4x4.exr --fail-above rmse=0.1")
# Within the limit: exit 0, the metrics printed (0.5 against 0.25 everywhere: rmse, mae and max_abs
# are exactly 0.25) and the error image written.
voxlab_cli_case_output(compare_within_limit 0 "^$"
  "compare ${_refdata}/grey50_4x4.exr ${_refdata}/grey25_4x4.exr --fail-above rmse=0.3 --out @OUT@/diff.png"
  "rmse +0\\.25\n[^\n]*\nmae +0\\.25\n[^\n]*\nmax_abs +0\\.25\n.*error image: [^\n]*diff\\.png"
  "@OUT@/diff.png" 0 "" "")
voxlab_cli_case(reference_sky_negative 2 "--sky '-1' is not valid; valid: a radiance >= 0 in W/\\(m\\^2 sr\\) \\(0 = no sky\\)"
  "reference --scene cornell-box --spp 1 --sky -1 --out @OUT@/ref.exr")
