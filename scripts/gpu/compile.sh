#!/usr/bin/env bash
# GPU shape of the renderer's program without a GPU: compiles every kernel variant (the
# options `candela render` builds for each shipped scene, and --generic's) offline with
# Debian's clang 19 for AMDGPU (gfx90a, gfx1030) and NVPTX (sm_80, sm_90), as a driver would
# see it: the host's program text (build/tests/candela_kernel_source), OpenCL C 1.2 at -O3,
# libclc's builtins linked, every function but the kernels internalized. Prints one JSON line
# per variant and target for render_paths: AMDGPU VGPRs, AGPRs, SGPRs, scratch bytes per
# lane, spills and occupancy; PTX registers, stack and spills from ptxas -v (CUDA toolkit,
# when installed) and the .local bytes of the PTX. Fails on any compile error or warning
# (with -Wkeyword-macro -Wgnu -pedantic) and on GNU C's typeof in the program text.
#
# Usage: scripts/gpu/compile.sh [--quick] [--out FILE] [--markdown] [--jobs N] [--ci]
#   --quick     measure the generic and the smallest variant; the others go through the front
#               end only (its errors and warnings are still checked)
#   --out FILE  append the JSON lines to FILE
#   --markdown  print tables instead of JSON lines
#   --jobs N    compiles at once (default: one per core)
#   --ci        exit 0 with a notice when clang 19 or libclc cannot be installed or fetched
#               (apt is given CANDELA_GPU_COMPILE_APT_TIMEOUT seconds, default 900)
# ptxas comes from CANDELA_PTXAS (a path, or none), PATH or /usr/local/cuda/bin.
# Work files and the unpacked libclc (kept between runs) are in build/gpu-compile/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
ci=0
for a in "$@"; do [ "$a" = --ci ] && ci=1; done

# clang 19 and its LLVM tools (opt, llc) from Debian, installed the way setup.sh installs
# packages; a slow or failing apt only skips this check under --ci
tools_missing() {
  for t in clang-19 opt-19 llc-19 llvm-dis-19 llvm-as-19; do command -v "$t" >/dev/null || return 0; done
  return 1
}
if tools_missing; then
  timeout "${CANDELA_GPU_COMPILE_APT_TIMEOUT:-900}" env CANDELA_EXTRA_PACKAGES="clang-19 llvm-19" \
    CANDELA_SKIP_BUILD=1 bash -c "source '$root/scripts/setup.sh'" || true
  if tools_missing; then
    echo "candela: clang-19 and llvm-19 could not be installed" >&2
    [ "$ci" = 1 ] && { echo "candela: skipping the GPU compile check" >&2; exit 0; }
    exit 1
  fi
fi
source "$root/scripts/setup.sh" >&2
cmake --build "$root/build" --target candela_kernel_source candela >&2

# libclc 19's bitcode, unpacked from its .deb (installing libclc-19 would remove
# mesa-opencl-icd), each library's triple set to the target's (no linker warning)
work=$root/build/gpu-compile
clc=$work/libclc-19
if [ ! -f "$clc/ready" ]; then
  rm -rf "$clc" "$work/deb"
  mkdir -p "$work/deb"
  if ! (cd "$work/deb" && timeout "${CANDELA_GPU_COMPILE_APT_TIMEOUT:-900}" apt-get download -q libclc-19 >download.log 2>&1); then
    cat "$work/deb/download.log" >&2
    echo "candela: cannot download libclc-19 (apt-get download libclc-19)" >&2
    [ "$ci" = 1 ] && { echo "candela: skipping the GPU compile check" >&2; exit 0; }
    exit 1
  fi
  dpkg -x "$work"/deb/libclc-19_*.deb "$work/deb/root"
  mkdir -p "$clc"
  for lib in amdgcn--amdhsa:amdgcn-amd-amdhsa nvptx64--nvidiacl:nvptx64-nvidia-cuda; do
    llvm-dis-19 "$work/deb/root/usr/lib/clc/${lib%%:*}.bc" -o - |
      sed "s/^target triple = .*/target triple = \"${lib#*:}\"/" | llvm-as-19 -o "$clc/${lib#*:}.bc"
  done
  dpkg-deb -f "$work"/deb/libclc-19_*.deb Version >"$clc/version"
  rm -rf "$work/deb"
  touch "$clc/ready"
fi

exec python3 "$root/scripts/gpu/compile_kernels.py" "$root" "$@"
