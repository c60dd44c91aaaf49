#!/usr/bin/env bash
# Regenerates the figures in README.md and docs/*.md that come from commands,
# in place between their marker comments (<!-- figures:NAME begin ... -->
# ... <!-- figures:NAME end -->); scripts/figures.py lists which command
# makes which block.
#
#   scripts/figures.sh            # = fast: sizes orders cli (about a minute)
#   scripts/figures.sh sizes      # file sizes and half error (docs/files.md)
#   scripts/figures.sh orders     # --orders N and the extrapolated tail (docs/accuracy.md)
#   scripts/figures.sh cli        # presets and bake defaults (docs/cli.md)
#   scripts/figures.sh scenes     # the example scenes against the full bake (examples/scenes/README.md,
#                                 # about two minutes)
#   scripts/figures.sh stress     # the stress set's table (docs/stability.md, about half a minute)
#   scripts/figures.sh bench      # docs/benchmark.md (scripts/bench.sh, about 7 minutes)
#   scripts/figures.sh report     # docs/accuracy.md, docs/images/report/ and the colour error in
#                                 # docs/colour.md and README.md (skybake report, a few minutes)
#   scripts/figures.sh runtime-cost  # the runtime's cost per pixel beside Bruneton's (docs/runtime_cost.md:
#                                 # tests/runtime_cost.cpp on llvmpipe and lavapipe, about 10 minutes)
#   scripts/figures.sh images     # the gallery and the engine example's images (scripts/gallery.sh,
#                                 # scripts/engine_example_images.sh) and the sky through sunset
#                                 # (docs/images/twilight/lut_sunset.png, skybake info --plot)
#   scripts/figures.sh all        # everything above (about 20 minutes)
#
# bench, report, scenes and runtime-cost time the machine: run them with nothing else running.
# SKYBAKE=path/to/skybake uses that executable and skips the build; likewise
# SKYBAKE_RUNTIME_COST=path/to/skybake_runtime_cost.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

parts=()
images=0
for arg in "${@:-fast}"; do
  case "$arg" in
    fast) parts+=(sizes orders cli) ;;
    all) parts+=(sizes orders cli scenes stress bench report runtime-cost); images=1 ;;
    images) images=1 ;;
    sizes | orders | cli | scenes | stress | bench | report | runtime-cost) parts+=("$arg") ;;
    *) sed -n '2,26p' "${BASH_SOURCE[0]}" >&2; exit 1 ;;
  esac
done

if [ -z "${SKYBAKE:-}" ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"${JOBS:-2}" --target skybake >&2
  SKYBAKE=build/cli/skybake
fi
if [[ " ${parts[*]:-} " == *" runtime-cost "* && -z "${SKYBAKE_RUNTIME_COST:-}" ]]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"${JOBS:-2}" --target skybake_runtime_cost >&2
  export SKYBAKE_RUNTIME_COST=build/tests/skybake_runtime_cost
fi
if ((${#parts[@]})); then
  /usr/bin/python3 scripts/figures.py "$SKYBAKE" "${parts[@]}"
fi
if ((images)); then
  scripts/gallery.sh
  scripts/engine_example_images.sh
  "$SKYBAKE" bake earth -o build/figures/sunset/earth -q
  "$SKYBAKE" info build/figures/sunset/earth --plot build/figures/sunset/plots >/dev/null
  cp build/figures/sunset/plots/lut_sunset.png docs/images/twilight/
fi
