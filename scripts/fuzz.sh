#!/usr/bin/env bash
# Fuzzes the scene loader (tests/fuzz/fuzz_scene_loader.cpp) with libFuzzer under ASan+UBSan for
# SECONDS (default 60), after running every regression file of tests/data/fuzz once. Needs the
# sanitized Clang build in build-asan/ (scripts/build-asan.sh; scripts/test.sh runs both).
# Findings are written to build-asan/fuzz-findings/; keep each as tests/data/fuzz/<what>.gltf
# once fixed (docs/testing.md#fuzzing-the-scene-loader). The corpus grows in build-asan/fuzz-corpus
# and is reused by the next run.
#
#   scripts/fuzz.sh [SECONDS] [extra libFuzzer flags...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
build="$root/build-asan"
fuzzer="$build/fuzz_scene_loader"
[ -x "$fuzzer" ] || { echo "fuzz.sh: $fuzzer is missing; build it with scripts/build-asan.sh" >&2; exit 2; }
source "$root/scripts/sanitizer-env.sh"
# The target writes every input to a scratch file in TMPDIR: on a disk file system, truncating it
# for each input left the fuzzer waiting in the kernel (state D) for much of its time, so a
# tmpfs is used where there is one.
[ -z "${TMPDIR:-}" ] && [ -d /dev/shm ] && [ -w /dev/shm ] && export TMPDIR=/dev/shm
python3 "$root/tests/fuzz/make_seeds.py" "$root" "$build/fuzz-seeds" >/dev/null
mkdir -p "$build/fuzz-corpus" "$build/fuzz-findings"
# Limits that make "allocates without bound" and "hangs" findings: one input may not take more
# than 30 s nor allocate more than 1 GiB at once (2 GiB resident in all). The largest scene the
# loader accepts (2^23 flattened vertices, e.g. tests/data/fuzz/instanced-implied-zeros-12x2e20.gltf
# and its mutants) takes 5.2 s of CPU under ASan; with 10 s, a machine busy with other builds
# (the fuzzer at a third of a core, 2026-12-01) reported that bounded load as a hang.
limits=(-timeout=30 -rss_limit_mb=2048 -malloc_limit_mb=1024 -max_len=65536)
regressions=("$root"/tests/data/fuzz/*.gl*)
if [ -e "${regressions[0]}" ]; then
  echo "== fuzz: ${#regressions[@]} regression files of tests/data/fuzz"
  "$fuzzer" "${limits[@]}" "${regressions[@]}" 2>&1 | tail -n 3
fi
echo "== fuzz: scene loader for ${seconds} s"
"$fuzzer" "${limits[@]}" -max_total_time="$seconds" -print_final_stats=1 \
  -dict="$root/tests/fuzz/gltf.dict" -artifact_prefix="$build/fuzz-findings/" \
  "$@" "$build/fuzz-corpus" "$build/fuzz-seeds" 2>&1 | grep -v '^#[0-9]*.*\(NEW\|REDUCE\|pulse\)' | tail -n 25
