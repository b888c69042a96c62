#!/usr/bin/env bash
# Builds the fuzz preset (Clang 14, libFuzzer, ASan+UBSan; scripts/setup.sh installs Clang if missing)
# and runs each fuzz target for SECONDS, one after another, starting from its seed corpus
# (tests/fuzz/corpus/<target>, never written to).
# New inputs go to build/<preset>/corpus/<target>; a failing input to build/<preset>/artifacts/<target>/
# and the script fails. Keep a failing input as a regression test by copying it into tests/fuzz/corpus/<target>/.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (default: 30 s; obj ply off stl gltf glb blob database)
# FUZZ_ARGS adds libFuzzer flags: FUZZ_ARGS="-fork=1 -ignore_crashes=1" keeps going after a failure.
# FUZZ_PRESET=asan fuzzes with the asan preset's build instead (coverage recorded in io alone, not core:
# what CI does, in the tree its ASan stage has built).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(obj ply off stl gltf glb blob database)

preset="${FUZZ_PRESET:-fuzz}"
fuzzers=()
for target in "${targets[@]}"; do fuzzers+=("fuzz_$target"); done
scripts/setup.sh "$preset" "${fuzzers[@]}"

for target in "${targets[@]}"; do
  corpus="build/$preset/corpus/$target" artifacts="build/$preset/artifacts/$target/"
  mkdir -p "$corpus" "$artifacts"
  dict=()
  [ -f "tests/fuzz/$target.dict" ] && dict=("-dict=tests/fuzz/$target.dict")
  echo "fuzz: $target for ${seconds} s"
  # shellcheck disable=SC2086
  build/$preset/tests/fuzz/"fuzz_$target" "${dict[@]}" ${FUZZ_ARGS:-} -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts" "$corpus" "tests/fuzz/corpus/$target" \
    >"build/$preset/$target.log" 2>&1 || { tail -60 "build/$preset/$target.log"; exit 1; }
  # The last status line: inputs run, coverage, corpus size (and, with -fork, failures found and kept going past).
  echo "fuzz: $target: $(grep -E '^#[0-9]+' "build/$preset/$target.log" | tail -n 1)"
done
