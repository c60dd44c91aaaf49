#!/bin/sh
# The largest relative difference |new - old| / |old| per channel of every EXR
# table of two baked sets, with OpenImageIO's oiiotool:
#
#   scripts/table_differences.sh OLD_SET NEW_SET
set -eu
for old in "$1"/*.exr; do
  name=$(basename "$old")
  max=$(oiiotool "$old" "$2/$name" --absdiff "$old" --abs --addc 1e-30 --div --printstats 2>&1 |
        sed -n 's/^ *Stats Max: *\([^(]*\)(.*/\1/p')
  echo "$name max relative difference per channel: $max"
done
