#!/usr/bin/env bash
# Kernel specialization: per scene, the kernel specialized to the scene's features against
# the generic one (--generic: every SceneFeatures flag on). Kernel build cold (empty
# candela and driver caches) and cached, and render speed in alternating runs, as samples
# per CPU-second: the CPU time of a render of 4 + spp samples less that of one of 4, so
# that start-up, scene loading and other machines' load cancel out (more samples where that
# difference is under 0.2 CPU-s; "nan" where even 64 times spp does not resolve it).
# Usage: scripts/bench/specialization.sh [device (default pocl)] [rounds (default 3)] [width (default 128)] [spp (default 8)]
source "$(dirname "${BASH_SOURCE[0]}")/../setup.sh"
cd "$CANDELA_ROOT"
dev=${1:-pocl}
rounds=${2:-3}
width=${3:-128}
spp=${4:-8}
export RUSTICL_ENABLE=${RUSTICL_ENABLE:-llvmpipe}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
scenes=${CANDELA_BENCH_SCENES:-"scenes/cornell-box/cornell-box.gltf scenes/materials/materials.gltf scenes/lights/environment.gltf scenes/lights/punctual.gltf"}
for scene in $scenes; do
  name=$(basename "$scene" .gltf)
  for variant in specialized generic; do
    flag=$([ $variant = generic ] && echo --generic || true)
    caches=(CANDELA_CACHE_DIR="$out/$name-$variant/candela" POCL_CACHE_DIR="$out/$name-$variant/pocl"
            MESA_SHADER_CACHE_DIR="$out/$name-$variant/mesa")
    for run in cold cached; do
      start=$(date +%s%N)
      env "${caches[@]}" ./build/candela render "$scene" -o "$out/x.exr" --spp 1 --width 16 --device "$dev" $flag -q \
        --stats "$out/$name-$variant-$run.json" >/dev/null 2>&1 || { echo "$scene: render failed"; exit 1; }
      echo $(( $(date +%s%N) - start )) >"$out/$name-$variant-$run.wall"
    done
  done
done
/usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/specialization_speed.py" "$out" "$rounds" "$dev" "$width" "$spp" $scenes
