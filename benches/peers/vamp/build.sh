#!/usr/bin/env bash
# Builds benches/peers/vamp/mbm.cc against VAMP's C++ headers into target/peers/vamp-mbm.
#
#   benches/peers/vamp/build.sh VAMP_DIR PDQSORT_DIR
#
# VAMP_DIR: a checkout of https://github.com/KavrakiLab/vamp (its src/impl headers; no Python,
# no CMake); PDQSORT_DIR: https://github.com/orlp/pdqsort. Needs g++ ≥ 10 and Eigen 3
# (Debian: libeigen3-dev). Nigh, VAMP's nearest-neighbour library, is replaced by the exhaustive
# scan in nigh-shim/ (see README.md). Compiled as VAMP compiles itself: -O3, the host's vector
# instructions. VAMP_MARCH sets another -march (`haswell`: AVX2 without AVX-512, for valgrind)
# and VAMP_OUT another program path.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
if [ $# -ne 2 ] || [ ! -f "$1/src/impl/vamp/robots/panda.hh" ] || [ ! -f "$2/pdqsort.h" ]; then
  echo "usage: $0 VAMP_DIR PDQSORT_DIR  (VAMP_DIR/src/impl/vamp/robots/panda.hh and PDQSORT_DIR/pdqsort.h must exist)" >&2
  exit 2
fi
eigen=${EIGEN_DIR:-/usr/include/eigen3}
[ -f "$eigen/Eigen/Dense" ] || { echo "no Eigen at $eigen: apt install libeigen3-dev, or set EIGEN_DIR" >&2; exit 2; }
out=${VAMP_OUT:-$root/target/peers/vamp-mbm}
[ ! -d "$out" ] || { echo "VAMP_OUT=$out is a directory: give the program's file path (e.g. $out/vamp-mbm)" >&2; exit 2; }
mkdir -p "$(dirname "$out")"
${CXX:-g++} -std=c++17 -O3 -march="${VAMP_MARCH:-native}" -DNDEBUG -w \
  -I"$1/src/impl" -I"$here/nigh-shim" -I"$2" -I"$eigen" \
  "$here/mbm.cc" -o "$out.tmp"
mv "$out.tmp" "$out"
echo "built $out"
