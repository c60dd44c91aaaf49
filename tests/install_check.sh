#!/bin/sh
# `cmake --install` end to end: installs the build into a temporary prefix,
# builds examples/install_consumer against the installed package
# (find_package(skybake), skybake::formats), bakes a small set with the
# installed skybake and loads it with the consumer; the installed skybake
# writes a plot through its installed image module.
#   install_check.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1 source=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
for f in bin/skybake include/skybake/formats/lut_files.h include/skybake/core/version.h \
         lib/cmake/skybake/skybakeConfig.cmake share/skybake/shaders_runtime/functions.glsl; do
  [ -e "$work/prefix/$f" ] || { echo "install_check: $f was not installed"; exit 1; }
done
cmake -S "$source/examples/install_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >"$work/configure.log"
cmake --build "$work/consumer" >"$work/build.log"
"$work/prefix/bin/skybake" bake preset:earth -o "$work/set" -q --format ktx2 --transmittance-size 64 16 \
  --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32 --sphere-samples 8 --orders 2
out=$("$work/consumer/load_set" "$work/set")
echo "$out"
echo "$out" | grep -qx "scattering 32x32x8" || { echo "install_check: unexpected output"; exit 1; }
# The installed skybake writes images through its installed image module.
LD_DEBUG=files "$work/prefix/bin/skybake" info "$work/set" --plot "$work/plots" >"$work/plot.log" 2>&1
grep -q "$work/prefix/lib[^ ]*/skybake/libskybake_images.so" "$work/plot.log" ||
  { echo "install_check: the installed image module was not the one loaded"; exit 1; }
[ -s "$work/plots/lut_transmittance.png" ] || { echo "install_check: no plot written"; exit 1; }
echo "install_check: the installed package loads a set baked by the installed skybake"
