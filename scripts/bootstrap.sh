#!/usr/bin/env bash
# Installs the Debian packages Remora builds and tests with, if any is missing.
# As root it runs apt-get; otherwise it prints the exact command and stops (exit 1).
#
#   scripts/bootstrap.sh           the packages of the default build (make build/test/demo)
#   scripts/bootstrap.sh --bench   those plus the benchmark-only ones (make bench): libcgal-dev,
#                                  for the remeshing race against CGAL (GPL; never in the library)
#   scripts/bootstrap.sh --web     those plus Debian's chromium, which the browser editor's
#                                  end-to-end test drives (make test)
# Node.js and npm (for three.js and playwright-core, scripts/build_web.sh) are installed from
# Debian when the machine has no `npm` command. The Python module (python/, docs/python.md) is
# built against Debian's /usr/bin/python3 with its pybind11, numpy and scipy; pytest, matplotlib,
# setuptools, wheel, pip and venv are for its tests, tutorial and `pip install .`.
set -euo pipefail

bench=0
web=0
for arg in "$@"; do
  case "$arg" in
    --bench) bench=1 ;;
    --web) web=1 ;;
    *)
      echo "bootstrap: unknown argument '$arg' (usage: scripts/bootstrap.sh [--bench] [--web])" >&2
      exit 2
      ;;
  esac
done

packages=(
  build-essential cmake pkg-config clang-format
  clang lld libomp-dev libclang-rt-14-dev
  libopenmesh-dev libeigen3-dev
  libsuitesparse-dev libmetis-dev libopenblas-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev libcpp-httplib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy python3-scipy python3-pytest python3-matplotlib
  python3-setuptools python3-wheel python3-pip python3-venv
)
if [ "$bench" -eq 1 ]; then
  packages+=(libcgal-dev)
fi
if [ "$web" -eq 1 ]; then
  packages+=(chromium)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ! command -v npm >/dev/null; then
  missing+=(nodejs npm)
fi

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "bootstrap: missing Debian packages: ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "bootstrap: run this as root, then run make again:"
  echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends ${missing[*]}"
  exit 1
fi
