#!/usr/bin/env bash
# Fuzzes the mesh importer (and everything a usable mesh goes through) with
# libFuzzer for SECONDS (default 60), and beside it the daemon's edge (the HTTP
# request's header, the gate, a JSON or multipart body) for HTTP_SECONDS
# (default 30). Builds build-fuzz/ with clang first.
# A crash, a sanitizer report, a leak in our code or a 10 s hang fails the run
# and leaves the input in build-fuzz/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
http_seconds=${2:-30}

CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROTAFAB_FUZZ=ON -DROTAFAB_BENCH=OFF
cmake --build build-fuzz --target fuzz_mesh_import fuzz_http_request

# Seeds: our examples and a few real-world files; the first byte picks the
# reader (0 off, 1 ply, 2 obj, 3 stl, 4 glb, 5 gltf, 6 3mf, 7 dae).
corpus=build-fuzz/corpus
mkdir -p "$corpus" build-fuzz/artifacts
rm -f build-fuzz/artifacts/*
seed() { [[ -f "$2" ]] && { printf "\\x$1"; cat "$2"; } > "$corpus/seed-$(basename "$2")" || true; }
seed 02 examples/cube.obj
seed 02 examples/soccer-ball.obj
seed 00 /usr/share/geomview/geom/dodec.off
seed 00 /usr/share/geomview/geom/facecube.off
seed 01 /usr/share/assimp/models/PLY/cube_binary.ply
seed 01 /usr/share/assimp/models/PLY/cube_uv.ply
seed 03 /usr/share/openscad/testdata/scad/3D/features/import.stl
seed 03 /usr/share/openscad/testdata/scad/3D/features/import_bin_solid.stl
seed 04 /usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb
seed 05 /usr/share/assimp/models/glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf
seed 06 /usr/share/assimp/models/3MF/box.3mf
seed 07 /usr/share/assimp/models/Collada/cube_triangulate.dae

# fuzz TARGET SECONDS CORPUS [libFuzzer options]: runs it, prints its summary and any report.
fuzz() {
  local target=$1 time=$2 seeds=$3
  shift 3
  local log=build-fuzz/$target.log status=0
  LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0" \
    build-fuzz/$target -max_total_time="$time" -timeout=10 -rss_limit_mb=4096 \
    -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/ "$@" "$seeds" >"$log" 2>&1 || status=$?
  # The progress lines are noise in CI's log; the summary and any report are not.
  grep -vE '^#[0-9]+ +(NEW|REDUCE|pulse)|^\s+NEW_FUNC' "$log" | tail -n 60
  if [[ $status -ne 0 ]]; then
    echo "fuzz: $target FAILED (status $status); the input is in build-fuzz/artifacts/" >&2
    exit 1
  fi
  echo "fuzz: $target: no crash, leak or hang in ${time} s"
}
# The two fuzzers run side by side, each on a core of its own (libFuzzer
# runs one thread): each gets its whole time, and CI waits for the longer.
fuzz fuzz_mesh_import "$seconds" "$corpus" -max_len=65536 &
mesh_fuzzer=$!

# The daemon's edge: requests as they arrive (the first byte picks the
# listener and the size of the body's pieces).
requests=build-fuzz/corpus-http
mkdir -p "$requests"
request() { printf '%b' "$2" > "$requests/seed-$1"; }
request get '\x01GET //api/jobs HTTP/1.1\r\nHost: 127.0.0.1:8730\r\nAuthorization: Bearer fuzz-token\r\n\r\n'
request events '\x01GET /api/events?session=abc HTTP/1.1\r\nHost: localhost\r\n\r\n'
request action '\x05POST /api/jobs/1/move HTTP/1.1\r\nHost: [::1]:8730\r\nAuthorization: Bearer fuzz-token\r\nOrigin: http://[::1]:8730\r\nContent-Type: application/json\r\nContent-Length: 28\r\n\r\n{"before": 2, "priority": 3}'
request form '\x00POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=b\r\nContent-Length: 120\r\n\r\n--b\r\nContent-Disposition: form-data; name="file"; filename="a.obj"\r\n\r\nv 0 0 0\r\n--b\r\nContent-Disposition: form-data; name="options"\r\n\r\n[]\r\n--b--\r\n'
request chunked '\x02POST /api/jobs/2/resume HTTP/1.1\r\nHost: example\r\nTransfer-Encoding: chunked\r\nContent-Type: application/json\r\n\r\n5\r\n{"a":\r\n0\r\n\r\n'
fuzz fuzz_http_request "$http_seconds" "$requests" -max_len=16384 &
http_fuzzer=$!
status=0
wait "$mesh_fuzzer" || status=1
wait "$http_fuzzer" || status=1
exit "$status"
