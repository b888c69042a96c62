#!/usr/bin/env bash
# Sets everything up (Debian packages, release build) and runs the main job on the bundled sample.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh release >/dev/null
build/release/bin/shapedb inspect data/samples/pebble.obj "$@"
echo
build/release/bin/shapedb describe data/samples/pebble.obj
