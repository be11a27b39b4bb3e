#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (CTest: unit, snapshot, physics,
# command-line and viewer tests). llvmpipe hands out tiles and work groups differently with more
# than one thread, so atomics append in another order (testing.md): the GPU tests (the unit-test
# binary: snapshots, exact, physics) run with LP_NUM_THREADS=1 and again with 2; the tests of the
# command line, the viewer, handouts and lights, whose checks do not depend on the thread count,
# run once, in the second pass. Then the sanitized pass (docs/testing.md#guards): the unit,
# command-line and snapshot tests once more, built with AddressSanitizer +
# UndefinedBehaviorSanitizer (Clang, build-asan/), and the scene-loader fuzzer for
# VOXLAB_FUZZ_SECONDS (default 90). VOXLAB_SANITIZED=0 skips that pass.
#
# Two tests run side by side (ctest -j2, VOXLAB_TEST_JOBS): each test process has its own
# temporary folder (tests/unit/test_main.cpp) and output folder, and the tests that open a window
# under Xvfb share one lock (RESOURCE_LOCK xvfb), so only one runs at a time.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cd "$root/build"
jobs="${VOXLAB_TEST_JOBS:-2}"
once='^(cli|viewer|handout|gallery|lights|platform|fidelity)\.'
echo "== ctest with LP_NUM_THREADS=1 (the unit-test binary: snapshots, exact and physics tests)"
LP_NUM_THREADS=1 ctest --output-on-failure -j"$jobs" --timeout 900 -E "$once"
echo "== ctest with LP_NUM_THREADS=2 (everything)"
LP_NUM_THREADS=2 ctest --output-on-failure -j"$jobs" --timeout 900

[ "${VOXLAB_SANITIZED:-1}" = 0 ] && exit 0
echo "== sanitized build (ASan + UBSan, Clang)"
"$root/scripts/build-asan.sh"
source "$root/scripts/sanitizer-env.sh"
cd "$root/build-asan"
# Viewer, handout (Chromium), platform and the fidelity suite's tests are left out: they exercise GLFW/Xvfb and a
# browser more than voxlab's code, and would double the sanitized pass (docs/testing.md#guards).
# The lights.* checks (every technique through the CLI on extra scenes) run in a second step with
# LeakSanitizer off and ASan + UBSan on: LeakSanitizer's own tracer dies at exit ("Tracer caught
# signal 11", a bogus dynamic-TLS range of Mesa's libraries) for near-field on 2CylinderEngine.glb,
# and use_tls=0 would instead report glibc's dlopen/dlerror buffers held in TLS as leaks in every
# test. The same code's leaks are checked by the snapshot tests of the first step.
# The same tracer crash struck LpvGpu.LookupAndBlendEqualCpu under ctest (3 of 3 runs, at exit,
# after the test passed; run alone it passed 4 of 4), so it joins the second step. A failed test
# also runs once more in both steps, for the crash's rarer appearances elsewhere: a report of ASan,
# UBSan or LeakSanitizer in project code is deterministic and fails both times.
# lights.default_sun_raw_sponza runs only in the plain pass: the same stages as lights.default_sun
# on the raw Sponza (262 267 triangles), 200 s there and several times that under ASan.
without_lsan='^(lights\.|LpvGpu\.LookupAndBlendEqualCpu$)'
echo "== sanitized ctest with LP_NUM_THREADS=1 (unit, command line, snapshots)"
LP_NUM_THREADS=1 ctest --output-on-failure -j"$jobs" --timeout 1200 --repeat until-pass:2 \
  -E "^(viewer|handout|gallery|platform|lights|fidelity)\.|^LpvGpu\.LookupAndBlendEqualCpu$"
echo "== sanitized ctest without LeakSanitizer: lights.*, LpvGpu.LookupAndBlendEqualCpu"
ASAN_OPTIONS="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}" LP_NUM_THREADS=1 \
  ctest --output-on-failure -j"$jobs" --timeout 1200 --repeat until-pass:2 -R "$without_lsan" \
  -E '^lights\.default_sun_raw_sponza$'
"$root/scripts/fuzz.sh" "${VOXLAB_FUZZ_SECONDS:-90}"
