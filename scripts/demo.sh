#!/usr/bin/env bash
# The README's main command: install missing packages, build (Release), and run the main job on a
# bundled default: inspect the shared 1,500-triangle bunny, query exact closest points and signed
# distances, bake it (sphere-tree + closest feature maps + contact tree) and print a level of spheres.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" --target clod_cli
mesh=${1:-../shared/data/meshes/bunny-1500.obj}
out=${2:-out/demo}
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
echo "== clod simulate scenes/bunny_on_box.json"
build/bin/clod simulate scenes/bunny_on_box.json -o "$out/bunny_on_box" --progress
echo "wrote $out/bunny_on_box/{trajectory.csv,contacts.csv,summary.json}"
