#!/usr/bin/env bash
# The smallest --size (whole inches) in [LOW, HIGH] at which
# `make MESH --structure band --panels PANELS --size Sin --layout rows`
# exits 0, by bisection (the size is taken to work from some size on), and
# what the build warned of there (labels left off, bands glued).
#
#   bench/smallest_size.sh ROTAFAB MESH PANELS LOW HIGH
set -uo pipefail
if [ $# -ne 5 ]; then
  echo "usage: $0 ROTAFAB MESH PANELS LOW HIGH" >&2
  exit 2
fi
rotafab=$1 mesh=$2 panels=$3 low=$4 high=$5
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
builds() {
  rm -rf "$work/out"
  "$rotafab" make "$mesh" --structure band --panels "$panels" --size "${1}in" --layout rows --out "$work/out" \
    > /dev/null 2> "$work/err"
}
if ! builds "$high"; then
  echo "none up to $high in: $(grep '^error' "$work/err")"
  exit 1
fi
while [ $((high - low)) -gt 1 ]; do
  middle=$(((low + high) / 2))
  if builds "$middle"; then high=$middle; else low=$middle; fi
done
builds "$high"
echo "smallest $high in $(grep -o '[0-9]* labels\? \(is\|are\) not etched' "$work/err") $(grep -o '[0-9]* bands\? without room.* glued' "$work/err")"
