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

file(GLOB VOXLAB_CLI_CASE_FILES ${CMAKE_SOURCE_DIR}/tests/cli/*.cmake)
foreach(f ${VOXLAB_CLI_CASE_FILES})
  include(${f})
endforeach()
