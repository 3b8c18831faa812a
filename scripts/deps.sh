#!/usr/bin/env bash
# Install navimpact's build and run dependencies from Debian bookworm.
# Idempotent: packages already present are not reinstalled, and apt is not
# touched at all when everything is there.
set -euo pipefail
PKGS=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libgeographiclib-dev libceres-dev libboost-math-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev zlib1g-dev
  libmrpt-obs-dev libmrpt-io-dev libmrpt-poses-dev libmrpt-random-dev
  libmrpt-system-dev libmrpt-config-dev
  mrpt-apps xvfb xauth x11-utils
  libopencv-dev libopencv-contrib-dev fonts-dejavu-core
  libgtest-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev llvm-14
  slurm-wlm munge
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PKGS[@]} packages present"
  exit 0
fi
echo "deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
