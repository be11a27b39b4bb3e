# Runs one command-line case: voxlab ARGS must exit with EXPECT_CODE, print exactly one line on
# stderr, and that line must match EXPECT_REGEX. Invoked by voxlab_cli_case() in cli_cases.cmake.
# Optional (voxlab_cli_case_output()): stdout must match EXPECT_STDOUT, the files in EXPECT_FILES
# (|-separated) must exist and be non-empty, and a follow-up command voxlab THEN_ARGS must exit
# with THEN_CODE with its stdout and stderr together matching THEN_REGEX.
separate_arguments(arg_list UNIX_COMMAND "${ARGS}")
# The expected files are removed first, so that one left by an earlier run cannot pass for one this
# run did not write (found by the mutation cli-reference-stderr-file: a reference command that
# never wrote its standard-error file passed on the previous run's).
string(REPLACE "|" ";" expect_files "${EXPECT_FILES}")
foreach(f ${expect_files})
  file(REMOVE "${f}")
endforeach()
execute_process(COMMAND ${EXE} ${arg_list}
  WORKING_DIRECTORY ${WORKDIR}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
string(STRIP "${err}" err_stripped)
string(REGEX MATCHALL "\n" newlines "${err_stripped}")
list(LENGTH newlines newline_count)
if(NOT "${rc}" STREQUAL "${EXPECT_CODE}")
  message(FATAL_ERROR "exit status ${rc}, expected ${EXPECT_CODE}\nstderr: ${err}\nstdout: ${out}")
endif()
if(NOT err_stripped MATCHES "${EXPECT_REGEX}")
  message(FATAL_ERROR "stderr does not match '${EXPECT_REGEX}':\n${err}")
endif()
if(newline_count GREATER 0)
  message(FATAL_ERROR "expected one line on stderr, got:\n${err}")
endif()
if(DEFINED EXPECT_STDOUT AND NOT out MATCHES "${EXPECT_STDOUT}")
  message(FATAL_ERROR "stdout does not match '${EXPECT_STDOUT}':\n${out}")
endif()
foreach(f ${expect_files})
  if(NOT EXISTS "${f}")
    message(FATAL_ERROR "expected file ${f} was not written")
  endif()
  file(SIZE "${f}" size)
  if(size EQUAL 0)
    message(FATAL_ERROR "expected file ${f} is empty")
  endif()
endforeach()
if(DEFINED THEN_ARGS)
  separate_arguments(then_list UNIX_COMMAND "${THEN_ARGS}")
  execute_process(COMMAND ${EXE} ${then_list}
    WORKING_DIRECTORY ${WORKDIR}
    RESULT_VARIABLE then_rc OUTPUT_VARIABLE then_out ERROR_VARIABLE then_err TIMEOUT 120)
  if(NOT "${then_rc}" STREQUAL "${THEN_CODE}")
    message(FATAL_ERROR "follow-up 'voxlab ${THEN_ARGS}': exit status ${then_rc}, expected ${THEN_CODE}\n${then_out}${then_err}")
  endif()
  if(NOT "${then_out}${then_err}" MATCHES "${THEN_REGEX}")
    message(FATAL_ERROR "follow-up 'voxlab ${THEN_ARGS}' does not match '${THEN_REGEX}':\n${then_out}${then_err}")
  endif()
endif()
message(STATUS "ok: ${err_stripped}")
