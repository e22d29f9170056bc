#!/usr/bin/env bash
# Install the Debian packages the build, tests and demo need, when any is missing.
# All come from Debian's own archive (no pip). Needs root (or sudo) only if something is missing.
set -euo pipefail
packages=(build-essential cmake ninja-build ccache git xz-utils ca-certificates
          libopenmpi-dev openmpi-bin libfftw3-dev libeigen3-dev voro++-dev libpng-dev
          libgtest-dev libgmock-dev libbenchmark-dev libyaml-dev
          python3 python3-numpy python3-scipy python3-matplotlib python3-pytest
          python3-pandas python3-tqdm python3-venv python3-pip python3-setuptools
          python3-sphinx python3-myst-parser python3-sphinx-rtd-theme python3-sphinx-argparse
          snakemake)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "-- Debian packages: all ${#packages[@]} present"
  exit 0
fi
echo "-- Debian packages missing: ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "ERROR: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
$SUDO apt-get update
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
