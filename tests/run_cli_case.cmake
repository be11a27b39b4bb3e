# Runs one command-line case: voxlab ARGS must exit with EXPECT_CODE, print exactly one line on
# stderr, and that line must match EXPECT_REGEX. Invoked by voxlab_cli_case() in cli_cases.cmake.
separate_arguments(arg_list UNIX_COMMAND "${ARGS}")
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
message(STATUS "ok: ${err_stripped}")
