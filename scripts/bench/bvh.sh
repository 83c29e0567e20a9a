#!/usr/bin/env bash
# BVH build speed and host memory per triangle on 1 M and 10 M triangles.
#
# Usage: scripts/bench/bvh.sh [ROUNDS (3)] [THREADS (1,all)]
#
# Meshes (generated on first use into build/bench/, never committed): the 1 M mesh
# (build/bench/suzanne-1m.gltf through Blender when installed, else mesh-1m.gltf from
# scripts/scenes/make_bench_mesh.py) and build/bench/mesh-10m.gltf (make_bench_mesh.py, 10 M).
# 1. build/bench/candela_bvh_bench builds each mesh's BVH ROUNDS times with each thread
#    count, alternating: wall seconds, CPU seconds, triangles/s, SAH cost, and whether the
#    tree is byte-identical across thread counts (JSON lines).
# 2. `candela render --stats` (16x16, 1 spp, PoCL) on the Cornell box, the 1 M and the
#    10 M mesh: peak RSS (getrusage), its bytes per triangle, and the marginal bytes per
#    triangle between the 1 M and the 10 M mesh (what a triangle costs once the OpenCL
#    platforms and libraries are loaded).
# The machines are shared: wall-clock build times move with the load (see uptime);
# CPU seconds and the ratios within one run are the stable numbers.
source "$(dirname "${BASH_SOURCE[0]}")/../setup.sh" >&2
cd "$CANDELA_ROOT"
rounds=${1:-3}
threads=${2:-1,all}
if command -v blender >/dev/null 2>&1; then
  m1=build/bench/suzanne-1m.gltf
  [ -f "$m1" ] || blender -b --factory-startup -noaudio --python scripts/scenes/make_blender_mesh.py -- "$m1" >/dev/null 2>&1
else
  m1=build/bench/mesh-1m.gltf
  [ -f "$m1" ] || python3 scripts/scenes/make_bench_mesh.py "$m1" >&2
fi
m10=build/bench/mesh-10m.gltf
[ -f "$m10" ] || python3 scripts/scenes/make_bench_mesh.py "$m10" 10000000 >&2
echo "# $(uptime)"
for m in "$m1" "$m10"; do
  build/bench/candela_bvh_bench "$m" "$rounds" "$threads"
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for m in scenes/cornell-box/cornell-box.gltf "$m1" "$m10"; do
  build/candela render "$m" -o "$tmp/x.exr" --spp 1 --width 16 --height 16 --device pocl -q --stats "$tmp/$(basename "$m").json" >/dev/null
done
python3 - "$tmp" "$m1" "$m10" <<'PY'
import json, os, sys
tmp, m1, m10 = sys.argv[1:4]
s = {m: json.load(open(os.path.join(tmp, os.path.basename(m) + ".json"))) for m in ("cornell-box.gltf", m1, m10)}
for m, d in s.items():
    print(json.dumps({"memory": os.path.basename(m), "triangles": d["triangles"], "peak_rss_bytes": d["peak_rss_bytes"],
                      "peak_rss_bytes_per_triangle": round(d["peak_rss_bytes"] / max(1, d["triangles"]), 1),
                      "device_bytes_per_triangle": round(d["device_bytes_per_triangle"], 1),
                      "bvh_build_seconds": round(d["bvh_build_seconds"], 3)}))
a, b = s[m1], s[m10]
print(json.dumps({"memory": "marginal, %s to %s" % (os.path.basename(m1), os.path.basename(m10)),
                  "bytes_per_triangle": round((b["peak_rss_bytes"] - a["peak_rss_bytes"]) /
                                              (b["triangles"] - a["triangles"]), 1)}))
PY
