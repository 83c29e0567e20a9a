#!/usr/bin/env bash
# CLI behaviour: bad input gives one clear message and a non-zero exit; a good render
# writes EXR (with metadata), PNG and stats; Ctrl-C keeps the samples already done.
# Usage: cli_test.sh path/to/candela repo_root
set -u
bin=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
passes=0
scene=$root/scenes/cornell-box/cornell-box.gltf

pass() { passes=$((passes + 1)); echo "ok: $1"; }
fail() { fails=$((fails + 1)); echo "FAIL: $1"; }

# expect_error NAME PATTERN -- command...: non-zero exit, no crash, stderr matches PATTERN
expect_error() {
  local name=$1 pattern=$2
  shift 3
  "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ $rc -eq 0 ]; then
    fail "$name: exit 0"
  elif [ $rc -ge 128 ]; then
    fail "$name: killed by signal (exit $rc)"
  elif ! grep -q -- "$pattern" "$tmp/err"; then
    fail "$name: stderr lacks '$pattern':"; cat "$tmp/err"
  elif [ "$(grep -c '^candela: error' "$tmp/err")" -ne 1 ]; then
    fail "$name: expected one error line:"; cat "$tmp/err"
  else
    pass "$name"
  fi
}

expect_error "missing scene" "scene file not found" -- "$bin" render "$tmp/nope.gltf" -o "$tmp/x.png" --device pocl
echo '{ "asset": {"version": "2.0"}, "nodes": [ {' >"$tmp/bad.gltf"
expect_error "malformed glTF" "cannot load glTF scene" -- "$bin" render "$tmp/bad.gltf" -o "$tmp/x.png" --device pocl
printf 'glTF\x02\x00\x00\x00junk' >"$tmp/bad.glb"
expect_error "malformed GLB" "cannot load glTF scene" -- "$bin" render "$tmp/bad.glb" -o "$tmp/x.png" --device pocl
expect_error "unknown device" "no OpenCL device matches --device 'quantum'" -- "$bin" render "$scene" -o "$tmp/x.png" --device quantum
expect_error "device index out of range" "there are only" -- "$bin" render "$scene" -o "$tmp/x.png" --device 7
mkdir -p "$tmp/no-vendors"
expect_error "no OpenCL platform" "no OpenCL platform found" -- env OCL_ICD_VENDORS="$tmp/no-vendors" OCL_ICD_FILENAMES= "$bin" render "$scene" -o "$tmp/x.png"
expect_error "missing scene, no OpenCL platform" "scene file not found" -- env OCL_ICD_VENDORS="$tmp/no-vendors" OCL_ICD_FILENAMES= "$bin" render "$tmp/nope.gltf" -o "$tmp/x.png"
expect_error "no OpenCL platform (devices)" "no OpenCL platform found" -- env OCL_ICD_VENDORS="$tmp/no-vendors" OCL_ICD_FILENAMES= "$bin" devices
expect_error "bad output extension" "must end in .exr, .png or .jpg" -- "$bin" render "$scene" -o "$tmp/x.tiff" --device pocl
expect_error "bad strategy" "strategy must be nee, bsdf or auto" -- "$bin" render "$scene" -o "$tmp/x.png" --strategy mis --device pocl
expect_error "bad background" "three comma-separated numbers" -- "$bin" render "$scene" -o "$tmp/x.png" --background 1,2 --device pocl
expect_error "zero field of view" "fov must be between 0 and 180" -- "$bin" render "$scene" -o "$tmp/x.png" --fov 0 --device pocl
expect_error "field of view of 180" "fov must be between 0 and 180" -- "$bin" render "$scene" -o "$tmp/x.png" --fov 180 --device pocl
expect_error "negative aperture" "aperture must be a non-negative radius" -- "$bin" render "$scene" -o "$tmp/x.png" --aperture -0.1 --device pocl
expect_error "zero focus distance" "focus-distance must be a positive distance" -- "$bin" render "$scene" -o "$tmp/x.png" --focus-distance 0 --device pocl
expect_error "negative focus distance" "focus-distance must be a positive distance" -- "$bin" render "$scene" -o "$tmp/x.png" --focus-distance -1 --device pocl
expect_error "unknown filter" "filter must be box, tent or gaussian" -- "$bin" render "$scene" -o "$tmp/x.png" --filter lanczos --device pocl
expect_error "unknown sampler" "sampler must be sobol or independent" -- "$bin" render "$scene" -o "$tmp/x.png" --sampler halton --device pocl
expect_error "unknown default light" "default-light must be auto, on or off" -- "$bin" render "$scene" -o "$tmp/x.png" --default-light maybe --device pocl
expect_error "unknown light units" "light-units must be photometric or radiometric" -- "$bin" render "$scene" -o "$tmp/x.png" --light-units nits --device pocl
expect_error "camera index out of range" "the scene has one camera (0)" -- "$bin" render "$scene" -o "$tmp/x.png" --camera 3 --device pocl
expect_error "info on a missing scene" "scene file not found" -- "$bin" info "$tmp/nope.gltf"

# candela info: geometry, cameras, lights and the default light's choice of a shipped scene
if "$bin" info "$scene" >"$tmp/info" 2>&1 && grep -q "^geometry: 32 triangles" "$tmp/info" &&
    grep -q "^cameras: 1" "$tmp/info" && grep -q "^default light .*: none" "$tmp/info"; then
  pass "info lists the scene"
else
  fail "info lists the scene:"; cat "$tmp/info"
fi

# The Cornell box seen by an orthographic camera 0.4 wide and 0.3 high
python3 - "$scene" "$tmp/ortho.gltf" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
j["cameras"][0] = {"type": "orthographic", "orthographic": {"xmag": 0.4, "ymag": 0.3, "znear": 0.01, "zfar": 100}}
json.dump(j, open(sys.argv[2], "w"))
PY
# KHR_materials_variants: info lists them; an unknown --variant is one error naming them
python3 - "$scene" "$tmp/variants.gltf" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
j["extensions"] = dict(j.get("extensions", {}), KHR_materials_variants={"variants": [{"name": "warm"}, {"name": "cold"}]})
j["extensionsUsed"] = j.get("extensionsUsed", []) + ["KHR_materials_variants"]
j["meshes"][0]["primitives"][0]["extensions"] = {"KHR_materials_variants": {"mappings": [{"material": 0, "variants": [1]}]}}
json.dump(j, open(sys.argv[2], "w"))
PY
if "$bin" info "$tmp/variants.gltf" >"$tmp/info" 2>&1 && grep -q "^material variants .*: 2" "$tmp/info" &&
    grep -q "^  'cold'" "$tmp/info"; then
  pass "info lists the material variants"
else
  fail "info lists the material variants:"; cat "$tmp/info"
fi
expect_error "unknown material variant" "variant 'hot' is not in the scene (its variants: 'warm', 'cold')" -- "$bin" render "$tmp/variants.gltf" -o "$tmp/x.png" --variant hot --device pocl
expect_error "aperture on an orthographic camera" "aperture needs a perspective camera" -- "$bin" render "$tmp/ortho.gltf" -o "$tmp/x.png" --aperture 0.01 --device pocl
mkdir -p "$tmp/broken-cl" && cp -r "$root/cl/." "$tmp/broken-cl/" && echo "this is not OpenCL C;" >>"$tmp/broken-cl/lights/lights.cl"
expect_error "kernel build failure shows the log" "cl/lights/lights.cl:" -- "$bin" --kernel-dir "$tmp/broken-cl" render "$scene" -o "$tmp/x.png" --device pocl --spp 1

# Punctual lights: counted in the summary and the stats; one warning under --strategy bsdf
punctual=$root/scenes/lights/punctual.gltf
if "$bin" render "$punctual" -o "$tmp/p.png" --spp 1 --width 16 --height 16 --device pocl \
    --stats "$tmp/p.json" >"$tmp/out" 2>"$tmp/err" && grep -q "^scene: .* 3 lights" "$tmp/err" &&
    ! grep -q "punctual light" "$tmp/err" &&
    python3 -c "import json; assert json.load(open('$tmp/p.json'))['lights'] == 3" 2>/dev/null; then
  pass "punctual lights count as lights"
else
  fail "punctual lights count as lights"; cat "$tmp/err"
fi
if "$bin" render "$punctual" -o "$tmp/p.png" --spp 1 --width 16 --height 16 --device pocl \
    --strategy bsdf >"$tmp/out" 2>"$tmp/err" &&
    [ "$(grep -c "the scene's 3 punctual lights contribute nothing under --strategy bsdf; use nee or auto" "$tmp/err")" -eq 1 ]; then
  pass "--strategy bsdf warns about punctual lights"
else
  fail "--strategy bsdf warns about punctual lights"; cat "$tmp/err"
fi

# Environment maps: a missing or unreadable map is one error line
expect_error "missing environment map" "environment map not found" -- "$bin" render "$scene" -o "$tmp/x.png" --env "$tmp/nope.hdr" --device pocl
echo "not an image" >"$tmp/bad.hdr"
expect_error "unreadable environment map" "cannot read environment map" -- "$bin" render "$scene" -o "$tmp/x.png" --env "$tmp/bad.hdr" --device pocl
sed 's/"file": "sky.hdr"/"file": "missing.hdr"/' "$root/scenes/lights/environment.gltf" >"$tmp/missing-map.gltf"
expect_error "scene extras name a missing map" "environment map not found" -- "$bin" render "$tmp/missing-map.gltf" -o "$tmp/x.png" --device pocl
if "$bin" render "$root/scenes/lights/environment.gltf" -o "$tmp/env.png" --spp 1 --width 16 --height 10 --device pocl -q \
    --env-strength 0.5 --env-rotation 90 >"$tmp/out" 2>"$tmp/err" && [ -s "$tmp/env.png" ]; then
  pass "environment scene renders"
else
  fail "environment scene renders"; cat "$tmp/err"
fi

# Default lighting: the Cornell box without its light (and without its black background)
# gets the built-in studio, announced on stderr; --no-default-light keeps it black (with a
# warning)
python3 - "$scene" "$tmp/dark.gltf" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
for m in doc["materials"]:
    m.pop("emissiveFactor", None)
    m.get("extensions", {}).pop("KHR_materials_emissive_strength", None)
doc["scenes"][0].pop("extras", None)
json.dump(doc, open(sys.argv[2], "w"))
PY
mean_of() { oiiotool --stats "$1" | sed -n 's/.*Stats Avg: \([0-9.e+-]*\).*/\1/p' | head -1; }
if "$bin" render "$tmp/dark.gltf" -o "$tmp/sky.exr" --spp 2 --width 16 --height 16 --device pocl -q >/dev/null 2>"$tmp/err" &&
  grep -q "note: lighting the scene with the built-in studio environment: the scene has no light (--default-light off keeps the scene black)" "$tmp/err" &&
  { ! command -v oiiotool >/dev/null || python3 -c "import sys; assert float(sys.argv[1]) > 0.05" "$(mean_of "$tmp/sky.exr")"; }; then
  pass "a scene without light gets the built-in studio"
else
  fail "a scene without light gets the built-in studio"; cat "$tmp/err"
fi
if "$bin" render "$tmp/dark.gltf" -o "$tmp/black.exr" --spp 2 --width 16 --height 16 --device pocl -q --no-default-light \
    >/dev/null 2>"$tmp/err" && grep -q "the image will be black" "$tmp/err" && ! grep -q "built-in studio" "$tmp/err" &&
  { ! command -v oiiotool >/dev/null || python3 -c "import sys; assert float(sys.argv[1]) == 0" "$(mean_of "$tmp/black.exr")"; }; then
  pass "--no-default-light keeps it black"
else
  fail "--no-default-light keeps it black"; cat "$tmp/err"
fi

# Automatic exposure: the Cornell box without its background, its light 1000 times brighter,
# is exposed down for PNG (announced) and is no white frame (8-bit means); --exposure 0 keeps it
# as it is
python3 - "$scene" "$tmp/bright.gltf" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
for m in doc["materials"]:
    ext = m.get("extensions", {}).get("KHR_materials_emissive_strength")
    if ext: ext["emissiveStrength"] *= 1000.0
doc["scenes"][0].pop("extras", None)
json.dump(doc, open(sys.argv[2], "w"))
PY
if "$bin" render "$tmp/bright.gltf" -o "$tmp/auto.png" --spp 4 --width 24 --height 24 --device pocl -q >/dev/null 2>"$tmp/err" &&
  grep -q "note: exposing PNG/JPEG outputs at -[0-9.]* stops" "$tmp/err" &&
  "$bin" render "$tmp/bright.gltf" -o "$tmp/plain.png" --spp 4 --width 24 --height 24 --device pocl -q --exposure 0 \
    >/dev/null 2>"$tmp/err2" && ! grep -q "exposing" "$tmp/err2" &&
  { ! command -v oiiotool >/dev/null ||
    python3 -c "import sys; a, p = float(sys.argv[1]), float(sys.argv[2]); assert 20 < a < 210 and p > 230, (a, p)" \
      "$(mean_of "$tmp/auto.png")" "$(mean_of "$tmp/plain.png")"; }; then
  pass "a scene lit far brighter than the studio is exposed down"
else
  fail "a scene lit far brighter than the studio is exposed down"; cat "$tmp/err"; mean_of "$tmp/auto.png"; mean_of "$tmp/plain.png"
fi

# --device rusticl finds Mesa's CPU device without RUSTICL_ENABLE in the environment
if ls /etc/OpenCL/vendors/ 2>/dev/null | grep -q rusticl; then
  if env -u RUSTICL_ENABLE "$bin" render "$scene" -o "$tmp/r.png" --spp 1 --width 16 --height 16 \
      --device rusticl -q >"$tmp/out" 2>"$tmp/err" && grep -q rusticl "$tmp/out"; then
    pass "--device rusticl enables rusticl"
  else
    fail "--device rusticl enables rusticl"; cat "$tmp/err"
  fi
fi

# devices lists PoCL with a selector
if "$bin" devices | grep -q "Portable Computing Language"; then pass "devices lists PoCL"; else fail "devices lists PoCL"; fi

# A good render: EXR with metadata, PNG, stats JSON
if "$bin" render "$scene" -o "$tmp/cb.exr" -o "$tmp/cb.png" --spp 4 --width 64 --height 48 --device pocl --seed 3 \
    --stats "$tmp/stats.json" -q >"$tmp/out" 2>"$tmp/err"; then
  pass "render exits 0"
else
  fail "render exits 0"; cat "$tmp/err"
fi
[ -s "$tmp/cb.png" ] && pass "PNG written" || fail "PNG written"
if python3 - "$tmp/stats.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
need = ["spp", "seconds", "samples_per_second", "kernel_build_seconds", "bvh_build_seconds",
        "triangles", "device", "dropped_samples"]
missing = [k for k in need if k not in s]
assert not missing, missing
assert s["spp"] == 4 and s["triangles"] == 32 and s["samples_per_second"] > 0, s
assert s["width"] == 64 and s["height"] == 48, s
assert s["energy_compensation"] is True, s
cam = s["camera"]  # the compiled camera: unit forward, right and up at right angles, the fov
assert cam["type"] in ("perspective", "orthographic") and len(cam["position"]) == 3, cam
dot = lambda a, b: sum(x * y for x, y in zip(a, b))
for v in ("forward", "right", "up"):
    assert abs(dot(cam[v], cam[v]) - 1) < 1e-5, cam
assert abs(dot(cam["forward"], cam["up"])) < 1e-5 and abs(dot(cam["forward"], cam["right"])) < 1e-5, cam
if cam["type"] == "perspective":
    import math
    tx, ty = (math.tan(math.radians(cam[k] / 2)) for k in ("xfov_degrees", "yfov_degrees"))
    assert 0 < cam["yfov_degrees"] < 180 and abs(tx / ty - 64 / 48) < 1e-4, cam
PY
then pass "stats JSON fields"; else fail "stats JSON fields"; fi
if command -v oiiotool >/dev/null; then
  if oiiotool --info -v "$tmp/cb.exr" | grep -q 'candela:spp: "4"'; then pass "EXR metadata"; else fail "EXR metadata"; fi
fi

# --no-energy-compensation is recorded in the EXR metadata and the stats
if "$bin" render "$scene" -o "$tmp/nec.exr" --spp 1 --width 16 --height 16 --device pocl --no-energy-compensation \
    --stats "$tmp/nec.json" -q >/dev/null 2>"$tmp/err" &&
  python3 -c "import json,sys; assert json.load(open('$tmp/nec.json'))['energy_compensation'] is False" &&
  { ! command -v oiiotool >/dev/null || oiiotool --info -v "$tmp/nec.exr" | grep -q 'candela:energy_compensation: "off"'; }; then
  pass "--no-energy-compensation recorded"
else
  fail "--no-energy-compensation recorded"; cat "$tmp/err"
fi

# An orthographic camera: --width alone takes the height from xmag / ymag (0.4 / 0.3)
if "$bin" render "$tmp/ortho.gltf" -o "$tmp/ortho.png" --spp 1 --width 40 --device pocl --stats "$tmp/ortho.json" -q \
    >/dev/null 2>"$tmp/err" &&
  python3 -c "import json; s = json.load(open('$tmp/ortho.json')); assert (s['width'], s['height']) == (40, 30), s"; then
  pass "orthographic camera sets the aspect"
else
  fail "orthographic camera sets the aspect"; cat "$tmp/err"
fi
grep -q "camera" "$tmp/err" && { fail "orthographic camera warns"; cat "$tmp/err"; } || pass "orthographic camera without warning"

# Thin lens and filters render, and the filter is recorded
if "$bin" render "$scene" -o "$tmp/dof.exr" --spp 2 --width 16 --height 16 --device pocl --aperture 0.02 \
    --focus-distance 1.2 --filter gaussian --stats "$tmp/dof.json" -q >/dev/null 2>"$tmp/err" &&
  python3 -c "import json; assert json.load(open('$tmp/dof.json'))['filter'] == 'gaussian'" &&
  { ! command -v oiiotool >/dev/null || oiiotool --info -v "$tmp/dof.exr" | grep -q 'candela:filter: "gaussian"'; }; then
  pass "thin lens with a Gaussian filter renders"
else
  fail "thin lens with a Gaussian filter renders"; cat "$tmp/err"
fi

# ---- Speed against accuracy: --variance, --generic, compare ----
expect_error "variance must be EXR" "variance must name an .exr file" -- "$bin" render "$scene" -o "$tmp/x.exr" --variance "$tmp/v.png" --device pocl
if "$bin" render "$scene" -o "$tmp/m.exr" --variance "$tmp/v.exr" --spp 4 --width 16 --height 16 --device pocl --generic \
    --stats "$tmp/v.json" -q >"$tmp/out" 2>"$tmp/err" && grep -q "wrote $tmp/v.exr" "$tmp/out" &&
  python3 -c "import json; assert json.load(open('$tmp/v.json'))['generic_kernel'] is True" &&
  { ! command -v oiiotool >/dev/null || oiiotool --info -v "$tmp/v.exr" | grep -q 'candela:image: "variance_of_mean"'; }; then
  pass "--variance writes the variance image (generic kernel)"
else
  fail "--variance writes the variance image (generic kernel)"; cat "$tmp/err"
fi
# ---- AOVs and the transparent background (tests/render/aov_test.cpp checks their values) ----
expect_error "unknown AOV" "unknown AOV 'foo'" -- "$bin" render "$scene" -o "$tmp/x.exr" --aov albedo,foo --device pocl
expect_error "unknown AOV output" "unknown AOV 'foo'" -- "$bin" render "$scene" -o "$tmp/x.png:foo" --device pocl
expect_error "AOV output of an EXR" "FILE:NAME is for .png" -- "$bin" render "$scene" -o "$tmp/x.exr:normal" --device pocl
aov_render() {  # OUT OFFSET: a shard with AOVs, a normal image and a transparent PNG
  "$bin" render "$scene" -o "$1" -o "$tmp/n.png:normal" -o "$tmp/t.png" --aov albedo,depth,spp --transparent --spp 2 \
    --sample-offset "$2" --width 16 --height 16 --device pocl -q >/dev/null 2>"$tmp/err"
}
channels='channel list: R, G, B, A, albedo.R, albedo.G, albedo.B, depth.Z, normal.X, normal.Y, normal.Z, spp.Y'
if aov_render "$tmp/a0.exr" 0 && aov_render "$tmp/a1.exr" 2 &&
  "$bin" merge "$tmp/a0.exr" "$tmp/a1.exr" -o "$tmp/a01.exr" -q >/dev/null 2>>"$tmp/err" &&
  { ! command -v oiiotool >/dev/null || { oiiotool --info -v "$tmp/a0.exr" | grep -q "$channels" &&
    oiiotool --info -v "$tmp/a01.exr" | grep -q "$channels" && oiiotool --info "$tmp/t.png" | grep -q '4 channel' &&
    oiiotool --info "$tmp/n.png" | grep -q '3 channel'; }; }; then
  pass "--aov and --transparent: EXR channels, PNG RGBA, one AOV as PNG, merge keeps them"
else
  fail "--aov and --transparent: EXR channels, PNG RGBA, one AOV as PNG, merge keeps them"; cat "$tmp/err"
fi
# The generic kernel renders the Cornell box (no optional feature) to the same image
if command -v oiiotool >/dev/null; then
  if "$bin" render "$scene" -o "$tmp/spec.exr" --spp 4 --width 16 --height 16 --device pocl -q >/dev/null 2>&1 &&
    "$bin" render "$scene" -o "$tmp/gen.exr" --spp 4 --width 16 --height 16 --device pocl -q --generic >/dev/null 2>"$tmp/err" &&
    ! grep -q "non-finite" "$tmp/err" && oiiotool "$tmp/spec.exr" "$tmp/gen.exr" --diff >/dev/null 2>&1; then
    pass "--generic renders the same image"
  else
    fail "--generic renders the same image"; cat "$tmp/err"
  fi
fi
expect_error "compare needs two devices" "at least two devices" -- "$bin" compare "$scene" --devices pocl --spp 4 --width 8
expect_error "compare with an unknown device" "device 'quantum': no OpenCL device matches --device 'quantum'" -- "$bin" compare "$scene" --devices pocl,quantum --spp 4 --width 8 -q
expect_error "compare with a missing scene" "scene file not found" -- "$bin" compare "$tmp/nope.gltf" --devices pocl,pocl
# The same device, full transport against direct light only: NOT consistent, exit status 2
"$bin" compare "$scene" --devices pocl,pocl --spp 8 --width 16 --device-args "0:--max-depth 8" --device-args "1:--max-depth 1" \
  --json "$tmp/c2.json" -q >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -eq 2 ] && grep -q "^verdict: NOT consistent" "$tmp/out" &&
  python3 -c "import json; j = json.load(open('$tmp/c2.json')); assert not j['consistent'] and j['devices'][1]['against_first']['z_test']['mean_z2'] > 2, j"; then
  pass "compare: max depth 8 against 1 is NOT consistent"
else
  fail "compare: max depth 8 against 1 is NOT consistent (exit $rc)"; cat "$tmp/out" "$tmp/err"
fi
# kept:DIR: a render made elsewhere (scripts/gpu/check.sh) read instead of rendered: seed 1 with
# its variance, and seed 0 for the determinism check, as a device at position 1 renders them
k="$tmp/kept"; mkdir -p "$k"
"$bin" render "$scene" -o "$k/main.exr" --variance "$k/main-variance.exr" --stats "$k/main.json" --spp 8 --width 16 \
  --seed 1 --max-depth 8 --device pocl -q >/dev/null 2>&1
"$bin" render "$scene" -o "$k/same-seed.exr" --spp 8 --width 16 --seed 0 --max-depth 8 --device pocl -q >/dev/null 2>&1
"$bin" compare "$scene" --devices "pocl,kept:$k" --spp 8 --width 16 --max-depth 8 -q >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -eq 0 ] && grep -q "^verdict: statistically consistent" "$tmp/out" &&
  grep -q "determinism, seed 0 on kept:$k against pocl: max |a-b| 0, max relative 0, 100.0% bit-identical" "$tmp/out"; then
  pass "compare: a kept render of the same device is consistent and bit-identical at the same seed"
else
  fail "compare: a kept render of the same device is consistent (exit $rc)"; cat "$tmp/out" "$tmp/err"
fi
"$bin" compare "$scene" --devices "pocl,kept:$k" --spp 8 --width 16 --max-depth 1 -q >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -eq 2 ] && grep -q "^verdict: NOT consistent" "$tmp/out"; then
  pass "compare: a kept render of other settings is NOT consistent"
else
  fail "compare: a kept render of other settings is NOT consistent (exit $rc)"; cat "$tmp/out" "$tmp/err"
fi
expect_error "compare: kept render of another spp" "kept render $k has spp 8, this comparison 16" -- \
  "$bin" compare "$scene" --devices "pocl,kept:$k" --spp 16 --width 16 -q
expect_error "compare: kept render at the wrong position" "has seed 1, this comparison 0" -- \
  "$bin" compare "$scene" --devices "kept:$k,pocl" --spp 8 --width 16 -q
expect_error "compare: kept folder without a render" "has no main.json" -- \
  "$bin" compare "$scene" --devices "pocl,kept:$tmp" --spp 8 --width 16 -q
# PoCL against rusticl: consistent; the same-seed determinism check is reported
if ls /etc/OpenCL/vendors/ 2>/dev/null | grep -q rusticl; then
  "$bin" compare "$scene" --devices pocl,rusticl --spp 16 --width 24 --max-depth 8 --json "$tmp/c1.json" -q >"$tmp/out" 2>"$tmp/err"
  rc=$?
  if [ $rc -eq 0 ] && grep -q "^verdict: statistically consistent" "$tmp/out" && grep -q "determinism, seed 0 on rusticl" "$tmp/out" &&
    python3 - "$tmp/c1.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["consistent"] and j["spp"] == 16 and j["width"] == 24, j
a, b = j["devices"]
assert a["seed"] == 0 and b["seed"] == 1, j
for d in (a, b):
    assert d["kernel_build_cold_seconds"] > 0 and d["kernel_from_cache"] and d["samples_per_second"] > 0, d
    assert d["render_options"] == [], d
z = b["against_first"]["z_test"]
assert z["consistent"] and z["values"] > 0 and 0.5 < z["mean_z2"] < 1.5, z
assert "max_abs_diff" in b["same_seed"] and 0 <= b["same_seed"]["identical_fraction"] <= 1, b
PY
  then
    pass "compare: pocl and rusticl are consistent"
  else
    fail "compare: pocl and rusticl are consistent (exit $rc)"; cat "$tmp/out" "$tmp/err"
  fi
fi

# Both samplers render, and the sampler is recorded (sobol by default)
if "$bin" render "$scene" -o "$tmp/ind.exr" --spp 2 --width 16 --height 16 --device pocl --sampler independent \
    --stats "$tmp/ind.json" -q >/dev/null 2>"$tmp/err" &&
  "$bin" render "$scene" -o "$tmp/sob.exr" --spp 2 --width 16 --height 16 --device pocl --stats "$tmp/sob.json" -q \
    >/dev/null 2>>"$tmp/err" &&
  python3 -c "import json; assert json.load(open('$tmp/ind.json'))['sampler'] == 'independent'" &&
  python3 -c "import json; assert json.load(open('$tmp/sob.json'))['sampler'] == 'sobol'" &&
  { ! command -v oiiotool >/dev/null || oiiotool --info -v "$tmp/ind.exr" | grep -q 'candela:sampler: "independent"'; }; then
  pass "--sampler independent and sobol render and are recorded"
else
  fail "--sampler independent and sobol render and are recorded"; cat "$tmp/err"
fi

# ---- Several devices and machines: --device LIST|all, --sample-offset, merge ----
# Pixel comparison of two EXRs on Debian's python3 (python3-openimageio, python3-numpy)
sys_py=/usr/bin/python3
have_oiio_py=0
$sys_py -c "import OpenImageIO, numpy" 2>/dev/null && have_oiio_py=1
# images_close A B ABS REL: every channel of every pixel within ABS + REL * |A|
images_close() {
  $sys_py - "$@" <<'PY'
import sys, numpy as np, OpenImageIO as oiio
a = oiio.ImageBuf(sys.argv[1]).get_pixels(oiio.FLOAT)
b = oiio.ImageBuf(sys.argv[2]).get_pixels(oiio.FLOAT)
tol_abs, tol_rel = float(sys.argv[3]), float(sys.argv[4])
assert a.shape == b.shape, (a.shape, b.shape)
assert a.mean() > 0.01, a.mean()
d = np.abs(a - b)
bad = d > tol_abs + tol_rel * np.abs(a)
assert not bad.any(), "max abs diff %g, %d values off" % (d.max(), bad.sum())
PY
}
mdev="--spp 8 --width 32 --height 32 --seed 7"
expect_error "unknown device in a list" "no OpenCL device matches --device 'quantum'" -- "$bin" render "$scene" -o "$tmp/x.exr" --device pocl,quantum $mdev
expect_error "empty device in a list" "empty entry" -- "$bin" render "$scene" -o "$tmp/x.exr" --device pocl,,pocl $mdev
expect_error "all inside a list" "all stands alone" -- "$bin" render "$scene" -o "$tmp/x.exr" --device pocl,all $mdev
"$bin" render "$scene" -o "$tmp/d1.exr" --device pocl $mdev -q >/dev/null 2>"$tmp/err"
# Two workers on the one PoCL device: the same samples, merged: float rounding only
# (measured: max relative difference 3e-7)
if "$bin" render "$scene" -o "$tmp/d2.exr" --device pocl,pocl $mdev --stats "$tmp/d2.json" >"$tmp/out" 2>"$tmp/err" &&
  grep -q "^device 1: .*Portable Computing Language" "$tmp/err" && grep -q "device 1 is device 0 again" "$tmp/err" &&
  grep -q "^  device 1: .*% of the samples" "$tmp/out" &&
  python3 - "$tmp/d2.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
d = s["devices"]
assert len(d) == 2 and all("Portable Computing Language" in x["description"] for x in d), d
assert abs(sum(x["share"] for x in d) - 1) < 1e-12, d
assert sum(x["samples"] for x in d) == 8 * 32 * 32, d
assert all(x["samples_per_second"] >= 0 for x in d), d
PY
then
  if [ $have_oiio_py -eq 1 ] && ! images_close "$tmp/d1.exr" "$tmp/d2.exr" 0 1e-5; then
    fail "--device pocl,pocl gives the single-device image"
  else
    pass "--device pocl,pocl: both devices in the stats, the single-device image"
  fi
else
  fail "--device pocl,pocl"; cat "$tmp/out" "$tmp/err"
fi
# PoCL and rusticl: the same sample indices, rusticl's floating point differs a little
# (measured on a whole rusticl render against PoCL's: max abs difference 2.6e-6)
if RUSTICL_ENABLE=llvmpipe "$bin" devices | grep -q rusticl; then
  if "$bin" render "$scene" -o "$tmp/dr.exr" --device pocl,rusticl $mdev --stats "$tmp/dr.json" >"$tmp/out" 2>"$tmp/err" &&
    python3 -c "
import json; d = json.load(open('$tmp/dr.json'))['devices']
assert len(d) == 2 and 'rusticl' in d[1]['description'] and abs(d[0]['share'] + d[1]['share'] - 1) < 1e-12, d" &&
    { [ $have_oiio_py -eq 0 ] || images_close "$tmp/d1.exr" "$tmp/dr.exr" 2e-5 1e-4; }; then
    pass "--device pocl,rusticl"
  else
    fail "--device pocl,rusticl"; cat "$tmp/out" "$tmp/err"
  fi
fi
# all: every device `candela devices` lists (same environment), once each
ndev=$("$bin" devices | grep -c '^[0-9]')
if "$bin" render "$scene" -o "$tmp/all.exr" --device all --spp 2 --width 8 --height 8 -q --stats "$tmp/all.json" >/dev/null 2>"$tmp/err" &&
  python3 -c "import json; d = json.load(open('$tmp/all.json'))['devices']; assert len(d) == $ndev, d"; then
  pass "--device all renders on the $ndev listed device(s)"
else
  fail "--device all"; cat "$tmp/err"
fi
if "$bin" render "$scene" -o "$tmp/t2.exr" --device pocl,pocl --time 0.5 --width 16 --height 16 --stats "$tmp/t2.json" >/dev/null 2>"$tmp/err" &&
  python3 -c "
import json; s = json.load(open('$tmp/t2.json'))
assert s['spp'] >= 1 and len(s['devices']) == 2 and sum(x['samples'] for x in s['devices']) >= s['spp'] * 256, s"; then
  pass "--time with two devices"
else
  fail "--time with two devices"; cat "$tmp/err"
fi

# Shards: sample indices [0,8) and [8,16) merged give the 16-spp render (float rounding:
# measured max relative difference 3e-7)
shard="--width 32 --height 32 --seed 7 --device pocl -q"
"$bin" render "$scene" -o "$tmp/s0.exr" --sample-offset 0 --spp 8 $shard >/dev/null 2>&1
"$bin" render "$scene" -o "$tmp/s1.exr" --sample-offset 8 --spp 8 $shard >/dev/null 2>&1
"$bin" render "$scene" -o "$tmp/s01.exr" --spp 16 $shard >/dev/null 2>&1
if "$bin" merge "$tmp/s0.exr" "$tmp/s1.exr" -o "$tmp/merged.exr" >"$tmp/out" 2>"$tmp/err" &&
  { ! command -v oiiotool >/dev/null ||
    { oiiotool --info -v "$tmp/s1.exr" | grep -q 'candela:sample_offset: "8"' &&
      oiiotool --info -v "$tmp/merged.exr" | grep -q 'candela:spp: "16"' &&
      oiiotool --info -v "$tmp/merged.exr" | grep -q 'candela:sample_ranges: "0:16"'; }; } &&
  { [ $have_oiio_py -eq 0 ] || images_close "$tmp/s01.exr" "$tmp/merged.exr" 0 1e-5; } &&
  { [ $have_oiio_py -eq 0 ] || ! images_close "$tmp/s01.exr" "$tmp/s0.exr" 0 1e-5 2>/dev/null; }; then
  pass "merge of shards [0,8) and [8,16) equals the 16-spp render"
else
  fail "merge of shards"; cat "$tmp/out" "$tmp/err"
fi
# A merged file merges on with a disjoint shard, not with one it holds
"$bin" render "$scene" -o "$tmp/s2.exr" --sample-offset 16 --spp 4 $shard >/dev/null 2>&1
if "$bin" merge "$tmp/merged.exr" "$tmp/s2.exr" -o "$tmp/merged2.exr" >/dev/null 2>"$tmp/err" &&
  { ! command -v oiiotool >/dev/null || oiiotool --info -v "$tmp/merged2.exr" | grep -q 'candela:spp: "20"'; }; then
  pass "merge of a merged image and a further shard"
else
  fail "merge of a merged image and a further shard"; cat "$tmp/err"
fi
expect_error "merge: overlap with a merged image" "overlapping sample ranges" -- "$bin" merge "$tmp/merged.exr" "$tmp/s1.exr" -o "$tmp/x.exr"
"$bin" render "$scene" -o "$tmp/s_overlap.exr" --sample-offset 4 --spp 8 $shard >/dev/null 2>&1
expect_error "merge: overlapping ranges" "overlapping sample ranges" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_overlap.exr" -o "$tmp/x.exr"
expect_error "merge: same file twice" "overlapping sample ranges" -- "$bin" merge "$tmp/s0.exr" "$tmp/s0.exr" -o "$tmp/x.exr"
"$bin" render "$scene" -o "$tmp/s_size.exr" --sample-offset 8 --spp 8 --width 16 --height 32 --seed 7 --device pocl -q >/dev/null 2>&1
expect_error "merge: different sizes" "is 16x32" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_size.exr" -o "$tmp/x.exr"
"$bin" render "$scene" -o "$tmp/s_seed.exr" --sample-offset 8 --spp 8 --width 32 --height 32 --seed 8 --device pocl -q >/dev/null 2>&1
expect_error "merge: different seeds" "different seed" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_seed.exr" -o "$tmp/x.exr"
"$bin" render "$scene" -o "$tmp/s_strat.exr" --sample-offset 8 --spp 8 --strategy bsdf $shard >/dev/null 2>&1
expect_error "merge: different strategies" "different strategy" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_strat.exr" -o "$tmp/x.exr"
"$bin" render "$scene" -o "$tmp/s_depth.exr" --sample-offset 8 --spp 8 --max-depth 3 $shard >/dev/null 2>&1
expect_error "merge: different max depth" "different max_depth" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_depth.exr" -o "$tmp/x.exr"
"$bin" render "$root/scenes/materials/materials.gltf" -o "$tmp/s_scene.exr" --sample-offset 8 --spp 1 $shard >/dev/null 2>&1
expect_error "merge: different scenes" "different scene" -- "$bin" merge "$tmp/s0.exr" "$tmp/s_scene.exr" -o "$tmp/x.exr"
if command -v oiiotool >/dev/null; then
  oiiotool --create 32x32 3 -o "$tmp/plain.exr"
  expect_error "merge: no candela metadata" "no candela metadata" -- "$bin" merge "$tmp/s0.exr" "$tmp/plain.exr" -o "$tmp/x.exr"
fi
expect_error "merge: one input" "at least two" -- "$bin" merge "$tmp/s0.exr" -o "$tmp/x.exr"
expect_error "merge: PNG input" "reads .exr images" -- "$bin" merge "$tmp/s0.exr" "$tmp/x.png" -o "$tmp/x.exr"
expect_error "merge: missing input" "not found" -- "$bin" merge "$tmp/s0.exr" "$tmp/nope.exr" -o "$tmp/x.exr"
[ ! -e "$tmp/x.exr" ] && pass "refused merges write nothing" || fail "a refused merge wrote $tmp/x.exr"

# --mpi: without MPI built in, one clear error; with it, a single rank renders
if "$bin" render "$scene" -o "$tmp/mpi1.exr" --mpi $shard --spp 16 >/dev/null 2>"$tmp/err"; then
  pass "--mpi as a single rank (an MPI build)"
else
  expect_error "--mpi without MPI" "built without MPI" -- "$bin" render "$scene" -o "$tmp/x.exr" --mpi $shard --spp 16
fi
# (tests/app/mpi_test.sh runs two ranks under mpirun: scripts/check/mpi-test.sh)

# Ctrl-C during a long render writes what was rendered and exits 130
"$bin" render "$scene" -o "$tmp/int.exr" --time 120 --width 64 --height 64 --device pocl \
  --stats "$tmp/int.json" >"$tmp/int.out" 2>"$tmp/int.err" &
pid=$!
# Wait until the kernel is built (the scene summary is printed), then let samples run
for i in $(seq 1 300); do
  grep -q "^scene:" "$tmp/int.err" 2>/dev/null && break
  [ -d "/proc/$pid" ] || break
  sleep 0.2
done
sleep 1
kill -INT $pid
wait $pid
rc=$?
if [ $rc -eq 130 ] && [ -s "$tmp/int.exr" ] && python3 -c "import json,sys; s=json.load(open('$tmp/int.json')); assert s['interrupted'] and s['spp'] > 0" 2>/dev/null; then
  pass "Ctrl-C keeps the samples done"
else
  fail "Ctrl-C keeps the samples done (exit $rc)"; cat "$tmp/int.err"
fi

# ---- A kernel build from source is announced (a wait of minutes on rusticl); a cached one is not ----
kc=$tmp/kcache-note
CANDELA_CACHE_DIR=$kc "$bin" render "$scene" -o "$tmp/n1.png" --width 16 --spp 1 --device pocl --stats "$tmp/n1.json" \
  >/dev/null 2>"$tmp/n1"
CANDELA_CACHE_DIR=$kc "$bin" render "$scene" -o "$tmp/n2.png" --width 16 --spp 1 --device pocl --stats "$tmp/n2.json" \
  >/dev/null 2>"$tmp/n2"
CANDELA_CACHE_DIR=$tmp/kcache-quiet "$bin" render "$scene" -o "$tmp/n3.png" --width 16 --spp 1 --device pocl -q \
  >/dev/null 2>"$tmp/n3"
if [ "$(grep -c '^compiling the render kernel for .*not in the kernel cache' "$tmp/n1")" -eq 1 ] &&
  ! grep -q '^compiling the render kernel' "$tmp/n2" && ! grep -q '^compiling the render kernel' "$tmp/n3"; then
  pass "an uncached kernel build is announced once, a cached or quiet one not"
else
  fail "the kernel build note"
  cat "$tmp/n1" "$tmp/n2" "$tmp/n3"
fi
# So are the albedo tables computed by the renderer (at most once: a load stalled past
# 0.25 s leaves them to the prebuild, which computes them quietly)
if [ "$(grep -c '^computing the albedo tables for .*once per device' "$tmp/n1")" -le 1 ] &&
  ! grep -q '^computing the albedo tables' "$tmp/n2" && ! grep -q '^computing the albedo tables' "$tmp/n3" &&
  [ -n "$(find "$kc" -name '*.ggx_albedo')" ]; then
  pass "the albedo tables are announced at most once, then cached"
else
  fail "the albedo tables note"
  cat "$tmp/n1" "$tmp/n2" "$tmp/n3"
fi
# The build made while the scene compiles is reported as the render's: from source the
# first time (PoCL's own cache may make it quick), from the cache the second
if python3 -c "
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert a['kernel_from_cache'] is False and a['kernel_build_seconds'] > 0.0, a
assert b['kernel_from_cache'] is True and b['kernel_build_seconds'] > 0.0, b
" "$tmp/n1.json" "$tmp/n2.json"; then
  pass "a kernel built while the scene compiles is reported as built from source, then as cached"
else
  fail "the kernel build's report (kernel_from_cache, kernel_build_seconds)"
fi

echo "$passes passed, $fails failed"
[ $fails -eq 0 ]
