# Sourced by scripts/test.sh and scripts/fuzz.sh: runtime options of the sanitized build.
# Every report is fatal; suppressions (tests/sanitizers/) cover third-party libraries only.
sanitizers="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tests/sanitizers"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=0:strict_string_checks=1:check_initialization_order=1"
# use_tls=0: LeakSanitizer's tracer reads a bogus dynamic-TLS range of the libraries Mesa loads
# (verbosity=1 shows "DTLS 8 at 0x...129a-0x...239c") and dies with "Tracer caught signal 11" at
# exit, e.g. near-field on tests/data/scenes/2CylinderEngine.glb (4 of 4 runs); with it the run is
# clean and no leak is reported. Thread-local storage is then not scanned for roots.
export LSAN_OPTIONS="suppressions=$sanitizers/lsan.supp:print_suppressions=0:use_tls=0"
export UBSAN_OPTIONS="suppressions=$sanitizers/ubsan.supp:print_stacktrace=1:halt_on_error=1"
