#!/usr/bin/env bash
# Installs dependencies if needed and builds skybake (Release) into build/:
# the targets named as arguments (scripts/skybake builds only the skybake
# executable), or every target, the tests included, without any.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ $# -gt 0 ]; then
  cmake --build "$root/build" -j"$(nproc)" --target "$@" >&2
else
  cmake --build "$root/build" -j"$(nproc)" >&2
fi
