#!/usr/bin/env bash
# Installs every Debian 12 package scfloam needs to build, test, benchmark and plot.
# Idempotent: when everything is already there it does nothing (and needs no network).
set -euo pipefail
packages=(
  build-essential cmake git pkg-config
  libeigen3-dev libceres-dev libnanoflann-dev libtbb-dev libyaml-cpp-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libpng-dev zlib1g-dev nlohmann-json3-dev
  libsqlite3-dev libzstd-dev liblz4-dev libbz2-dev liblzf-dev
  librosbag-dev libsensor-msgs-dev  # ROS 1 bags (reader; sensor_msgs only for the writer in tests)
  libopen3d-dev
  clang libclang-rt-14-dev
  python3 python3-matplotlib python3-numpy python3-scipy  # scipy: bench/unusual_motions.py, bench/loop_edges_vs_truth.py
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
