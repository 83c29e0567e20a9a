#!/usr/bin/env bash
# Builds candela with MPI (-DCANDELA_MPI=ON, Debian's Open MPI) in build-mpi/ and runs the
# MPI test (tests/app/mpi_test.sh): two ranks under mpirun render the 16-spp image of the single-rank
# render, and --mpi with --time is refused. On a fresh Debian machine it installs what it
# needs (scripts/setup.sh plus libopenmpi-dev and openmpi-bin).
# Usage: scripts/check/mpi-test.sh
CANDELA_EXTRA_PACKAGES="libopenmpi-dev openmpi-bin"
CANDELA_SKIP_BUILD=1
source "$(dirname "${BASH_SOURCE[0]}")/../setup.sh"
set -euo pipefail
out=$CANDELA_ROOT/build-mpi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$CANDELA_ROOT" -B "$out" -DCMAKE_BUILD_TYPE=Release -DCANDELA_MPI=ON \
  "${launcher[@]}" >/dev/null
cmake --build "$out" --target candela -j "$(nproc 2>/dev/null || echo 2)"
CANDELA_CACHE_DIR=$out/test-kernel-cache bash "$CANDELA_ROOT/tests/app/mpi_test.sh" "$out/candela" "$CANDELA_ROOT"
