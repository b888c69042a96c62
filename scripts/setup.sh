#!/usr/bin/env bash
# Installs shapedb's Debian 12 packages (only those missing; silent when all are there) and builds one
# CMake preset (default: release), or only the given targets of it.
# Usage: scripts/setup.sh [release|debug|asan|tsan|fuzz] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
targets=("$@")

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libopenvdb-dev libboost-dev libboost-iostreams-dev libtbb-dev libtet1.5-dev libeigen3-dev
  libopenmesh-dev libspectra-dev libgtest-dev googletest libbenchmark-dev libcli11-dev
  nlohmann-json3-dev libtinygltf-dev libassimp-dev libsqlite3-dev libstb-dev zlib1g-dev sqlite3 libbullet-dev
  libsuitesparse-dev libopenblas0-pthread
  python3-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
  libopenmpi-dev openmpi-bin
)
# The sanitizer presets asan and fuzz build with Clang (fuzz links libFuzzer).
case "$preset" in asan | fuzz) packages+=(clang-14 libclang-rt-14-dev) ;; esac
missing=()
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

echo "setup: building preset '$preset' in build/$preset"
mkdir -p build
cmake --preset "$preset" >"build/configure-$preset.log" 2>&1 || { cat "build/configure-$preset.log"; exit 1; }
if ((${#targets[@]})); then
  cmake --build "build/$preset" --target "${targets[@]}"
else
  cmake --build --preset "$preset"
fi
