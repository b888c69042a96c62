#!/usr/bin/env bash
# The volume a fracture keeps, on every mesh of a folder: `shapedb fracture` at each piece count with the
# default (automatic) resolution, one Markdown row per mesh and count: fragments, resolution, volume
# kept, crumbs and fragments remeshed, wall time. Usage:
#   bench/fracture_volume.sh MESH_FOLDER [PIECES...]     (default pieces: 50 200)
# The shapedb binary is build/release/bin/shapedb unless $SHAPEDB says otherwise.
set -euo pipefail
folder=${1:?usage: bench/fracture_volume.sh MESH_FOLDER [PIECES...]}
shift
[ $# -gt 0 ] || set -- 50 200
pieces=("$@")
shapedb=${SHAPEDB:-"$(dirname "$0")/../build/release/bin/shapedb"}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

echo "| mesh | pieces | fragments | resolution | volume kept | dropped, remeshed | time |"
echo "|---|---|---|---|---|---|---|"
find "$folder" -type f \( -iname '*.obj' -o -iname '*.ply' -o -iname '*.off' -o -iname '*.stl' \) | sort |
  while read -r mesh; do
    for n in "${pieces[@]}"; do
      rm -rf "$out/f"
      start=$(date +%s.%N)
      if ! report=$("$shapedb" fracture "$mesh" --pieces "$n" --out "$out/f" 2>&1); then
        echo "| ${mesh#"$folder"/} | $n | error: $(echo "$report" | tail -1) | | | | |"
        continue
      fi
      seconds=$(echo "$(date +%s.%N) - $start" | bc)
      fragments=$(echo "$report" | sed -n 's/.*: \([0-9]*\) fragments from.*/\1/p')
      resolution=$(echo "$report" | sed -n 's/.*resolution \([0-9]*\),.*/\1/p')
      kept=$(echo "$report" | sed -n 's/^volume kept: \([0-9.]* %\).*/\1/p')
      rest=$(echo "$report" | grep '^volume kept' | sed 's/^[^;]*;\{0,1\} *//; s/^volume kept.*//')
      printf '| %s | %s | %s | %s | %s | %s | %.1f s |\n' "${mesh#"$folder"/}" "$n" "$fragments" "$resolution" \
        "$kept" "${rest:-none}" "$seconds"
    done
  done
