#!/usr/bin/env bash
# Every mesh of CGAL's demo data (Debian's libcgal-demo, data/meshes/*.off)
# of at most 8,000 faces, woven (`make --structure weave`) with the options
# given, each result checked by the independent checker tools/weavecheck.py
# (labels, holes, their alignment, outlines). One line per mesh: woven and
# clean, woven with problems (their kinds), or refused (the reason's first
# words); a count of each at the end. Results: docs/PERFORMANCE.md, "Meshes
# other people made, woven".
#
#   bench/weave_wild.sh ROTAFAB [MAKE OPTIONS...]
#   e.g. bench/weave_wild.sh build/rotafab --panels 400 --size 36in
set -uo pipefail
shopt -s nullglob
if [ $# -lt 1 ]; then
  echo "usage: $0 ROTAFAB [MAKE OPTIONS...]" >&2
  exit 2
fi
rotafab=$1
shift
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$work" data/meshes || exit 2
faces() {  # the face count of an OFF file's header (comments and blank lines skipped)
  python3 - "$1" <<'PY'
import sys
words = []
with open(sys.argv[1], errors="replace") as f:
    for line in f:
        line = line.split("#")[0].split()
        if not line:
            continue
        if not words and line[0].upper().endswith("OFF"):
            line = line[1:]
        words += line
        if len(words) >= 2:
            break
print(words[1] if len(words) >= 2 else 0)
PY
}
woven=0 clean=0 refused=0
for mesh in "$work"/data/meshes/*.off; do
  name=$(basename "$mesh" .off)
  f=$(faces "$mesh")
  [[ $f =~ ^[0-9]+$ ]] && ((f <= 8000)) || continue
  rm -rf "$work/out"
  start=$(date +%s.%N)
  if "$rotafab" make "$mesh" --structure weave --out "$work/out" "$@" > /dev/null 2> "$work/err"; then
    seconds=$(echo "$(date +%s.%N) - $start" | bc)
    woven=$((woven + 1))
    result=$(python3 "$here/tools/weavecheck.py" "$work/out" --json --allow-glue)
    if [ -z "$result" ]; then
      printf '%-28s %5s faces  woven, but its manifest could not be checked\n' "$name" "$f"
      continue
    fi
    python3 - "$name" "$f" "$seconds" "$result" "$work/out/manifest.json" <<'PY'
import json, sys
name, faces, seconds, result, manifest = sys.argv[1:]
r = json.loads(result)
m = json.load(open(manifest))
size = m.get("size", {})
problems = ", ".join("%s %d" % kv for kv in sorted(r["problems"].items())) or "clean"
print("%-28s %5s faces  woven: %4d panels, %3d sheets, %3d glued, %s in; %s (%.1f s)" % (
    name, faces, r["panels"], len(m["sheets"]), r["glued"],
    " x ".join("%.1f" % v for v in (size.values() if isinstance(size, dict) else size)), problems, float(seconds)))
PY
    if python3 -c 'import json, sys; r = json.loads(sys.argv[1]); sys.exit(bool(r["problems"]) or r["glued"] > 0)' "$result"; then
      clean=$((clean + 1))
    fi
  else
    refused=$((refused + 1))
    printf '%-28s %5s faces  refused: %s\n' "$name" "$f" "$(grep -v '^make:' "$work/err" | tail -1 | cut -c1-160)"
  fi
done
echo "woven $woven (clean, no glue: $clean), refused $refused"
