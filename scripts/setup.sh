#!/usr/bin/env bash
# Installs every Debian package costar needs (idempotent) and builds it with ccache.
#   bash scripts/setup.sh                      # install + configure + build everything into build/
#   bash scripts/setup.sh costar costar-robot  # ... build only these targets (and what they need)
#   COSTAR_BUILD_DIR=out bash scripts/setup.sh
# Safe to run again: installs only what is missing, rebuilds only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR="${COSTAR_BUILD_DIR:-build}"

# One list, one place: what a fresh Debian 12 machine needs to build and test costar.
PACKAGES=(
  # toolchain
  g++ cmake ninja-build ccache pkg-config python3 clang libclang-rt-14-dev
  # test and benchmark frameworks
  libgtest-dev libgmock-dev libbenchmark-dev
  # libraries of the engine, the component model and the CLI
  libpugixml-dev nlohmann-json3-dev libspdlog-dev libcli11-dev libeigen3-dev libboost-dev libpng-dev
  # the simulated workcell: MuJoCo physics, headless rendering with Mesa's EGL
  libmujoco-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
  # arm kinematics from URDF (Orocos KDL), collision checking (FCL), motion planning (OMPL)
  liborocos-kdl-dev libkdl-parser-dev liburdfdom-dev libfcl-dev libompl-dev
  # plots of trial results
  libcairo2-dev
  # the editor's server (costar serve): SQLite store; Boost.Beast comes with libboost-dev
  libsqlite3-dev
  # perception: point clouds and ObjRecRANSAC (PCL), ArUco (OpenCV contrib), the SVM (libsvm)
  libpcl-dev libopencv-dev libopencv-contrib-dev libsvm-dev
  # components in other processes and machines over DDS (dds/): Eclipse CycloneDDS and its idlc
  cyclonedds-dev cyclonedds-tools
)

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  SUDO="sudo"
fi

missing=()
for package in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#PACKAGES[@]} packages already installed"
fi

export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
JOBS="$(nproc)"
echo "setup: configuring $BUILD_DIR (Release, ccache)"
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache \
  -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
if [[ $# -gt 0 ]]; then
  echo "setup: building $* with $JOBS job(s)"
  cmake --build "$BUILD_DIR" -j "$JOBS" --target "$@"
else
  echo "setup: building everything with $JOBS job(s)"
  cmake --build "$BUILD_DIR" -j "$JOBS"
fi
echo "setup: done; the costar executable is $BUILD_DIR/cli/costar"
