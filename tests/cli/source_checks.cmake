# Checks of the source itself, no build output needed: no function body in the listed folders is
# longer than 150 lines (scripts/check-function-length.py prints each one with its file and line).
add_test(NAME lint.function_length
  COMMAND python3 ${CMAKE_SOURCE_DIR}/scripts/check-function-length.py --max 150 ${CMAKE_SOURCE_DIR}/src/inspect)
