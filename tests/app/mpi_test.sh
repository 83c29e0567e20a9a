#!/usr/bin/env bash
# MPI: two ranks under mpirun render the image of a single-process 16-spp render (the same
# sample indices, split into blocks and merged by rank 0), split a sequence's frames (each
# frame as one process renders it), and --mpi with --time is refused on every rank. Needs a -DCANDELA_MPI=ON build and mpirun (scripts/check/mpi-test.sh does both).
# Usage: mpi_test.sh path/to/candela repo_root
set -u
bin=$1
root=$2
scene=$root/scenes/cornell-box/cornell-box.gltf
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passes=0
fails=0
pass() { passes=$((passes + 1)); echo "ok: $1"; }
fail() { fails=$((fails + 1)); echo "FAIL: $1"; }
command -v mpirun >/dev/null || { echo "mpirun not found (Debian: openmpi-bin)"; exit 1; }
mpirun_args=(-np 2)
[ "$(id -u)" = 0 ] && mpirun_args+=(--allow-run-as-root)
mpirun --version 2>/dev/null | grep -q "Open MPI" && mpirun_args+=(--oversubscribe)
shard=(--width 32 --height 32 --seed 7 --device pocl -q)

"$bin" render "$scene" -o "$tmp/one.exr" --spp 16 "${shard[@]}" >/dev/null 2>"$tmp/err" || { cat "$tmp/err"; exit 1; }
if mpirun "${mpirun_args[@]}" "$bin" render "$scene" -o "$tmp/mpi.exr" --mpi --spp 16 "${shard[@]}" \
  --stats "$tmp/mpi.json" >"$tmp/out" 2>"$tmp/err" &&
  python3 -c "import json; s = json.load(open('$tmp/mpi.json')); assert s['spp'] == 16 and s['mpi_ranks'] == 2, s" &&
  [ "$(grep -c '^wrote' "$tmp/out")" -eq 1 ] &&
  /usr/bin/python3 - "$tmp/one.exr" "$tmp/mpi.exr" <<'PY'
import sys, numpy as np, OpenImageIO as oiio
a, b = (oiio.ImageBuf(p).get_pixels(oiio.FLOAT) for p in sys.argv[1:3])
d = np.abs(a - b).max() / max(np.abs(a).max(), 1e-30)
print(f"max relative difference {d:.2e}")
sys.exit(0 if d <= 1e-5 else 1)
PY
then
  pass "mpirun -np 2 render --mpi gives the 16-spp render"
else
  fail "render --mpi on 2 ranks"
  cat "$tmp/out" "$tmp/err"
fi
# A sequence under --mpi: the ranks split the frames; every frame written once, equal bit for
# bit to the single-process sequence's (seed, metered exposure of the PNGs, and for a scene
# without a camera the framing of the first frame's pose)
same_sequence() {  # NAME SCENE
  local name=$1 file=$2 ok=1
  mkdir -p "$tmp/$name-one" "$tmp/$name-mpi"
  seq=(--frames 0:2 --width 24 --height 24 --spp 4 --seed 3 --device pocl -q)
  "$bin" render "$file" -o "$tmp/$name-one/f_#.exr" -o "$tmp/$name-one/f_#.png" "${seq[@]}" >/dev/null 2>&1 &&
    mpirun "${mpirun_args[@]}" "$bin" render "$file" -o "$tmp/$name-mpi/f_#.exr" -o "$tmp/$name-mpi/f_#.png" \
      --mpi "${seq[@]}" >"$tmp/out" 2>"$tmp/err" || ok=0
  [ "$(grep -c '^wrote' "$tmp/out")" -eq 6 ] || ok=0
  /usr/bin/python3 - "$tmp/$name-one" "$tmp/$name-mpi" <<'PY' || ok=0
import sys, numpy as np, OpenImageIO as oiio
for name in (f'f_{f}.{ext}' for f in range(3) for ext in ('exr', 'png')):
    a, b = (oiio.ImageBuf(f'{d}/{name}').get_pixels(oiio.FLOAT) for d in sys.argv[1:3])
    if a is None or b is None or not np.array_equal(a, b):
        sys.exit(f'{name} differs')
PY
  if [ $ok = 1 ]; then
    pass "$name: mpirun -np 2 render --frames 0:2 --mpi writes each frame once, as one process does"
  else
    fail "$name: render --frames --mpi"
    cat "$tmp/out" "$tmp/err"
  fi
}
same_sequence cornell "$scene"
# A room lit by its own dim emitters: PNG outputs exposed from the image, the same on every rank
/usr/bin/python3 -c "import sys; sys.path.insert(0, '$root/tests/app'); import emitter_exposure_test as t; \
t.room_scene('$tmp/room.gltf')" && same_sequence room "$tmp/room.gltf"
fox=$root/../shared/gltf-samples/Fox/Fox.gltf
if [ -f "$fox" ]; then same_sequence fox "$fox"; else echo "skip: $fox is not there"; fi

# The ranks report the error (rank-prefixed) and the job exits non-zero. Whichever rank
# reports first aborts the job, which may kill the others before they print
if ! mpirun "${mpirun_args[@]}" "$bin" render "$scene" -o "$tmp/x.exr" --mpi --time 1 --width 8 --device pocl -q \
  >"$tmp/out" 2>"$tmp/err" && grep -q "^candela: error: rank [0-9]*: --mpi needs --spp" "$tmp/err"; then
  pass "--mpi with --time is refused"
else
  fail "--mpi with --time is refused"
  cat "$tmp/err"
fi
echo "$passes passed, $fails failed"
[ $fails -eq 0 ]
