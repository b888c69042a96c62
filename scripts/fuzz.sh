#!/usr/bin/env bash
# Builds the fuzz preset (Clang 14, libFuzzer, ASan+UBSan; scripts/setup.sh installs Clang if missing)
# and runs each fuzz target for SECONDS, one after another, starting from its seed corpus
# (tests/fuzz/corpus/<target>, never written to).
# New inputs go to build/fuzz/corpus/<target>; a failing input to build/fuzz/artifacts/<target>/ and the
# script fails. Keep a failing input as a regression test by copying it into tests/fuzz/corpus/<target>/.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (default: 30 s; obj ply off stl blob database)
# FUZZ_ARGS adds libFuzzer flags: FUZZ_ARGS="-fork=1 -ignore_crashes=1" keeps going after a failure.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(obj ply off stl blob database)

fuzzers=()
for target in "${targets[@]}"; do fuzzers+=("fuzz_$target"); done
scripts/setup.sh fuzz "${fuzzers[@]}"

for target in "${targets[@]}"; do
  corpus="build/fuzz/corpus/$target" artifacts="build/fuzz/artifacts/$target/"
  mkdir -p "$corpus" "$artifacts"
  dict=()
  [ -f "tests/fuzz/$target.dict" ] && dict=("-dict=tests/fuzz/$target.dict")
  echo "fuzz: $target for ${seconds} s"
  # shellcheck disable=SC2086
  build/fuzz/tests/fuzz/"fuzz_$target" "${dict[@]}" ${FUZZ_ARGS:-} -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts" "$corpus" "tests/fuzz/corpus/$target" \
    >"build/fuzz/$target.log" 2>&1 || { tail -60 "build/fuzz/$target.log"; exit 1; }
  # The last status line: inputs run, coverage, corpus size (and, with -fork, failures found and kept going past).
  echo "fuzz: $target: $(grep -E '^#[0-9]+' "build/fuzz/$target.log" | tail -n 1)"
done
