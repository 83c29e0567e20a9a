# Shared set-up for scripts/demo, scripts/test and scripts/bench/bench.sh (sourced, not run):
# installs missing Debian packages, then configures and builds Release into build/
# (scripts/fuzz sets CANDELA_SKIP_BUILD=1: it builds build-fuzz/ with clang instead).
set -euo pipefail

CANDELA_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
CANDELA_PACKAGES=(
  cmake g++ make pkg-config python3
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers clinfo
  mesa-opencl-icd
  libtinygltf-dev nlohmann-json3-dev libdraco-dev libmeshoptimizer-dev
  libopenimageio-dev openimageio-tools libglm-dev libcli11-dev libnanovdb-dev libopenvdb-dev
  googletest libgtest-dev clang-format
  python3-numpy python3-openimageio python3-matplotlib python3-pil
)
# A script sourcing this may add packages (scripts/fuzz: clang and libFuzzer)
read -r -a _candela_extra <<<"${CANDELA_EXTRA_PACKAGES:-}"
CANDELA_PACKAGES+=("${_candela_extra[@]}")

candela_install_packages() {
  local missing=()
  for p in "${CANDELA_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "candela: installing ${missing[*]}" >&2
  local sudo=()
  [ "$(id -u)" -ne 0 ] && sudo=(sudo)
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# CANDELA_BUILD_TARGETS (e.g. "candela"): build only those targets (scripts/demo: the
# renderer without the test suite); default everything
candela_build() {
  local jobs targets=()
  jobs=$(nproc 2>/dev/null || echo 2)
  for t in ${CANDELA_BUILD_TARGETS:-}; do targets+=(--target "$t"); done
  cmake -S "$CANDELA_ROOT" -B "$CANDELA_ROOT/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$CANDELA_ROOT/build" -j "$jobs" "${targets[@]}"
}

candela_install_packages
[ "${CANDELA_SKIP_BUILD:-0}" = 1 ] || candela_build
