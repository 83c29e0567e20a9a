#!/usr/bin/env bash
# Renders every shipped scene (and the glTF sample assets, when ../shared/gltf-samples is
# there) small and fast with fixed seeds, and prints one line per render: the SHA-256 of the
# linear pixels, then the render's name. Two runs print the same lines exactly when the
# images are bit-identical: the check that a refactor changed no image.
# Usage: scripts/check/image-digest.sh [CANDELA_BINARY] > digests.txt
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
bin=${1:-$root/build/candela}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
digest() {  # NAME SCENE [render options...]
  local name=$1 scene=$2
  shift 2
  if ! "$bin" render "$scene" -o "$tmp/out.exr" -q --device pocl --width 48 --spp 4 "$@" >/dev/null 2>"$tmp/err"; then
    echo "FAILED  $name"; sed 's/^/  /' "$tmp/err"; return
  fi
  printf '%s  %s\n' "$(PYTHONPATH="$root/scripts" /usr/bin/python3 -m candela_tools digest "$tmp/out.exr" | cut -d' ' -f1)" \
    "$name"
}
for scene in $(cd "$root" && find scenes -name '*.gltf' | sort); do
  for strategy in nee bsdf auto; do
    digest "$scene $strategy" "$root/$scene" --strategy "$strategy" --max-depth 8
  done
  digest "$scene generic" "$root/$scene" --generic --max-depth 8
done
digest "materials no-energy-compensation" "$root/scenes/materials/materials.gltf" --no-energy-compensation
digest "materials independent tent" "$root/scenes/materials/materials.gltf" --sampler independent --filter tent
# The sample assets beside the checkout (from a git worktree: beside the main checkout)
samples=$(PYTHONPATH="$root/scripts" /usr/bin/python3 -c 'import candela_tools as ct; print(ct.samples_folder())')
if [ -d "$samples" ]; then
  for f in $(find "$samples" -name '*.gltf' -o -name '*.glb' | sort); do
    digest "${f#"$samples"/}" "$f" --max-depth 6
  done
fi
