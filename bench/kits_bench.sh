#!/usr/bin/env bash
# Sheets cut in kits against the free order: for the README's first mesh
# (the bunny) and CGAL's cow and elephant, band structure, every other
# option the default, at the default nesting budget and at --time 120.
# For each: the sheets, the share of the usable bed area in parts, the
# fewest sheets the parts' area allows (the area bound), why the nesting
# stopped, and the whole command's seconds (wall clock). Targets and
# results: docs/PERFORMANCE.md, "Kits and the free order".
#
#   bench/kits_bench.sh ROTAFAB [TIMES...]     (TIMES: budgets; default: "default 120")
set -uo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 ROTAFAB [TIMES...]" >&2
  exit 2
fi
rotafab=$1
shift
times=("${@:-default}")
[ $# -eq 0 ] && times=(default 120)
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$work" data/meshes/cow.off data/meshes/elephant.off
printf '%-9s %-5s %-8s %6s %6s %6s  %-17s %8s\n' mesh order budget sheets fill bound stopped seconds
for mesh in "$here/examples/bunny.obj" "$work/data/meshes/cow.off" "$work/data/meshes/elephant.off"; do
  for order in kits free; do
    for budget in "${times[@]}"; do
      args=(make "$mesh" --structure band --order "$order" --out "$work/out" --json)
      [ "$budget" != default ] && args+=(--time "$budget")
      rm -rf "$work/out"
      start=$(date +%s.%N)
      if ! "$rotafab" "${args[@]}" > "$work/json" 2> "$work/err"; then
        echo "$(basename "$mesh") $order $budget: failed: $(tail -1 "$work/err")"
        continue
      fi
      end=$(date +%s.%N)
      python3 - "$work/json" "$(basename "$mesh" | sed 's/\..*//')" "$order" "$budget" "$start" "$end" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
sheets, fill = d["sheets"], d["utilization"]
bound = math.ceil(fill * sheets - 1e-9)
print(f"{sys.argv[2]:<9} {sys.argv[3]:<5} {sys.argv[4]:<8} {sheets:>6} {fill * 100:5.1f}% {bound:>6}  "
      f"{d.get('nesting_stopped', ''):<17} {float(sys.argv[6]) - float(sys.argv[5]):8.1f}")
PY
    done
  done
done
