#!/usr/bin/env bash
# Installs the Debian packages clod needs (only the missing ones). Run as root.
#   scripts/install-deps.sh            build + test dependencies
#   scripts/install-deps.sh --peers    also the comparison peers used by bench/ (CGAL, Embree, FCL, OpenVDB; Bullet is a build dependency)
#   scripts/install-deps.sh --fuzz     also clang 16 and its libFuzzer runtime (scripts/fuzz.sh)
set -euo pipefail
packages=(build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libassimp-dev libtbb-dev nlohmann-json3-dev libcli11-dev libqhull-dev libxxhash-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libtinygltf-dev gnuplot-nox chromium nodejs
  libmujoco-dev  # MuJoCo 2.2.2: the clod_mujoco plug-in and its tests (engines/mujoco)
  libbullet-dev  # Bullet 3.24: the clod_bullet plug-in and its tests (engines/bullet, docs/engines.md)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-dask python3-distributed python3-matplotlib
  python3-venv python3-pip python3-setuptools python3-wheel)
for arg in "$@"; do
  case "$arg" in
    --peers) packages+=(libcgal-dev libembree-dev libfcl-dev libopenvdb-dev) ;;
    --fuzz) packages+=(clang-16 libclang-rt-16-dev) ;;  # clang 16: C++20 lambda captures of structured bindings (14 lacks them)
    *) echo "install-deps.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm ships inside some nodejs builds (NodeSource) and separately in Debian's: ask for it only when absent.
command -v npm >/dev/null 2>&1 || missing+=(npm)
if ((${#missing[@]})); then
  echo "install-deps.sh: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
