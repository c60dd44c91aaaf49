#!/usr/bin/env bash
# Regenerates the README gallery (docs/images/gallery/*.png, see docs/gallery.md):
# for each of earth, mars, heavy-haze and light-fog, bakes reduced tables,
# renders 256-pixel fisheyes and aerial strips at sunrise, noon and sunset
# through the CPU twin, and keeps the contact sheet.
#
#   scripts/gallery.sh            # from the repository root or anywhere
#
# Tables are smaller than the default bake (scattering 16x64x16x8 instead of
# 32x128x32x8, 3 orders instead of 4) so the whole gallery takes about a
# minute on two cores; the pictures differ from a full bake only in fine
# detail near the horizon.
set -euo pipefail
# Relative paths from the repository root, so the command line recorded in
# each PNG (and so the file) is the same in every clone.
cd "$(dirname "${BASH_SOURCE[0]}")/.."
work=build/gallery
out=docs/images/gallery

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"${JOBS:-2}" --target skybake >&2
skybake=build/cli/skybake

bake_size=(--transmittance-size 128 32 --irradiance-size 32 8 --scattering-size 16 64 16 8
           --ray-samples 64 --sphere-samples 8 --orders 3)
# sunrise: sun 4 degrees above the horizon; noon: 30 degrees from the zenith;
# sunset: sun 1 degree below the horizon (civil twilight).
sun_zenith=86,30,91

mkdir -p "$out"
for preset in earth mars heavy-haze light-fog; do
  "$skybake" bake "$preset" -o "$work/$preset/tables" "${bake_size[@]}" --quiet
  "$skybake" render "$work/$preset/tables" -o "$work/$preset/render" --size 256 --sun-zenith "$sun_zenith" \
    --views fisheye,aerial --quiet
  cp "$work/$preset/render/contact_sheet.png" "$out/$preset.png"
  echo "gallery: $out/$preset.png" >&2
done
