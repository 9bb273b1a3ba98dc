#!/usr/bin/env bash
# Regenerates the test meshes of issue 4 from the shape library (clumpkit mesh): ASCII STL in
# metres, ~2000 triangles for curved shapes, the rock with seed 1. The test
# ShapeLibrary.CommittedMeshesAreWhatTheGeneratorWrites checks that these files are current.
#   meshes/generate.sh [path/to/clumpkit]       (or: ninja regenerate_meshes)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
clumpkit="${1:-$here/../build/apps/clumpkit/clumpkit}"
for shape in $("$clumpkit" mesh --list | awk '{print $1}'); do
  "$clumpkit" mesh "$shape" --triangles 2000 --seed 1 --units m -o "$here/$shape.stl"
done
