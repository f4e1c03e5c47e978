#!/usr/bin/env bash
# The README's main command: install missing packages, build (Release), and run the main job on a
# bundled default: inspect the shared 1,500-triangle bunny, query exact closest points and signed
# distances, bake it (sphere-tree + closest feature maps + contact tree) and print a level of spheres,
# then drop the bunny onto a box with glTF export and build the web viewer to watch it:
#   scripts/demo.sh [MESH] [OUTDIR] [--view]   (--view starts `clod view` on the result at the end)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" --target clod_cli
view=0
args=()
for arg in "$@"; do
  if [[ "$arg" == --view ]]; then view=1; else args+=("$arg"); fi
done
mesh=${args[0]:-../shared/data/meshes/bunny-1500.obj}
out=${args[1]:-out/demo}
mkdir -p "$out"
echo "== clod inspect $mesh"
build/bin/clod inspect "$mesh"
printf '0 0 0\n0.05 0.1 0.02\n-0.1 0.2 0.3\n' > "$out/points.txt"
echo "== clod closest (3 points)"
build/bin/clod closest "$mesh" --points "$out/points.txt" --json
echo "== clod bake"
build/bin/clod bake "$mesh" -o "$out/bunny.clod"
echo "== clod spheres --level 1"
build/bin/clod spheres "$out/bunny.clod" --level 1 --json | head -20
echo "== clod simulate scenes/bunny_on_box.json --gltf"
build/bin/clod simulate scenes/bunny_on_box.json -o "$out/bunny_on_box" --gltf --progress
echo "wrote $out/bunny_on_box/{trajectory.csv,contacts.csv,summary.json,scene.glb,layers.json}"
echo "== web viewer (scripts/build-viewer.sh)"
scripts/build-viewer.sh
if ((view)); then
  exec build/bin/clod view "$out/bunny_on_box"
fi
echo "watch it: build/bin/clod view $out/bunny_on_box   (then open the printed URL)"
