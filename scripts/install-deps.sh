#!/usr/bin/env bash
# Installs the Debian 12 packages fesd needs (build, tests, plots, Python). Safe to re-run.
set -euo pipefail
pkgs=(build-essential cmake pkg-config coinor-libipopt-dev libeigen3-dev libtomlplusplus-dev
      nlohmann-json3-dev libcli11-dev libfmt-dev libgtest-dev liblapack-dev libsuitesparse-dev gnuplot-nox
      python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
      python3-dask python3-distributed)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all packages present"
fi
