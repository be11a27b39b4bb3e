# Lessons (src/lesson/lesson_check.h, src/app/cmd_lesson.cpp): every shipped lesson passes the whole
# check, text and rendered pictures; a lesson with a blank step fails it, naming the step.
add_test(NAME lesson.check_all
  COMMAND $<TARGET_FILE:voxlab> lesson --check ${CMAKE_SOURCE_DIR}/lessons --size 256x256)
set_tests_properties(lesson.check_all PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}" TIMEOUT 600)

voxlab_cli_case(lesson_blank_step 1
  "blank-step\\.md:16: step 2's picture \\(svo/svo-build/svo-structure@4, 2x2\\) is blank: 0\\.00 % of its pixels"
  "lesson --check @ROOT@/tests/cli/lesson/blank-step.md --size 64x64")

# A step's sweep is validated with the lesson, before anything renders: one line naming the step.
voxlab_cli_case(lesson_sweep_unknown_param 2
  "bad-sweep-param\\.md:3: sweep: unknown parameter 'cone\\.nope'; valid parameters: .*cone\\.aperture"
  "lesson --check @ROOT@/tests/cli/lesson/bad-sweep-param.md --no-render")
voxlab_cli_case(lesson_sweep_value_out_of_range 2
  "bad-sweep-value\\.md:3: sweep cone\\.aperture=30,500: parameter cone\\.aperture='500' is not valid; valid: 5\\.\\.120"
  "lesson --check @ROOT@/tests/cli/lesson/bad-sweep-value.md --no-render")

# A step's frames too: the count and every animation, one line naming the step.
voxlab_cli_case(lesson_frames_out_of_range 2
  "bad-frames-param\\.md:3: frames: parameter light\\.0\\.elevation=200 is out of range; valid: -90\\.\\.90"
  "lesson --check @ROOT@/tests/cli/lesson/bad-frames-param.md --no-render")
voxlab_cli_case(lesson_frames_count 2
  "bad-frames-count\\.md:3: frames: 'count' must be 2\\.\\.64, got 100"
  "lesson --check @ROOT@/tests/cli/lesson/bad-frames-count.md --no-render")
