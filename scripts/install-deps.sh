#!/usr/bin/env bash
# Installs what kdet needs to build and test on Debian (run as root). Skips apt when all is there.
set -euo pipefail
packages=(cmake g++ make libgtest-dev libbenchmark-dev libcgal-dev python3)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi
