#!/usr/bin/env bash
# Reliability of the command line: bad values refused up front in one line, signals at
# every phase keep what was rendered, outputs checked before the render and written
# atomically (a full disk leaves the previous file), shards that overlap or differ refused
# by merge, and a scene's files read only from its own folder.
# Usage: reliability_test.sh path/to/candela repo_root
set -u
bin=$1
root=$2
scene=$root/scenes/cornell-box/cornell-box.gltf
tmp=$(mktemp -d)
mounted=""
cleanup() {
  [ -n "$mounted" ] && umount "$mounted" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
passes=0
fails=0
pass() { passes=$((passes + 1)); echo "ok: $1"; }
fail() { fails=$((fails + 1)); echo "FAIL: $1"; }
py=/usr/bin/python3
render=("$bin" render "$scene" --device pocl -q)

# meta FILE KEY: the candela:KEY attribute of an EXR ("" when absent)
meta() {
  "$py" - "$1" "$2" <<'PY'
import sys, OpenImageIO as oiio
inp = oiio.ImageInput.open(sys.argv[1])
print(inp.spec().getattribute("candela:" + sys.argv[2]) or "")
PY
}

# one_error NAME -- command: exit 1, stderr exactly one line `candela: error: ...` with no
# number of more than 20 digits, and nothing written to $tmp/never.*
one_error() {
  local name=$1
  shift 2
  rm -f "$tmp"/never.*
  "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ $rc -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q '^candela: error: ' "$tmp/err" &&
    ! grep -Eq '[0-9]{21}' "$tmp/err" && [ -z "$(ls "$tmp"/never.* 2>/dev/null)" ]; then
    pass "$name: $(cat "$tmp/err")"
  else
    fail "$name (exit $rc)"
    cat "$tmp/err"
  fi
}

# ---- Values: refused before anything runs ----
for args in "--time nan" "--time -1" "--time inf" "--spp 0" "--spp abc" "--spp 1e3" "--width 0" "--width 99999999999" \
  "--height -4" "--seed -1" "--max-depth -3" "--exposure nan" "--exposure -inf" "--env-strength nan" \
  "--env-rotation inf" "--fov 180" "--fov nan" "--aperture -1" "--aperture nan" "--aperture 1e30" \
  "--focus-distance 0" "--up 0,0,0" "--up 0,0,-1" "--up 1,2" "--look-from nan,0,0" "--camera -1" "--camera 5" \
  "--sample-offset -1" "--sample-offset 4294967295 --spp 2" "--strategy fast" "--tonemap aces" "--bogus" \
  "--sampler halton" "--default-light maybe"; do
  # shellcheck disable=SC2086
  one_error "render $args" -- "${render[@]}" -o "$tmp/never.png" --width 16 $args
done
one_error "merge with one input" -- "$bin" merge "$tmp/a.exr" -o "$tmp/never.exr"
one_error "compare --spp 1" -- "$bin" compare "$scene" --devices pocl,pocl --spp 1

# ---- Outputs: checked before the render ----
one_error "missing output folder" -- "${render[@]}" -o "$tmp/nowhere/out.png" --width 16
one_error "-o twice the same file" -- "${render[@]}" -o "$tmp/never.png" -o "$tmp/./never.png" --width 16
one_error "--stats onto the image" -- "${render[@]}" -o "$tmp/never.exr" --stats "$tmp/never.exr" --width 16
one_error "--variance onto the image" -- "${render[@]}" -o "$tmp/never.exr" --variance "$tmp/never.exr" --width 16
one_error "--stats onto the scene" -- "${render[@]}" -o "$tmp/never.png" --stats "$scene" --width 16
"$py" -c "import OpenImageIO as oiio; oiio.ImageBuf(oiio.ImageSpec(8, 4, 3, 'float')).write('$tmp/env.exr')"
env=$tmp/env.exr
one_error "-o onto the --env map" -- "${render[@]}" -o "$env" --env "$env" --width 16
one_error "--stats in a missing folder" -- "${render[@]}" -o "$tmp/never.png" --stats "$tmp/nowhere/s.json" --width 16

# ---- Signals: each phase, SIGINT and SIGTERM ----
# phase  expected-exit-offset  files: none | partial (spp 0, partial_pass 1) | some (spp >= 1) | all (spp 8)
check_signal() {
  local phase=$1 sig=$2 want=$3 width=$4
  local code=130
  [ "$sig" = TERM ] && code=143
  rm -f "$tmp"/sig.*
  # launches of a millisecond: every pass takes several, so each phase is reached
  CANDELA_LAUNCH_SECONDS=0.001 CANDELA_RAISE_AT=$phase:$sig "${render[@]}" -o "$tmp/sig.exr" -o "$tmp/sig.png" --stats "$tmp/sig.json" \
    --width "$width" --spp 8 >"$tmp/out" 2>"$tmp/err"
  local rc=$? got=none
  if [ -s "$tmp/sig.exr" ] && [ -s "$tmp/sig.png" ] && [ -s "$tmp/sig.json" ]; then
    local spp partial
    spp=$(meta "$tmp/sig.exr" spp)
    partial=$(meta "$tmp/sig.exr" partial_pass)
    if [ "$spp" = 0 ] && [ "$partial" = 1 ]; then
      got=partial
    elif [ "$spp" = 8 ]; then
      got=all
    elif [ "$spp" -ge 1 ] 2>/dev/null; then
      got=some
    else
      got="spp=$spp"
    fi
  elif [ -e "$tmp/sig.exr" ] || [ -e "$tmp/sig.png" ]; then
    got=incomplete
  fi
  if [ $rc -eq $code ] && [ "$got" = "$want" ]; then
    pass "SIG$sig at $phase: exit $rc, files $got"
  else
    fail "SIG$sig at $phase: exit $rc (want $code), files $got (want $want)"
    cat "$tmp/err"
  fi
}
for sig in INT TERM; do
  check_signal loading $sig none 64
  check_signal kernel-build $sig none 64
  check_signal first-pass $sig partial 160
  check_signal later-pass $sig some 64
  check_signal writing $sig all 64
done

# A real SIGTERM from outside during a timed render keeps the samples (exit 143)
"${render[@]}" -o "$tmp/term.exr" --time 120 --width 64 >"$tmp/out" 2>"$tmp/err" &
pid=$!
for _ in $(seq 1 300); do
  [ -d "/proc/$pid" ] || break
  # the kernel is built once the process has run a while; give it samples to keep
  sleep 0.2
  [ "$(awk '{print $14+$15}' "/proc/$pid/stat" 2>/dev/null || echo 0)" -gt 150 ] && break
done
sleep 1
kill -TERM $pid
wait $pid
rc=$?
spp=$(meta "$tmp/term.exr" spp 2>/dev/null)
if [ $rc -eq 143 ] && [ "${spp:-0}" -ge 1 ] 2>/dev/null; then
  pass "SIGTERM from outside keeps $spp spp (exit 143)"
else
  fail "SIGTERM from outside (exit $rc, spp '${spp:-}')"
  cat "$tmp/err"
fi

# ---- Shards: merge refuses overlaps, interrupted ones included, and differing settings ----
# Stopped inside its second range (launches of a millisecond: a range takes several), the
# shard holds sample indices past its whole passes: a shard that starts there overlaps it
CANDELA_LAUNCH_SECONDS=0.001 CANDELA_RAISE_AT=mid-pass:INT "${render[@]}" -o "$tmp/cut.exr" --width 320 --spp 8 \
  >/dev/null 2>&1
cut_spp=$(meta "$tmp/cut.exr" spp)
cut_ranges=$(meta "$tmp/cut.exr" sample_ranges)
cut_end=${cut_ranges#*:}
if [ "$(meta "$tmp/cut.exr" partial_pass)" = 1 ] && [ "$cut_end" -gt "$cut_spp" ] 2>/dev/null; then
  pass "a shard cut inside a range records indices [0, $cut_end) over $cut_spp whole passes"
  "${render[@]}" -o "$tmp/next.exr" --width 320 --spp 2 --sample-offset "$cut_spp" >/dev/null 2>&1
  one_error "merge of a cut shard with one starting at its whole passes" -- \
    "$bin" merge "$tmp/cut.exr" "$tmp/next.exr" -o "$tmp/never.exr"
  "${render[@]}" -o "$tmp/after.exr" --width 320 --spp 2 --sample-offset "$cut_end" >/dev/null 2>&1
  if "$bin" merge "$tmp/cut.exr" "$tmp/after.exr" -o "$tmp/merged.exr" >/dev/null 2>"$tmp/err" &&
    [ "$(meta "$tmp/merged.exr" partial_pass)" = 1 ] && [ "$(meta "$tmp/merged.exr" spp)" = $((cut_spp + 2)) ]; then
    pass "a cut shard merges with the one after its last index, and the result says so"
  else
    fail "a cut shard merges with the one after its last index"
    cat "$tmp/err"
  fi
else
  fail "a shard cut inside a range records its indices (spp '$cut_spp', ranges '$cut_ranges')"
fi
"${render[@]}" -o "$tmp/s0.exr" --width 16 --spp 2 >/dev/null 2>&1
"${render[@]}" -o "$tmp/s1.exr" --width 16 --spp 2 --sample-offset 2 --sampler independent >/dev/null 2>&1
one_error "merge of different samplers" -- "$bin" merge "$tmp/s0.exr" "$tmp/s1.exr" -o "$tmp/never.exr"
"${render[@]}" -o "$tmp/s2.exr" --width 16 --spp 2 --sample-offset 2 --light-selection power >/dev/null 2>&1
one_error "merge of different light selections" -- "$bin" merge "$tmp/s0.exr" "$tmp/s2.exr" -o "$tmp/never.exr"
"${render[@]}" -o "$tmp/s2.exr" --width 16 --spp 2 --sample-offset 2 --look-from 0,1,4 >/dev/null 2>&1
one_error "merge of different cameras" -- "$bin" merge "$tmp/s0.exr" "$tmp/s2.exr" -o "$tmp/never.exr"
"${render[@]}" -o "$tmp/s3.exr" --width 16 --spp 2 --sample-offset 2 --background 1,1,1 >/dev/null 2>&1
one_error "merge of different lighting" -- "$bin" merge "$tmp/s0.exr" "$tmp/s3.exr" -o "$tmp/never.exr"
one_error "merge onto one of its inputs" -- "$bin" merge "$tmp/s0.exr" "$tmp/s1.exr" -o "$tmp/s0.exr"
# A timed render near the end of the 32-bit index space stops there instead of wrapping
"${render[@]}" -o "$tmp/wrap.exr" --width 8 --time 2 --sample-offset 4294967290 >/dev/null 2>&1
if [ "$(meta "$tmp/wrap.exr" spp)" -le 6 ] 2>/dev/null; then
  pass "--time from sample 2^32-6 renders at most 6 samples ($(meta "$tmp/wrap.exr" spp))"
else
  fail "--time near 2^32 wraps ($(meta "$tmp/wrap.exr" spp 2>/dev/null))"
fi

# ---- A full disk: the previous file stays, the other outputs are still written ----
disk=$tmp/disk
mkdir -p "$disk"
if mount -t tmpfs -o size=96k tmpfs "$disk" 2>/dev/null; then
  mounted=$disk
  echo previous >"$disk/out.exr"
  head -c 60000 /dev/zero >"$disk/filler"
  "${render[@]}" -o "$disk/out.exr" -o "$tmp/elsewhere.png" --width 128 --spp 1 >"$tmp/out" 2>"$tmp/err"
  rc=$?
  if [ $rc -ne 0 ] && grep -q "^candela: error: .*out.exr" "$tmp/err" && [ "$(cat "$disk/out.exr")" = previous ] &&
    [ -s "$tmp/elsewhere.png" ] && [ -z "$(ls "$disk" | grep -v -e '^out.exr$' -e '^filler$')" ]; then
    pass "full disk: exit $rc, previous file intact, no temporary left, the other output written"
  else
    fail "full disk (exit $rc)"
    cat "$tmp/err"
    ls -la "$disk"
  fi
else
  echo "skip: full-disk test (cannot mount a tmpfs here: not root?)"
fi

# ---- A scene's files: from its own folder only, regular files only ----
# scene_with DIR NAME BUFFER_URI [IMAGE_URI]: a one-triangle glTF whose positions are in
# BUFFER_URI (36 bytes) and, with IMAGE_URI, a base colour texture
scene_with() {
  "$py" - "$@" <<'PY'
import json, sys
d, name, buf = sys.argv[1:4]
img = sys.argv[4] if len(sys.argv) > 4 else None
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
     "materials": [{"pbrMetallicRoughness": {}}],
     "buffers": [{"uri": buf, "byteLength": 36}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                    "min": [0, 0, 0], "max": [1, 1, 0]}]}
if img:
    g["images"] = [{"uri": img}]
    g["textures"] = [{"source": 0}]
    g["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
json.dump(g, open(f"{d}/{name}", "w"))
PY
}
box=$tmp/box
mkdir -p "$box/scene" "$box/outside"
"$py" -c "import struct; open('$box/outside/tri.bin','wb').write(struct.pack('9f',0,0,0,1,0,0,0,1,0))"
cp "$box/outside/tri.bin" "$box/scene/tri.bin"
"$py" -c "import OpenImageIO as oiio; oiio.ImageBuf(oiio.ImageSpec(4, 4, 3, 'uint8')).write('$box/outside/private.png')"
ln -s ../outside/tri.bin "$box/scene/link.bin"
mkdir -p "$box/scene/folder.bin"
mkfifo "$box/scene/fifo.bin"
# escape REFERENCE PATTERN: a scene whose buffer is REFERENCE fails with one line matching PATTERN
escape() {
  scene_with "$box/scene" escape.gltf "$1"
  "$bin" info "$box/scene/escape.gltf" >"$tmp/out" 2>"$tmp/err" &
  local pid=$! waited=0
  while [ -d "/proc/$pid" ] && [ $waited -lt 100 ]; do sleep 0.1; waited=$((waited + 1)); done
  if [ -d "/proc/$pid" ]; then
    kill -9 $pid
    fail "buffer '$1': hangs"
    return
  fi
  wait $pid
  local rc=$?
  if [ $rc -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q "^candela: error: .*$2" "$tmp/err"; then
    pass "buffer '$1': $(cut -c1-150 "$tmp/err")"
  else
    fail "buffer '$1' (exit $rc)"
    cat "$tmp/err"
  fi
}
escape "../outside/tri.bin" "leaves the scene's folder"
escape "%2e%2e/outside/tri.bin" "leaves the scene's folder"
escape "..%2Foutside%2Ftri.bin" "leaves the scene's folder"
escape "$box/outside/tri.bin" "absolute path"
escape "file://$box/outside/tri.bin" "URI with a scheme"
escape "link.bin" "outside the scene's folder"
escape "folder.bin" "is a folder, not a regular file"
escape "fifo.bin" "is a FIFO, not a regular file"
escape "missing.bin" "not found"
# The user can allow more
scene_with "$box/scene" outside.gltf "../outside/tri.bin"
if "$bin" info "$box/scene/outside.gltf" --allow-outside-paths >/dev/null 2>"$tmp/err"; then
  pass "--allow-outside-paths reads ../outside/tri.bin"
else
  fail "--allow-outside-paths reads ../outside/tri.bin"
  cat "$tmp/err"
fi
# An image outside the folder is dropped with a warning naming the reason; the scene renders
scene_with "$box/scene" image.gltf "tri.bin" "../outside/private.png"
if "$bin" render "$box/scene/image.gltf" --device pocl -q -o "$tmp/img.png" --width 16 --spp 1 >/dev/null 2>"$tmp/err" &&
  grep -q "leaves the scene's folder" "$tmp/err"; then
  pass "an image outside the folder is dropped with a warning"
else
  fail "an image outside the folder is dropped with a warning"
  cat "$tmp/err"
fi
# A data: URI that is not base64 drops its image with a warning
scene_with "$box/scene" baddata.gltf "tri.bin" "data:image/png;base64,@@@not base64@@@"
if "$bin" render "$box/scene/baddata.gltf" --device pocl -q -o "$tmp/bad.png" --width 16 --spp 1 >/dev/null 2>"$tmp/err"; then
  pass "a bad data: URI image is dropped with a warning: $(grep -m1 warning "$tmp/err" | cut -c1-120)"
else
  fail "a bad data: URI image is dropped with a warning"
  cat "$tmp/err"
fi
# A primitive naming a material the file does not have: a warning, the default material
"$py" - "$box/scene/tri.bin" "$box/scene/nomaterial.gltf" <<'PY'
import json, sys
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 99}]}],
     "buffers": [{"uri": "tri.bin", "byteLength": 36}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                    "min": [0, 0, 0], "max": [1, 1, 0]}]}
json.dump(g, open(sys.argv[2], "w"))
PY
if "$bin" render "$box/scene/nomaterial.gltf" --device pocl -q -o "$tmp/nm.png" --width 16 --spp 1 >/dev/null \
  2>"$tmp/err" && grep -q "^warning: .*material 99" "$tmp/err"; then
  pass "a missing material index is a warning: $(grep -m1 'material 99' "$tmp/err")"
else
  fail "a missing material index is a warning"
  cat "$tmp/err"
fi
# Non-regular files named on the command line: one line, no hang
one_error "a FIFO as the scene" -- timeout 20 "$bin" info "$box/scene/fifo.bin"
one_error "/dev/zero as --env" -- timeout 20 "${render[@]}" -o "$tmp/never.png" --env /dev/zero --width 16
one_error "a folder as --env" -- timeout 20 "${render[@]}" -o "$tmp/never.png" --env "$box" --width 16

# ---- The kernel cache: a folder or a FIFO where an entry belongs is reported, not fatal ----
cache=$tmp/kcache
CANDELA_CACHE_DIR=$cache "${render[@]}" -o "$tmp/c0.png" --width 16 --spp 1 >/dev/null 2>&1
entries=$(ls "$cache" 2>/dev/null)
if [ -n "$entries" ]; then
  first=1
  for e in $entries; do
    rm -f "$cache/$e"
    if [ $first = 1 ]; then mkdir "$cache/$e"; else mkfifo "$cache/$e"; fi
    first=0
  done
  if CANDELA_CACHE_DIR=$cache timeout 60 "${render[@]}" -o "$tmp/c1.png" --width 16 --spp 1 >/dev/null 2>"$tmp/err" &&
    [ -s "$tmp/c1.png" ] && grep -q '^warning: the kernel cache entry .* is not a regular file' "$tmp/err"; then
    pass "a folder and a FIFO in the kernel cache: $(head -1 "$tmp/err")"
  else
    fail "a folder and a FIFO in the kernel cache"
    cat "$tmp/err"
  fi
else
  fail "the kernel cache was not written to $cache"
fi

echo "$passes passed, $fails failed"
[ $fails -eq 0 ]
