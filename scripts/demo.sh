#!/usr/bin/env bash
# Sets everything up (Debian packages, release build), builds the demo database on the spot if it is not
# there yet (112 entries, 7 of each of the sixteen families, about 55 s on 2 cores), and runs the main job on it: the
# bundled sample meshes (data/samples, made by scripts/make_samples.py) queried against it, one table of
# matches and physical data, then one query in full with its timing and a picture of query and match.
# Usage: scripts/demo.sh [DB]   (default build/demo.db)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh release >/dev/null
db="${1:-build/demo.db}"
shapedb=build/release/bin/shapedb
if [ ! -f "$db" ]; then
  "$shapedb" build "$db" --entries 112
elif [ "$("$shapedb" info "$db" --json | grep -c '"status": "complete"')" -eq 0 ]; then
  "$shapedb" build "$db" --resume   # an interrupted demo build picks up where it stopped
fi
echo
"$shapedb" info "$db"
echo
"$shapedb" query "$db" data/samples/*.obj --table --material steel
echo
"$shapedb" query "$db" data/samples/egg.obj --k 3 --material glass --timing --png build/demo-egg.png \
  --export-obj build/demo-export
echo "(build/demo-egg.png: the query beside its match; build/demo-export: the adapted tets and collision compound)"
