#!/bin/sh
# Bakes the sets whose bytes a change that is not meant to alter results must
# keep: the default earth, a scene bake, --half, --orders auto on heavy fog and
# on Mars, and the fit of earth; prints one "sha256  set/file" line per file,
# with the manifests' "command" line (which names the folder) left out.
#
#   scripts/output_digests.sh BUILD/cli/skybake > after.txt
#   diff before.txt after.txt   # nothing: the outputs are byte-identical
#
# With a second argument the sets are kept in that (new) folder, for
# scripts/table_differences.sh OLD/earth NEW/earth where the bytes differ.
set -eu
exe=$(realpath "$1")
root=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -ge 2 ]; then
  mkdir "$2"
  work=$(realpath "$2")
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
cd "$work"
"$exe" bake earth -o earth -q
"$exe" bake earth --scene "$root/examples/scenes/sunset-cinematic.toml" -o scene -q
"$exe" bake earth --half -o half -q
"$exe" bake heavy-fog --orders auto -o heavy-fog-auto -q
"$exe" bake mars --orders auto -o mars-auto -q
mkdir fit && "$exe" fit earth -o fit/earth >/dev/null 2>&1
for file in $(find . -type f | sort); do
  case "$file" in
    *.json) grep -v '"command":' "$file" | sha256sum | sed "s|-\$|${file#./}|" ;;
    *) sha256sum "$file" | sed 's|  \./|  |' ;;
  esac
done
