#!/usr/bin/env bash
# Runs the benchmarks of docs/PERFORMANCE.md on a Release build and prints the
# figures recorded there: medians of 5 repetitions, the time ratio per
# doubling of the faces, and `rotafab inspect` on a 100k-face mesh (hyperfine).
set -euo pipefail
cd "$(dirname "$0")/.."
ROTAFAB_SKIP_APT=${ROTAFAB_SKIP_APT:-1} scripts/setup.sh >/dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
build/rotafab_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="$out/bench.json" --benchmark_out_format=json >/dev/null
python3 - "$out/bench.json" <<'PY'
import json, sys
rows = [b for b in json.load(open(sys.argv[1]))["benchmarks"] if b.get("aggregate_name") == "median"]
series = {}
for b in rows:
    name, size = b["run_name"].split("/")
    series.setdefault(name, []).append((int(size), b["real_time"]))
for name, points in series.items():
    print(f"{name}")
    print(f"  {'faces':>8} {'median ms':>10} {'ratio':>7} {'per 2x':>7}")
    previous = None
    for size, ms in points:
        if previous:
            ratio = ms / previous[1]
            per_doubling = ratio ** (0.693147 / __import__('math').log(size / previous[0]))
            print(f"  {size:>8} {ms:>10.2f} {ratio:>7.2f} {per_doubling:>7.2f}")
        else:
            print(f"  {size:>8} {ms:>10.2f}")
        previous = (size, ms)
PY
build/rotafab_bench write-mesh 100000 "$out/torus-100k.obj"
hyperfine --warmup 2 --runs 10 -N "build/rotafab inspect --json $out/torus-100k.obj" 2>&1 | grep -E 'Time|Range'
