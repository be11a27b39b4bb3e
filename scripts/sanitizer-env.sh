# Sourced by scripts/test.sh and scripts/fuzz.sh: runtime options of the sanitized build.
# Every report is fatal; suppressions (tests/sanitizers/) cover third-party libraries only.
sanitizers="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tests/sanitizers"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=0:strict_string_checks=1:check_initialization_order=1"
export LSAN_OPTIONS="suppressions=$sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="suppressions=$sanitizers/ubsan.supp:print_stacktrace=1:halt_on_error=1"
