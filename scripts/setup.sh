# Shared set-up for scripts/demo, scripts/test and scripts/bench/bench.sh (sourced, not run):
# installs missing Debian packages and Open Image Denoise, then configures and builds Release into build/
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
  python3-numpy python3-openimageio python3-matplotlib python3-pil python3-pip
  # candela view's window (GLFW, Dear ImGui, Mesa's OpenGL) and its test (ctest view: Xvfb, xdotool, xwd)
  libglfw3-dev libimgui-dev libgl1-mesa-dri xvfb xdotool x11-apps
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

# Intel Open Image Denoise for `render --denoise`: the official libraries of the PyPI wheel
# pyoidn, unpacked into build/oidn/lib (where candela looks beside its executable). Skipped
# when there, or with CANDELA_SKIP_OIDN=1; without PyPI (or pip) one notice, and the rest goes on.
CANDELA_OIDN_WHEEL="pyoidn>=2.5,<2.6"
candela_install_oidn() {
  local dest="$CANDELA_ROOT/build/oidn"
  [ "${CANDELA_SKIP_OIDN:-0}" = 1 ] && return 0
  [ -e "$dest/lib/libOpenImageDenoise.so.2" ] && return 0
  local tmp
  tmp=$(mktemp -d)
  echo "candela: fetching Open Image Denoise (the PyPI wheel $CANDELA_OIDN_WHEEL, about 90 MB) for --denoise" >&2
  if python3 -m pip download -q --no-deps --only-binary=:all: -d "$tmp" "$CANDELA_OIDN_WHEEL" >/dev/null 2>&1 &&
    python3 - "$tmp" "$dest" <<'PY'
import glob, os, sys, zipfile
tmp, dest = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(glob.glob(os.path.join(tmp, 'pyoidn-*.whl'))[0]) as wheel:
    os.makedirs(os.path.join(dest, 'lib.part'), exist_ok=True)
    for item in wheel.infolist():
        name = item.filename[len('pyoidn/oidn/lib/'):]
        if item.filename.startswith('pyoidn/oidn/lib/') and name and '/' not in name:
            target = os.path.join(dest, 'lib.part', name)
            with wheel.open(item) as src, open(target, 'wb') as out:
                out.write(src.read())
os.replace(os.path.join(dest, 'lib.part'), os.path.join(dest, 'lib'))
PY
  then
    echo "candela: Open Image Denoise is in $dest/lib" >&2
  else
    rm -rf "$dest/lib.part"
    echo "candela: note: could not fetch Open Image Denoise from PyPI (offline, or no pip): render --denoise is unavailable; the rest works" >&2
  fi
  rm -rf "$tmp"
}

candela_install_packages
candela_install_oidn
[ "${CANDELA_SKIP_BUILD:-0}" = 1 ] || candela_build
