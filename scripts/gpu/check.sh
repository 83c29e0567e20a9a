#!/bin/bash
# Renders the shipped scenes on a GPU machine's OpenCL device and checks them against PoCL.
#
#   scripts/gpu/check.sh prepare DIR        here: DIR/bundle.tar.xz (scripts/gpu/portable_bundle.py of this
#                                        build) and DIR/assets (sample assets from ../shared)
#   scripts/gpu/check.sh run DIR OUT [SEC]  on the GPU machine (no build, no packages needed: the
#                                        bundle carries candela and its libraries): the device
#                                        list, a kept render per scene (seed 1, and seed 0 for the
#                                        determinism check), speed renders, the registers and
#                                        spills of each kernel's PTX (ptxas -v), and the kernel
#                                        tests on the device; everything under OUT, in about SEC
#                                        seconds (default 300: each phase stops at its deadline)
#   scripts/gpu/check.sh compare OUT        here: `candela compare SCENE --devices pocl,kept:...`
#                                        for every kept render (the z-test and determinism check
#                                        of docs/devices.md), a table in OUT/compare.txt
#
# The vendor's OpenCL driver is found by name (libnvidia-opencl.so.1, libamdocl64.so,
# libigdrcl.so) under the usual library folders and handed to the bundled ICD loader through
# OCL_ICD_VENDORS; --device "$DEV" picks it.
set -u
here=$(cd "$(dirname "$0")/../.." && pwd)
DEV=${GPU_CHECK_DEVICE:-gpu}  # a dry run here: GPU_CHECK_DEVICE=pocl

# The z-test renders: scene, then every option but the seed (PoCL renders the same here)
ZWIDTH=128
ZSPP=256
ZSCENES=(
  scenes/cornell-box/cornell-box.gltf
  scenes/materials/materials.gltf
  assets/DamagedHelmet/glTF-Binary/DamagedHelmet.glb
  scenes/lights/veach.gltf
  scenes/lights/environment.gltf
  scenes/lights/many-lights.gltf
  scenes/lights/punctual.gltf
  scenes/volumes/cloud.gltf
  scenes/materials/iridescence.gltf
  scenes/lights/near-specular.gltf
  scenes/volumes/liquid-glass.gltf
  assets/Fox/Fox.gltf
  scenes/lights/small-light.gltf
  scenes/lights/large-light-glossy.gltf
  scenes/lights/near-specular-sky.gltf
  scenes/volumes/god-rays.gltf
  scenes/volumes/plume.gltf
  assets/2CylinderEngine_draco/2CylinderEngine.gltf
  scenes/furnace/white-objects.gltf
  scenes/furnace/closed-sphere.gltf
)
# The speed renders: name|scene|options
SPEED=(
  "cornell-512-d8|scenes/cornell-box/cornell-box.gltf|--width 512 --max-depth 8 --spp 1024"
  "materials-512|scenes/materials/materials.gltf|--width 512 --spp 256"
  "DamagedHelmet-512|assets/DamagedHelmet/glTF-Binary/DamagedHelmet.glb|--width 512 --spp 256"
  "2CylinderEngine-512|assets/2CylinderEngine_draco/2CylinderEngine.gltf|--width 512 --spp 256"
  "Fox-512|assets/Fox/Fox.gltf|--width 512 --spp 256"
  "veach-512|scenes/lights/veach.gltf|--width 512 --spp 256"
  "cloud-256|scenes/volumes/cloud.gltf|--width 256 --spp 64"
)

name_of() { local b; b=$(basename "$1"); echo "${b%.*}"; }
# A scene's path: assets/ live in the prepared folder, scenes/ in the checkout
scene_path() { case "$1" in assets/*) echo "$2/$1" ;; *) echo "$here/$1" ;; esac; }

prepare() {
  local dir=$1
  mkdir -p "$dir/assets"
  "$here/scripts/gpu/portable_bundle.py" "$dir/bundle.tar.xz" "$here/build/candela" "$here/build/tests/candela_tests" || exit 1
  for a in DamagedHelmet Fox 2CylinderEngine_draco; do
    cp -r "$here/../shared/gltf-samples/$a" "$dir/assets/" || exit 1
  done
  du -sh "$dir"
}

find_vendor_driver() {
  local lib
  for name in libnvidia-opencl.so.1 libamdocl64.so libigdrcl.so; do
    lib=$(ldconfig -p 2>/dev/null | awk -v n="$name" '$1 == n { print $NF; exit }')
    [ -z "$lib" ] && lib=$(find /usr/local/nvidia /usr/lib /usr/lib64 /usr/local/lib /opt -name "$name" 2>/dev/null | head -1)
    [ -n "$lib" ] && { echo "$lib"; return 0; }
  done
  return 1
}

run_on_gpu() {
  local dir out budget start
  dir=$(cd "$1" && pwd); out=$2; budget=${3:-300}; start=$(date +%s)
  mkdir -p "$out/kept" "$out/speed" "$out/ptx"
  left() { echo $((start + budget * $1 / 100 - $(date +%s))); }  # seconds to phase deadline ($1 % of budget)
  local log="$out/log.txt"
  exec > >(tee -a "$log") 2>&1
  echo "gpu-check on $(hostname), $(date -u +%FT%TZ), budget ${budget}s"
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>&1 | tee "$out/gpu.txt"
  local b=/tmp/gpu-check
  rm -rf "$b" && mkdir -p "$b"
  python3 -c "import tarfile, sys; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" "$dir/bundle.tar.xz" "$b" || exit 1
  local run="$b/candela-bundle/run"
  local lib
  if lib=$(find_vendor_driver); then
    mkdir -p "$b/icd" && echo "$lib" >"$b/icd/vendor.icd"
    export OCL_ICD_VENDORS="$b/icd"
    echo "vendor driver: $lib"
  else
    echo "no vendor OpenCL driver found; /etc/OpenCL/vendors:"; ls -la /etc/OpenCL/vendors 2>&1
    ls /usr/local/nvidia /usr/local/nvidia/lib* 2>&1 | head -40
  fi
  "$run" candela devices | tee "$out/devices.txt"
  if [ "$DEV" = gpu ] && ! "$run" candela devices | grep -q " gpu "; then echo "no GPU device: stopping"; return 1; fi
  # The checkout's own path, where the test program looks for scenes
  [ -e /work/main ] || { mkdir -p /work && ln -s "$here" /work/main; }

  echo "== kept renders for the z-test: ${ZWIDTH} px, ${ZSPP} spp (phase ends at 45 %)"
  for s in "${ZSCENES[@]}"; do
    [ "$(left 45)" -gt 5 ] || { echo "deadline: skipping the rest from $s"; break; }
    local n k t0; n=$(name_of "$s"); k="$out/kept/$n"; mkdir -p "$k"; t0=$(date +%s.%N)
    export CANDELA_CACHE_DIR="$b/cache/$n"
    local p; p=$(scene_path "$s" "$dir")
    timeout "$(left 45)" "$run" candela render "$p" -o "$k/cold.exr" --stats "$k/cold.json" --spp 1 --width $ZWIDTH --seed 1 --device "$DEV" -q >"$k/log.txt" 2>&1 &&
      timeout "$(left 45)" "$run" candela render "$p" -o "$k/main.exr" --variance "$k/main-variance.exr" --stats "$k/main.json" --spp $ZSPP --width $ZWIDTH --seed 1 --device "$DEV" -q >>"$k/log.txt" 2>&1 &&
      timeout "$(left 45)" "$run" candela render "$p" -o "$k/same-seed.exr" --stats "$k/same-seed.json" --spp $ZSPP --width $ZWIDTH --seed 0 --device "$DEV" -q >>"$k/log.txt" 2>&1
    local rc=$?
    rm -f "$k/cold.exr"
    python3 - "$k" "$rc" "$t0" <<'PY'
import json, os, sys, time
k, rc, t0 = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
def stat(name, key):
    try: return json.load(open(os.path.join(k, name))).get(key)
    except Exception: return None
print(f"{os.path.basename(k):28s} rc {rc}  build cold {stat('cold.json', 'kernel_build_seconds') or 0:7.2f} s  "
      f"render {stat('main.json', 'seconds') or 0:7.3f} s  {(stat('main.json', 'samples_per_second') or 0) / 1e6:9.2f} Msamples/s  "
      f"dropped {stat('main.json', 'dropped_samples')}  wall {time.time() - t0:6.1f} s")
PY
    [ $rc -eq 0 ] || tail -5 "$k/log.txt"
  done

  echo "== speed renders (phase ends at 55 %)"
  for e in "${SPEED[@]}"; do
    [ "$(left 55)" -gt 5 ] || { echo "deadline: skipping the rest from $e"; break; }
    local n s o p; IFS='|' read -r n s o <<<"$e"; p=$(scene_path "$s" "$dir")
    export CANDELA_CACHE_DIR="$b/cache/speed"
    # shellcheck disable=SC2086
    timeout "$(left 55)" "$run" candela render "$p" -o "$out/speed/$n.png" --stats "$out/speed/$n.json" $o --device "$DEV" -q 2>&1 | tail -2
  done

  echo "== ptxas -v of each kernel's PTX (phase ends at 62 %)"
  local ptxas; ptxas=$(command -v ptxas || ls /usr/local/cuda/bin/ptxas 2>/dev/null)
  python3 - "$b/cache" "$out/ptx" <<'PY'
import os, sys
src, dst = sys.argv[1], sys.argv[2]
seen = set()  # a variant's cache entry, once (the speed renders reuse the scenes' variants)
for root, _, files in sorted(os.walk(src)):
    for f in sorted(files):
        if f[:16] in seen: continue
        seen.add(f[:16])
        data = open(os.path.join(root, f), "rb").read()
        at = data.find(b"//\n// Generated by NVIDIA")
        if at < 0: at = data.find(b".version")
        if at < 0: continue
        name = os.path.basename(root) + "-" + f[:16] + ".ptx"
        open(os.path.join(dst, name), "wb").write(data[at:].split(b"\0")[0])
PY
  if [ -n "$ptxas" ]; then
    for f in "$out"/ptx/*.ptx; do
      [ -e "$f" ] && [ "$(left 62)" -gt 3 ] || break
      echo "$(basename "$f"): $(timeout "$(left 62)" "$ptxas" -arch=sm_90 -v "$f" -o /dev/null 2>&1 | grep -E "Used|stack|spill" | tr '\n' ' ')"
    done | tee "$out/ptxas.txt"
  else
    echo "no ptxas"
  fi

  echo "== kernel tests on the device (phase ends at 97 %)"
  export CANDELA_TEST_DEVICE="$DEV" CANDELA_CACHE_DIR="$b/cache/tests" TEST_TMPDIR="$b/testtmp"
  mkdir -p "$TEST_TMPDIR"
  (cd "$here" && timeout "$(left 97)" "$run" candela_tests \
    --gtest_filter='Devices/*:Lobes/*:Materials/*:SamplingTest.*:BsdfHarness.*:LightTree.*:Energy*:Determinism.*:Media/*:Render.*' \
    >"$out/tests.txt" 2>&1)
  echo "tests exit status $? ($(grep -c '^\[       OK' "$out/tests.txt") passed, $(grep -c '^\[  FAILED' "$out/tests.txt") failed lines)"
  grep -E '^\[  FAILED|^\[  PASSED|tests ran' "$out/tests.txt" | tail -30
  echo "gpu-check done in $(($(date +%s) - start)) s"
}

compare_kept() {
  local out; out=$(cd "$1" && pwd)
  local cand="$here/build/candela" assets="$here/../shared/gltf-samples"
  : >"$out/compare.txt"
  for s in "${ZSCENES[@]}"; do
    local n p; n=$(name_of "$s")
    [ -f "$out/kept/$n/main.json" ] || continue
    case "$s" in assets/*) p="$assets/${s#assets/}" ;; *) p="$here/$s" ;; esac
    echo "== $n" | tee -a "$out/compare.txt"
    "$cand" compare "$p" --devices "pocl,kept:$out/kept/$n" --spp $ZSPP --width $ZWIDTH -q \
      --json "$out/kept/$n/compare.json" 2>&1 | tee -a "$out/compare.txt"
  done
}

case "${1:-}" in
  prepare) prepare "${2:?DIR}" ;;
  run) run_on_gpu "${2:?DIR}" "${3:?OUT}" "${4:-300}" ;;
  compare) compare_kept "${2:?OUT}" ;;
  *) sed -n '2,20p' "$0"; exit 2 ;;
esac
