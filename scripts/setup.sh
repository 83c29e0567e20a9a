# Shared set-up for scripts/demo, scripts/test and scripts/bench/bench.sh (sourced, not run):
# installs missing Debian packages, Open Image Denoise and (with CANDELA_INTEL_OPENCL=1) Intel's OpenCL CPU
# runtime, then configures and builds Release into build/
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

# Intel's OpenCL CPU runtime, with CANDELA_INTEL_OPENCL=1: the PyPI packages intel-opencl-rt and
# intel-cmplr-lib-rt (with tbb and tcmlib; about 270 MB to download, 500 MB installed) installed
# into a scratch prefix, their libraries moved to build/intel-opencl/lib (libintelocl.so finds
# the others beside itself), an ICD file written beside them, build/intel-opencl/intel-cpu.icd,
# and links to its oneTBB in build/intel-opencl/tbb.
# candela adds that ICD to the system's (docs/devices.md). Skipped when there; without PyPI
# one notice, and the rest goes on.
CANDELA_INTEL_OPENCL_PACKAGES=("intel-opencl-rt==2026.*" "intel-cmplr-lib-rt==2026.*")
candela_install_intel_opencl() {
  local dest="$CANDELA_ROOT/build/intel-opencl"
  [ "${CANDELA_INTEL_OPENCL:-0}" = 1 ] || return 0
  [ -e "$dest/lib/libintelocl.so" ] && [ -e "$dest/tbb/libtbb.so.12" ] && [ -e "$dest/intel-cpu.icd" ] && return 0
  local tmp
  tmp=$(mktemp -d)
  echo "candela: installing Intel's OpenCL CPU runtime (PyPI ${CANDELA_INTEL_OPENCL_PACKAGES[*]}, about 270 MB) into $dest" >&2
  if python3 -m pip install -q --disable-pip-version-check --no-warn-script-location --ignore-installed \
    --prefix "$tmp/prefix" "${CANDELA_INTEL_OPENCL_PACKAGES[@]}" >/dev/null 2>&1 &&
    python3 - "$tmp/prefix" "$dest" <<'PY'
import filecmp, glob, os, shutil, sys
prefix, dest = sys.argv[1], sys.argv[2]
# The libraries' folder: prefix/lib, or prefix/local/lib under Debian's Python
lib = os.path.dirname(glob.glob(os.path.join(prefix, '**', 'libintelocl.so'), recursive=True)[0])
# The wheels carry each library under all its names as copies: keep one, link the others
files = sorted((f for f in os.listdir(lib) if os.path.isfile(os.path.join(lib, f))), key=lambda f: (-len(f), f))
for i, f in enumerate(files):
    for g in files[:i]:
        a, b = os.path.join(lib, f), os.path.join(lib, g)
        if not os.path.islink(b) and os.path.getsize(a) == os.path.getsize(b) and filecmp.cmp(a, b, shallow=False):
            os.remove(a)
            os.symlink(g, a)
            break
shutil.rmtree(dest, ignore_errors=True)
os.makedirs(dest)
shutil.move(lib, os.path.join(dest, 'lib'))
# Its oneTBB, newer than Debian's, where candela's RPATH looks first (CMakeLists.txt)
os.makedirs(os.path.join(dest, 'tbb'))
for f in os.listdir(os.path.join(dest, 'lib')):
    if f.startswith('libtbb'):
        os.symlink(os.path.join('..', 'lib', f), os.path.join(dest, 'tbb', f))
with open(os.path.join(dest, 'intel-cpu.icd'), 'w') as icd:
    icd.write(os.path.join(os.path.abspath(dest), 'lib', 'libintelocl.so') + '\n')
PY
  then
    echo "candela: Intel's OpenCL CPU runtime is in $dest (candela lists it as Intel(R) OpenCL; --device intel)" >&2
  else
    echo "candela: note: could not install Intel's OpenCL CPU runtime from PyPI (offline, or no pip): --device intel is unavailable; the rest works" >&2
  fi
  rm -rf "$tmp"
}

candela_install_packages
candela_install_oidn
candela_install_intel_opencl
[ "${CANDELA_SKIP_BUILD:-0}" = 1 ] || candela_build
