#!/usr/bin/env bash
# Times the default earth bake phase by phase (median of RUNS runs, files
# written, peak resident memory) and how its cost scales: each table axis
# doubled, orders 1 to 8, 3, 15 and 45 wavelengths, 1, 2 and all threads,
# each with its peak memory.
# Prints the Markdown tables that docs/benchmark.md holds.
#
#   scripts/bench.sh             # RUNS=5 by default; run on a quiet machine
#   RUNS=3 scripts/bench.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"${JOBS:-2}" --target skybake >&2
build/cli/skybake bench earth --runs "${RUNS:-5}" --scaling
