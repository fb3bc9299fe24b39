#!/usr/bin/env bash
# Fuzzes the mesh importer (and everything a usable mesh goes through) with
# libFuzzer for SECONDS (default 60). Builds build-fuzz/ with clang first.
# A crash, a sanitizer report, a leak in our code or a 10 s hang fails the run
# and leaves the input in build-fuzz/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}

CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROTAFAB_FUZZ=ON -DROTAFAB_BENCH=OFF
cmake --build build-fuzz --target fuzz_mesh_import

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

log=build-fuzz/fuzz.log
status=0
LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0" \
  build-fuzz/fuzz_mesh_import -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -max_len=65536 \
  -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/ "$corpus" >"$log" 2>&1 || status=$?
# The progress lines are noise in CI's log; the summary and any report are not.
grep -vE '^#[0-9]+ +(NEW|REDUCE|pulse)|^\s+NEW_FUNC' "$log" | tail -n 60
if [[ $status -ne 0 ]]; then
  echo "fuzz: FAILED (status $status); the input is in build-fuzz/artifacts/" >&2
  exit 1
fi
echo "fuzz: no crash, leak or hang in ${seconds} s"
