#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run):
#   1. scripts/setup.sh (install the Debian packages, build Release), then every test;
#   2. fuzz the mesh importer for a bounded time (libFuzzer, clang);
#   3. build and run every test again under AddressSanitizer + UBSan.
# Environment: ROTAFAB_FUZZ_SECONDS (default 60; 0 skips fuzzing),
#              ROTAFAB_SKIP_SANITIZERS=1 skips step 3.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

# Each step says how long it took: CI has 45 minutes on 2 cores.
took() { echo "test.sh: $1 took $((SECONDS - step_began)) s (${SECONDS} s in all)"; step_began=$SECONDS; }
step_began=$SECONDS

scripts/setup.sh
took "setup (packages and the Release build)"
ctest --test-dir build --output-on-failure -j"$jobs"
took "the Release tests"

if [[ "${ROTAFAB_FUZZ_SECONDS:-60}" != 0 ]]; then
  scripts/fuzz.sh "${ROTAFAB_FUZZ_SECONDS:-60}"
  took "fuzzing"
fi

if [[ -z "${ROTAFAB_SKIP_SANITIZERS:-}" ]]; then
  # -g1: line tables are all a sanitizer's report needs, and full debug
  # information would double the build. -O1: the build took 21 minutes of
  # CI's 45 at -O2 and takes 11.5 at -O1, and the tests ran no slower.
  # Clang: it compiles these files in 65% of GCC's time (the geometry
  # library and the command-line tests: 270 s against 419 s on 2 cores),
  # and its instrumented tests take as long (819 s against 791 s). The
  # Release build stays GCC's, as the README builds it, so both compilers see the code.
  # (The compiler named on the command line: a build-asan configured before with GCC changes over.)
  cmake -S . -B build-asan -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DROTAFAB_SANITIZE=ON -DROTAFAB_BENCH=OFF
  cmake --build build-asan
  took "the sanitizers' build"
  # The Release pass's test times, so that ctest starts the longest first
  # and two cores are not left with one long test at the end.
  mkdir -p build-asan/Testing/Temporary
  cp build/Testing/Temporary/CTestCostData.txt build-asan/Testing/Temporary/ 2>/dev/null || true
  # Assimp (Debian's build) leaks on some inputs; our own code is still leak-checked.
  export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  # The browser tests are left out here: Chromium itself is not built with
  # the sanitizers, and the daemon's paths they drive run under them in the
  # Daemon and Page suites; they would add a minute to CI's 45. So is the
  # huge pages' test: it checks glibc malloc's tunable, and AddressSanitizer
  # replaces that allocator (a minute of a core, for nothing it could find).
  # And the weave of every CGAL mesh: six minutes in Release, most of an
  # hour instrumented; the other weave tests run its code here. Its six
  # minutes in the Release pass are paid for here by two long command-line
  # tests of meshes from the wild (a minute of a core each instrumented),
  # CGAL's half cylinder patched and OpenSCAD's CAD STLs repaired: the
  # patching and the repair run instrumented in the geometry tests, and
  # the band's wild meshes' test builds meshes from the wild here.
  ctest --test-dir build-asan --output-on-failure -j"$jobs" \
    -E '^(Browser\.|MakeCli\.TheHeapIsOnHugePages|WovenMeshesOthersMade\.|WeaveCli\.ABentHoleThatOneFaceCannotCloseIsWovenPatched|MakeCli\.CadStlsFacesOfZeroAreaAreRepaired)'
  took "the sanitizers' tests"
fi
