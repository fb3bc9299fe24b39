#!/usr/bin/env bash
# Installs every Debian 12 package Rotafab needs, then configures and builds it
# in Release. Non-interactive and idempotent: run it again at any time.
#
#   scripts/setup.sh            install (when root) + build into build/
#   ROTAFAB_SKIP_APT=1 scripts/setup.sh   build only
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config clang clang-format
  libclang-rt-14-dev
  # libraries (see README "Dependencies" for what each is for)
  libassimp-dev libeigen3-dev libcli11-dev nlohmann-json3-dev libsimdjson-dev
  libspdlog-dev libfmt-dev libyaml-cpp-dev libboost-dev libboost-system-dev
  libsqlite3-dev libpq-dev libssl-dev libusb-1.0-0-dev libserialport-dev libpolyclipping-dev
  libopenmesh-dev libmosquitto-dev
  hershey-fonts-data libumockdev-dev umockdev
  # the workshop page's 3D view, served from Debian's path
  libjs-three
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev ghostscript hyperfine
  # the nesting benchmark's baseline: the same parts through libnest2d
  libnest2d-dev libnlopt-cxx-dev
  # real tools that read our SVG and DXF sheets in the tests
  librsvg2-bin libxml2-utils python3-ezdxf inkscape
  # a real browser for the workshop page's tests (headless, over DevTools)
  chromium
  # a real PostgreSQL server for the job store's tests (scripts/test-postgres.sh)
  postgresql-15
  # a real MQTT broker and subscriber for the notifications' tests
  mosquitto mosquitto-clients
  # meshes other people made, read by the tests where these packages install
  # them (tests/data/external/README.md)
  assimp-testmodels geomview openscad-testing-data libcgal-demo
)

if [[ -z "${ROTAFAB_SKIP_APT:-}" ]]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  if ((${#missing[@]})); then
    sudo=""
    [[ $(id -u) -eq 0 ]] || sudo="sudo"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update
    $sudo apt-get install -y --no-install-recommends "${missing[@]}"
  fi
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
