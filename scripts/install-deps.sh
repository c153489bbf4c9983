#!/usr/bin/env bash
# Installs what kdet needs to build and test on Debian (run as root). Skips apt when all is there.
set -euo pipefail
# python3-venv and python3-dev: the Python package is built (headers) and tested in a virtual environment;
# ninja-build: the generator scikit-build-core uses for it, the same one for every pip call; ccache: the
# test command's later builds of the library (Python package, consumer) reuse the first one's objects.
packages=(cmake g++ make libgtest-dev libbenchmark-dev libcgal-dev python3 python3-venv python3-dev ninja-build ccache
  clang libclang-rt-14-dev tetgen)
# The kdet command: CLI11 parses its command lines, nlohmann/json writes `kdet collide --json`.
packages+=(libcli11-dev nlohmann-json3-dev)
# kdet::mpi, distributed detection, and its tests under mpirun: Debian's OpenMPI.
packages+=(openmpi-bin libopenmpi-dev)
# `kdet view`: GLFW, Dear ImGui (with its GLFW and OpenGL 3 backends), libepoxy, libpng; its tests draw
# under Xvfb with Mesa's software renderer (llvmpipe).
packages+=(pkg-config libglfw3-dev libimgui-dev libepoxy-dev libpng-dev xvfb xauth libgl1-mesa-dri)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi
# Optional: matplotlib for the figures of `kdet plot` (python/requirements.txt). Building and testing do not
# need it, so a failure only warns.
if ! python3 -c "import matplotlib" >/dev/null 2>&1; then
  requirements="$(dirname "$0")/../python/requirements.txt"
  pip_install=(python3 -m pip install -q --timeout 30 --root-user-action=ignore -r "$requirements")
  { python3 -m pip --version >/dev/null 2>&1 || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-pip >/dev/null; } &&
    { "${pip_install[@]}" || "${pip_install[@]}" --break-system-packages; } ||
    echo "warning: matplotlib not installed; kdet plot needs it (pip install -r python/requirements.txt)" >&2
fi
