#!/usr/bin/env bash
# Intel's OpenCL CPU runtime (scripts/setup.sh with CANDELA_INTEL_OPENCL=1): without it,
# `--device intel` is one error line that says how to install it; with it, `candela devices`
# lists it after the other platforms, a few kernel tests pass on it (CANDELA_TEST_DEVICE=intel)
# and `candela compare` finds its Cornell box consistent with PoCL's. Skipped (77) where it
# is not installed.
# Usage: intel_test.sh path/to/candela path/to/candela_tests repo_root
set -u
bin=$1
tests=$2
root=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=$root/scenes/cornell-box/cornell-box.gltf

# A loader that reads the system's ICD files only (candela leaves a set OCL_ICD_VENDORS alone)
OCL_ICD_VENDORS=/etc/OpenCL/vendors "$bin" render "$scene" --device intel --spp 1 --width 8 --height 8 \
  -o "$tmp/x.png" >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -ne 1 ] || [ "$(grep -c '^candela: error' "$tmp/err")" -ne 1 ] ||
  ! grep -q 'CANDELA_INTEL_OPENCL=1 bash scripts/setup.sh' "$tmp/err"; then
  echo "FAIL: --device intel without the runtime: exit $rc, expected one error line naming the switch:"
  cat "$tmp/err"
  exit 1
fi
echo "ok: --device intel without the runtime: $(cat "$tmp/err")"

"$bin" devices >"$tmp/devices" || exit 1
if ! grep -q '(Intel(R) OpenCL)$' "$tmp/devices"; then
  echo "skip: Intel's OpenCL CPU runtime is not installed (CANDELA_INTEL_OPENCL=1 bash scripts/setup.sh installs it into the build folder)"
  exit 77
fi
cat "$tmp/devices"
if [ "$(grep -E '^[0-9]' "$tmp/devices" | tail -1 | grep -c '(Intel(R) OpenCL)$')" -ne 1 ]; then
  echo "FAIL: Intel's runtime is not listed last"
  exit 1
fi

# Kernel tests of the sampler, the BVH walk and the furnace renders on Intel's runtime (the
# tests' "pocl" device is CANDELA_TEST_DEVICE)
CANDELA_TEST_DEVICE=intel "$tests" --gtest_brief=1 \
  --gtest_filter='Devices/SamplerTest.*/pocl:Devices/BvhTest.*/pocl:Devices/FurnaceTest.*/pocl_*' ||
  { echo "FAIL: kernel tests on Intel's runtime"; exit 1; }
echo "ok: kernel tests on Intel's runtime"

"$bin" compare "$scene" --devices pocl,intel --spp 32 --width 48 -q || { echo "FAIL: compare pocl,intel"; exit 1; }
echo "ok: compare pocl,intel"
