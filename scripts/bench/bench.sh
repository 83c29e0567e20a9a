#!/usr/bin/env bash
# Speed benchmark over the shipped scenes and a generated million-triangle mesh.
#
# Usage: scripts/bench/bench.sh [options] [spp] [devices]
#   spp                    samples per pixel of the timed render (default 16)
#   devices                space-separated --device selectors (default "pocl rusticl")
#   --scenes "A B ..."     scene files (default: the Cornell box, materials, lights/*.gltf
#                          and the million-triangle mesh, generated on first use:
#                          build/bench/suzanne-1m.gltf through Blender when it is installed
#                          (scripts/scenes/make_blender_mesh.py), else build/bench/mesh-1m.gltf
#                          (scripts/scenes/make_bench_mesh.py))
#   --size N               image size N x N (default 512); --max-depth D (default 8)
#   --json | --csv         print JSON lines or CSV instead of the table
#   --out FILE             append the JSON lines to FILE as well
#   --kernel-dir DIR       kernel sources to benchmark (A/B tests on copies of cl/)
#   --binary PATH          candela binary (default build/candela)
#   --record               set each scene's figure (SCENE-bench-DEVICE) in docs/figures/results.json
#                          (scripts/bench/bench_rows.py record)
#
# For each scene and device: a cold run (empty candela and PoCL kernel caches, 16x16,
# 1 spp) gives the uncached kernel build; a second one the cached build; then the timed
# render (next-event estimation) runs under /usr/bin/time -v for the peak resident set.
# Each result is one JSON object (--json, --out) with: scene, device, triangles, spp,
# seconds, samples_per_second, bvh_build_seconds, bvh_triangles_per_second,
# kernel_build_cold_seconds, kernel_build_cached_seconds, kernel_from_cache,
# scene_device_bytes, device_bytes_per_triangle, peak_rss_bytes (getrusage, from --stats;
# /usr/bin/time for binaries without it), peak_rss_bytes_per_triangle, bvh_sah_cost,
# bvh_threads, git commit (of the checkout, "+dirty" with local changes), binary,
# kernel_dir, time. Side by side with Blender Cycles: scripts/compare/vs_cycles.py.
# The machines are shared and noisy: compare runs made back to back, alternating.
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/../setup.sh" >&2  # build messages off stdout
cd "$CANDELA_ROOT"
command_line="scripts/bench/bench.sh $*"

spp=16
devices="pocl rusticl"
scenes=""
size=512
max_depth=8
out_file=""
csv=0
kernel_dir=""
binary=./build/candela
record=""
positional=()
while [ $# -gt 0 ]; do
  case "$1" in
    --scenes) scenes=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --max-depth) max_depth=$2; shift 2 ;;
    --out) out_file=$2; shift 2 ;;
    --csv) csv=1; shift ;;
    --json) csv=2; shift ;;
    --kernel-dir) kernel_dir=$2; shift 2 ;;
    --binary) binary=$2; shift 2 ;;
    --record) record=$command_line; shift ;;
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
    *) positional+=("$1"); shift ;;
  esac
done
[ ${#positional[@]} -ge 1 ] && spp=${positional[0]}
[ ${#positional[@]} -ge 2 ] && devices=${positional[1]}
export RUSTICL_ENABLE=${RUSTICL_ENABLE:-llvmpipe}

if command -v blender >/dev/null 2>&1; then
  mesh=build/bench/suzanne-1m.gltf
else
  mesh=build/bench/mesh-1m.gltf
fi
if [ -z "$scenes" ]; then
  scenes="scenes/cornell-box/cornell-box.gltf scenes/materials/materials.gltf"
  for f in scenes/lights/*.gltf; do [ -f "$f" ] && scenes="$scenes $f"; done
  scenes="$scenes $mesh"
fi
case " $scenes " in
  *" build/bench/mesh-1m.gltf "*) [ -f build/bench/mesh-1m.gltf ] || python3 scripts/scenes/make_bench_mesh.py build/bench/mesh-1m.gltf >&2 ;;
esac
case " $scenes " in
  *" build/bench/suzanne-1m.gltf "*) [ -f build/bench/suzanne-1m.gltf ] ||
    blender -b --factory-startup -noaudio --python scripts/scenes/make_blender_mesh.py -- build/bench/suzanne-1m.gltf >/dev/null 2>&1 ;;
esac

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
extra=()
[ -n "$kernel_dir" ] && export CANDELA_KERNEL_DIR=$kernel_dir
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
[ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ] && commit="$commit+dirty"

for dev in $devices; do
  for scene in $scenes; do
    name=$(basename "$scene" .gltf)
    cold="$tmp/cold-$dev-$name"
    mkdir -p "$cold/candela" "$cold/pocl"
    # Cold: empty candela cache and empty PoCL kernel cache
    if ! CANDELA_CACHE_DIR="$cold/candela" POCL_CACHE_DIR="$cold/pocl" "$binary" render "$scene" \
        -o "$tmp/c.exr" --spp 1 --width 16 --height 16 --device "$dev" -q "${extra[@]}" \
        --stats "$tmp/cold.json" >/dev/null 2>"$tmp/err"; then
      echo "{\"scene\": \"$name\", \"device\": \"$dev\", \"error\": \"$(head -c 200 "$tmp/err" | tr '\n"' '  ')\"}"
      continue
    fi
    CANDELA_CACHE_DIR="$cold/candela" POCL_CACHE_DIR="$cold/pocl" "$binary" render "$scene" \
      -o "$tmp/c.exr" --spp 1 --width 16 --height 16 --device "$dev" -q "${extra[@]}" \
      --stats "$tmp/cached.json" >/dev/null 2>&1
    CANDELA_CACHE_DIR="$cold/candela" POCL_CACHE_DIR="$cold/pocl" /usr/bin/time -v -o "$tmp/time.txt" \
      "$binary" render "$scene" -o "$tmp/r.exr" --spp "$spp" --width "$size" --height "$size" \
      --max-depth "$max_depth" --device "$dev" -q "${extra[@]}" --stats "$tmp/run.json" >/dev/null
    rm -rf "$cold"
    /usr/bin/python3 "$here/bench_rows.py" row "$name" "$dev" "$commit" "$tmp" "$binary" "$kernel_dir"
  done
done | tee ${out_file:+-a "$out_file"} ${record:+"$tmp/rows.jsonl"} | if [ "$csv" = 2 ]; then
  cat
elif [ "$csv" = 1 ]; then
  /usr/bin/python3 "$here/bench_rows.py" csv
else
  /usr/bin/python3 "$here/bench_rows.py" table
fi
if [ -n "$record" ]; then
  /usr/bin/python3 "$here/bench_rows.py" record "$record" <"$tmp/rows.jsonl"
fi
