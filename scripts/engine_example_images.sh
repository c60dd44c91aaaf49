#!/usr/bin/env bash
# Regenerates the engine example's images in the README
# (docs/images/engine/earth_sz*_{fisheye,aerial}.png): bakes the default
# `earth` set, then renders it on the GPU path (OpenGL ES 3.0 on Mesa,
# headless) with examples/engine at three sun zenith angles.
#
#   scripts/engine_example_images.sh      # from the repository root or anywhere
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
work=build/engine_example
out=docs/images/engine

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"${JOBS:-2}" --target skybake skybake_engine_example >&2

build/cli/skybake bake earth -o "$work/tables" --format ktx2 --quiet
mkdir -p "$out"
# Noon-ish, afternoon, and the sun 2 degrees above the horizon.
for sun_zenith in 30 70 88; do
  build/examples/engine/skybake_engine_example "$work/tables" "$work/sz$sun_zenith" --size 256 \
    --sun-zenith "$sun_zenith"
  for view in fisheye aerial; do
    cp "$work/sz$sun_zenith/$view.png" "$out/earth_sz${sun_zenith}_$view.png"
  done
  echo "engine example: $out/earth_sz${sun_zenith}_*.png" >&2
done
