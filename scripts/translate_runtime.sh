#!/usr/bin/env bash
# Regenerates shaders_runtime/generated/ (the HLSL, MSL and WGSL runtimes)
# from the GLSL runtime. Run after editing any shaders_runtime/*.glsl; the
# ctest runtime_translation_fresh fails while the committed files are stale.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
node "$root/shaders_runtime/translate/translate.mjs" --out "$root/shaders_runtime/generated" \
  --work-dir "${SKYBAKE_NPM_WORK_DIR:-$root/build/tests/npm/runtime_translate}"
