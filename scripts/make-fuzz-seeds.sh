#!/usr/bin/env bash
# Regenerates the fuzz seeds that come from a real database: tests/fuzz/corpus/database/seed-small.db
# (two entries, 2 modes, grid 4) and tests/fuzz/corpus/blob/seed-* (each of its blobs, prefixed with
# the byte that picks fuzz_blob's decoder). The text-format seeds are written by hand.
# Usage: scripts/make-fuzz-seeds.sh [path/to/shapedb]   (default: build/release/bin/shapedb)
set -euo pipefail
cd "$(dirname "$0")/.."
shapedb="${1:-build/release/bin/shapedb}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$shapedb" build "$work/seed.db" --entries 2 --families box,shard --modes 2 --grid 4 --quiet
sqlite3 "$work/seed.db" "PRAGMA wal_checkpoint(TRUNCATE);" >/dev/null
cp "$work/seed.db" tests/fuzz/corpus/database/seed-small.db
rm -f tests/fuzz/corpus/blob/seed-*
python3 - "$work/seed.db" tests/fuzz/corpus/blob <<'PY'
import sqlite3, sys
db, out = sqlite3.connect(sys.argv[1]), sys.argv[2]
# fuzz_blob's selector: 0 descriptor, 1 tet mesh, 2 modes, 3 mass properties, 4 collision, 5 sound.
part_selector = {0: 1, 1: 3, 2: 2, 3: 4, 4: 5}
for entry, kind, data in db.execute("SELECT entry_id, kind, data FROM descriptors"):
    open(f"{out}/seed-descriptor-{entry}-{kind}", "wb").write(bytes([0]) + data)
for entry, part, data in db.execute("SELECT entry_id, part, data FROM physics"):
    open(f"{out}/seed-part{part}-{entry}", "wb").write(bytes([part_selector[part]]) + data)
PY
ls tests/fuzz/corpus/database tests/fuzz/corpus/blob
