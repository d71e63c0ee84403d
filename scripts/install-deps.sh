#!/usr/bin/env bash
# Installs the Debian packages backlash builds against — only those missing.
# Idempotent: when everything is installed it touches neither apt nor the
# network, so it also works offline.  Installing needs root (or sudo).
set -euo pipefail

required_packages=(
  build-essential cmake pkg-config
  libginac-dev libcln-dev ginac-tools
  libeigen3-dev libboost-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libfmt-dev
  gnuplot-nox librsvg2-bin
  libceres-dev libmatio-dev
  libhdf5-dev libopenmpi-dev openmpi-bin libboost-mpi-dev
  texlive-latex-base texlive-latex-recommended texlive-fonts-recommended poppler-utils
  python3-sympy python3-mpmath python3-scipy python3-numpy python3-pytest python3-dev pybind11-dev
  emscripten nodejs chromium
)

missing_packages=()
for package in "${required_packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  if [[ "$status" != "install ok installed" ]]; then
    missing_packages+=("$package")
  fi
done

if [[ ${#missing_packages[@]} -eq 0 ]]; then
  echo "install-deps: all ${#required_packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing_packages[*]}"
if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "install-deps: error: missing packages (${missing_packages[*]}) and not root; rerun as root" >&2
  exit 1
fi

"${as_root[@]}" apt-get update
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing_packages[@]}"
