#!/usr/bin/env bash
# Installs auvdock's build and test dependencies from Debian 12 packages.
# Idempotent: only calls apt-get when a package is missing. Must run as root (or via sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev
  libopencv-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  opencv-doc  # sample chessboards (examples/data/left*.jpg) for the PnP agreement tests
  python3-matplotlib  # `evaluate --plots` (scripts/plot_run.py, run with /usr/bin/python3)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "install_deps: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
