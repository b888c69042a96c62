#!/usr/bin/env bash
# Sets everything up (Debian packages, release build), builds the demo database on the spot if it is not
# there yet (350 entries of all seven families, about 30 s on 2 cores), and runs the main job on it and on
# the bundled sample. Usage: scripts/demo.sh [DB]   (default build/demo.db)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh release >/dev/null
db="${1:-build/demo.db}"
shapedb=build/release/bin/shapedb
if [ ! -f "$db" ]; then
  "$shapedb" build "$db" --entries 350
elif [ "$("$shapedb" info "$db" --json | grep -c '"status": "complete"')" -eq 0 ]; then
  "$shapedb" build "$db" --resume   # an interrupted demo build picks up where it stopped
fi
echo
"$shapedb" info "$db"
echo
"$shapedb" inspect data/samples/pebble.obj
echo
"$shapedb" describe data/samples/pebble.obj
