#!/bin/sh
# Reads every EXR file a real `skybake bake` writes with OpenEXR's and
# OpenImageIO's own tools (Debian packages openexr and openimageio-tools,
# installed by scripts/setup.sh):
#   exrinfo -s           strict header validation, must print the header's
#                        channels (its exit status is not used: OpenEXR 3.1.5's
#                        exrinfo returns an uninitialised count, src/bin/exrinfo/
#                        main.c, process_file; it prints nothing for a header it
#                        rejects)
#   oiiotool --info -v -a  full read with every attribute, must exit 0 and show skybake.table
#   iinfo --stats        must report NaN and Inf counts of 0 in every channel
# First it checks that the tools do catch a truncated file, so a pass means
# something.
#
#   exr_tools_check.sh <skybake> <work dir>
# Exit codes: 0 all good, 1 a tool disagrees, 77 skipped (a tool is missing).
set -u
skybake=$1
work=$2

for tool in exrinfo oiiotool iinfo; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIPPED: $tool not installed (scripts/setup.sh installs openexr and openimageio-tools)"
    exit 77
  fi
done

failures=0
fail() {
  echo "FAILED: $*"
  failures=$((failures + 1))
}

small="--transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32 --sphere-samples 8 --orders 2"
rm -rf "$work"
mkdir -p "$work"
# float, half, and single Mie packed into alpha (RGBA files).
for variant in float half pack-mie; do
  case $variant in
    float) extra="" ;;
    half) extra="--half" ;;
    pack-mie) extra="--pack-mie" ;;
  esac
  # shellcheck disable=SC2086
  if ! "$skybake" bake earth -q --format exr -o "$work/$variant" $small $extra; then
    echo "FAILED: skybake bake ($variant) failed"
    exit 1
  fi
done

# check FILE: returns non-zero (and says why) if any tool objects.
check() {
  file=$1
  status=0
  out=$(exrinfo -s "$file" 2>&1)
  if ! printf '%s\n' "$out" | grep -q 'channels:'; then
    echo "exrinfo -s $file: no header read: $out"
    status=1
  fi
  if ! out=$(oiiotool --info -v -a "$file" 2>&1); then
    echo "oiiotool --info -v -a $file: $out"
    status=1
  elif ! printf '%s\n' "$out" | grep -q 'skybake.table'; then
    echo "oiiotool --info -v -a $file: no skybake.table attribute"
    status=1
  fi
  # iinfo exits 0 even when it cannot read the file: judge by its output.
  out=$(iinfo --stats "$file" 2>&1)
  if printf '%s\n' "$out" | grep -q 'ERROR'; then
    echo "iinfo --stats $file: $out"
    status=1
  else
    for stat in NanCount InfCount; do
      line=$(printf '%s\n' "$out" | grep "Stats $stat:")
      if [ -z "$line" ]; then
        echo "iinfo --stats $file: no $stat line"
        status=1
      elif printf '%s\n' "$line" | sed "s/.*$stat://" | tr ' ' '\n' | grep -qv '^0*$'; then
        echo "iinfo --stats $file: $line"
        status=1
      fi
    done
  fi
  return $status
}

# The checkers must catch damage, or a pass proves nothing.
head -c 3000 "$work/float/scattering.exr" > "$work/truncated.exr"
if check "$work/truncated.exr" >/dev/null 2>&1; then
  fail "the tools accept a truncated EXR file; this check would prove nothing"
fi
head -c 64 "$work/float/scattering.exr" > "$work/header_cut.exr"
if exrinfo -s "$work/header_cut.exr" 2>&1 | grep -q 'channels:'; then
  fail "exrinfo -s reads a header cut short; its check would prove nothing"
fi
rm -f "$work/header_cut.exr"

count=0
for file in "$work"/*/*.exr; do
  count=$((count + 1))
  if check "$file"; then
    echo "ok   $file"
  else
    fail "$file"
  fi
done
if [ "$count" -ne 11 ]; then
  fail "expected 11 EXR files (4 + 4 + 3), found $count"
fi
if [ "$failures" -ne 0 ]; then
  echo "exr tools check: $failures problem(s)"
  exit 1
fi
echo "exr tools check: $count EXR files pass exrinfo -s, oiiotool --info -v -a and iinfo --stats (no NaN, no Inf)"
