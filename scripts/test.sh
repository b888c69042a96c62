#!/usr/bin/env bash
# Sets everything up and runs every test. Usage: scripts/test.sh [release|debug|asan|tsan]
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
start=$SECONDS
scripts/setup.sh "$preset"
echo "test: set up and built in $((SECONDS - start)) s"
ctest --preset "$preset"
