#!/bin/sh
# `cmake --install` end to end: installs the build into a temporary prefix,
# builds examples/install_consumer against the installed package
# (find_package(skybake), skybake::formats), whose build bakes a small set
# with the installed skybake (skybake_add_bake), and loads the set with the
# consumer. A second build does nothing; a touched atmosphere file runs the
# bake, which finds the set up to date; a changed one bakes it again. The
# installed skybake writes a plot through its installed image module.
#   install_check.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1 source=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
fail() { echo "install_check: $*"; exit 1; }
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
for f in bin/skybake include/skybake/formats/lut_files.h include/skybake/core/version.h \
         lib/cmake/skybake/skybakeConfig.cmake lib/cmake/skybake/skybakeAddBake.cmake \
         share/skybake/shaders_runtime/lookups.glsl; do
  [ -e "$work/prefix/$f" ] || fail "$f was not installed"
done
# Ninja where it is installed (scripts/setup.sh installs it), else Makefiles:
# both read the bake's depfile.
generator=
command -v ninja >/dev/null 2>&1 && generator="-GNinja"
cp "$source/examples/atmospheres/earth.toml" "$work/sky.toml"
cmake -S "$source/examples/install_consumer" -B "$work/consumer" $generator -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release -DSKY_ATMOSPHERE="$work/sky.toml" \
  "-DSKY_BAKE_OPTIONS=--format;ktx2;--transmittance-size;64;16;--irradiance-size;16;4;--scattering-size;8;32;8;4;--ray-samples;32;--sphere-samples;8;--orders;2" \
  >"$work/configure.log"
set=$work/consumer/sky
build_consumer() {  # build_consumer LOG: builds, and says whether the bake ran
  cmake --build "$work/consumer" >"$work/$1" 2>&1 || { cat "$work/$1"; fail "the consumer's build failed"; }
  grep -q "skybake bake" "$work/$1"
}
build_consumer build.log || fail "the first build did not bake"
out=$("$work/consumer/load_set" "$set")
echo "$out"
echo "$out" | grep -qx "scattering 32x32x8" || fail "unexpected output"
cp "$set/skybake.json" "$work/manifest.first"
! build_consumer build2.log || fail "the second build ran the bake again"
# A file saved unchanged: the bake runs, finds the set up to date and leaves it.
sleep 1
touch "$work/sky.toml"
build_consumer build3.log || fail "a touched atmosphere file did not run the bake"
grep -q "is up to date, not baked again" "$work/build3.log" || fail "an up-to-date set was baked again"
cmp -s "$set/skybake.json" "$work/manifest.first" || fail "an up-to-date set was written again"
! build_consumer build4.log || fail "the build after an up-to-date bake ran it again"
# A changed atmosphere bakes the set again.
sed 's/^ground_albedo = 0.1$/ground_albedo = 0.3/' "$work/sky.toml" >"$work/sky.new"
mv "$work/sky.new" "$work/sky.toml"
build_consumer build5.log || fail "a changed atmosphere file did not run the bake"
grep -q "^baking" "$work/build5.log" || fail "a changed atmosphere did not bake the set again"
grep -A1 '"ground_albedo"' "$set/skybake.json" | grep -q '0\.3' || fail "the set was not baked from the changed atmosphere"
"$work/consumer/load_set" "$set" >/dev/null || fail "the re-baked set does not load"
# The installed skybake writes images through its installed image module.
LD_DEBUG=files "$work/prefix/bin/skybake" info "$set" --plot "$work/plots" >"$work/plot.log" 2>&1
grep -q "$work/prefix/lib[^ ]*/skybake/libskybake_images.so" "$work/plot.log" ||
  fail "the installed image module was not the one loaded"
[ -s "$work/plots/lut_transmittance.png" ] || fail "no plot written"
echo "install_check: the installed package bakes a set as a build step, again only when its atmosphere changes,"
echo "install_check: and loads it"
