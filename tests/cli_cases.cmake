# Command-line cases as data: each line runs voxlab with ARGS and checks the exit status and the
# one-line message on stderr. Paths in ARGS may use @ROOT@ for the source tree and @OUT@ for a
# scratch folder in the build tree.
#
#   voxlab_cli_case(NAME EXIT_CODE "REGEX" "ARGS")
function(voxlab_cli_case name code regex args)
  string(REPLACE "@ROOT@" "${CMAKE_SOURCE_DIR}" args "${args}")
  string(REPLACE "@OUT@" "${CMAKE_BINARY_DIR}/cli-out/${name}" args "${args}")
  add_test(NAME cli.${name}
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:voxlab> -DEXPECT_CODE=${code}
            "-DEXPECT_REGEX=${regex}" "-DARGS=${args}" -DWORKDIR=${CMAKE_BINARY_DIR}
            -P ${CMAKE_SOURCE_DIR}/tests/run_cli_case.cmake)
  set_tests_properties(cli.${name} PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}")
endfunction()

# A case that succeeds checks what it produced, not only its exit status:
#   voxlab_cli_case_output(NAME EXIT_CODE "STDERR_REGEX" "ARGS" "STDOUT_REGEX" "FILES"
#                          THEN_CODE "THEN_REGEX" "THEN_ARGS")
# FILES (|-separated, may be empty) must exist and be non-empty; then voxlab THEN_ARGS must exit
# with THEN_CODE and print (stdout and stderr) something matching THEN_REGEX (THEN_ARGS "" skips it).
function(voxlab_cli_case_output name code regex args stdout_regex files then_code then_regex then_args)
  foreach(var args files then_args)
    string(REPLACE "@ROOT@" "${CMAKE_SOURCE_DIR}" ${var} "${${var}}")
    string(REPLACE "@OUT@" "${CMAKE_BINARY_DIR}/cli-out/${name}" ${var} "${${var}}")
  endforeach()
  set(then "")
  if(NOT then_args STREQUAL "")
    set(then "-DTHEN_ARGS=${then_args}" -DTHEN_CODE=${then_code} "-DTHEN_REGEX=${then_regex}")
  endif()
  add_test(NAME cli.${name}
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:voxlab> -DEXPECT_CODE=${code}
            "-DEXPECT_REGEX=${regex}" "-DARGS=${args}" -DWORKDIR=${CMAKE_BINARY_DIR}
            "-DEXPECT_STDOUT=${stdout_regex}" "-DEXPECT_FILES=${files}" ${then}
            -P ${CMAKE_SOURCE_DIR}/tests/run_cli_case.cmake)
  set_tests_properties(cli.${name} PROPERTIES ENVIRONMENT "VOXLAB_ROOT=${CMAKE_SOURCE_DIR}")
endfunction()

file(GLOB VOXLAB_CLI_CASE_FILES ${CMAKE_SOURCE_DIR}/tests/cli/*.cmake)
foreach(f ${VOXLAB_CLI_CASE_FILES})
  include(${f})
endforeach()
