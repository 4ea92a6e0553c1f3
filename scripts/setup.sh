#!/usr/bin/env bash
# Installs the Debian 12 packages octiso builds, tests and benchmarks with. Idempotent: a package
# already present is not fetched again, and apt-get update runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libtbb-dev libembree-dev libopenimageio-dev openimageio-tools libvtk9-dev
  libgtest-dev libbenchmark-dev libxxhash-dev zstd libzstd-dev libpng-dev libopenexr-dev zlib1g-dev
  libopenvdb-dev libboost-iostreams-dev mricron-data invesalius-examples
  python3-numpy python3-matplotlib python3-dev pybind11-dev python3-pytest python3-nibabel clang
  nlohmann-json3-dev libfmt-dev libcli11-dev python3-pil
  libcpp-httplib-dev chromium chromium-driver python3-selenium
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[[ $(id -u) -ne 0 ]] && SUDO="sudo"
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
