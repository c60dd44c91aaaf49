#!/bin/sh
# Runs the shipped runtime on the GPU driver of another x86-64 Linux machine
# against the CPU twin. Here, this packs into BUNDLE_DIR:
#   - skybake_runtime_tests (the runtime's driver tests: GLSL ES 3.0 and GLSL
#     3.3 core through EGL, Vulkan GLSL and HLSL through Vulkan, each on the
#     same queries as the twin, tests/runtime_queries.h) and the two engine
#     examples (examples/engine), built from BUILD_DIR;
#   - a default Earth bake (KTX2 only) for the examples to draw;
#   - glslangValidator and the shared libraries these load, except the C and
#     C++ runtimes and the EGL, GLES and Vulkan loaders, which come with the
#     other machine's driver;
#   - run.sh, which runs them there (as root: glslangValidator goes where the
#     binaries look for it) and writes OUT_DIR/runtime_tests.log,
#     OUT_DIR/examples.log and OUT_DIR/images.tar.
# Back here, the examples' pictures are checked against the twin's:
#   tar -xf OUT_DIR/images.tar -C BUNDLE_DIR
#   SKYBAKE_TEST_GPU_BUNDLE=BUNDLE_DIR build/tests/skybake_tests \
#       --gtest_filter='EngineExample.PicturesDrawnOnAnotherDriverMatchTheTwin'
#
#   scripts/gpu_bundle.sh BUNDLE_DIR [BUILD_DIR]
set -eu
[ $# -ge 1 ] || { echo "usage: scripts/gpu_bundle.sh BUNDLE_DIR [BUILD_DIR]" >&2; exit 1; }
bundle=$1
build=${2:-build}

cmake --build "$build" -j2 --target skybake skybake_runtime_tests skybake_engine_example skybake_vulkan_example
rm -rf "$bundle"
mkdir -p "$bundle/bin" "$bundle/lib"
binaries="$build/tests/skybake_runtime_tests $build/examples/engine/skybake_engine_example
          $build/examples/engine/skybake_vulkan_example"
cp $binaries "$bundle/bin/"
glslang=$(command -v glslangValidator)
cp "$glslang" "$bundle/bin/"
ldd $binaries "$glslang" | awk '$2 == "=>" && $3 ~ /^\// { print $3 }' | sort -u | while read -r library; do
  case $(basename "$library") in
    libc.so.* | libm.so.* | libstdc++.so.* | libgcc_s.so.* | libEGL.so.* | libGLESv2.so.* | libGLdispatch.so.* | \
      libvulkan.so.*) ;;
    *) cp -L "$library" "$bundle/lib/" ;;
  esac
done
"$build/cli/skybake" bake earth -q --format ktx2 --ktx2-supercompression zstd --runtime glsl -o "$bundle/lut"

cat >"$bundle/run.sh" <<EOF
#!/bin/sh
# Written by scripts/gpu_bundle.sh: runs the runtime's driver tests and the
# engine examples on this machine's GPU driver.  run.sh OUT_DIR
set -u
here=\$(cd "\$(dirname "\$0")" && pwd)
out=\$1
mkdir -p "\$out"
export LD_LIBRARY_PATH="\$here/lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
# The binaries run glslangValidator from where it was on the packing machine.
if [ ! -x "$glslang" ]; then mkdir -p "$(dirname "$glslang")" && cp "\$here/bin/glslangValidator" "$glslang"; fi
command -v nvidia-smi >/dev/null && nvidia-smi -L >"\$out/runtime_tests.log"
"\$here/bin/skybake_runtime_tests" --gtest_filter='-RuntimeSnippet.*' >>"\$out/runtime_tests.log" 2>&1
echo "skybake_runtime_tests exit code \$?" >>"\$out/runtime_tests.log"
: >"\$out/examples.log"
for example in engine vulkan; do
  for sun in 60 96; do
    "\$here/bin/skybake_\${example}_example" "\$here/lut" "\$here/images/\$example-sun\$sun" --format ktx2 \\
        --size 128 --sun-zenith \$sun --sun-azimuth 30 >>"\$out/examples.log" 2>&1
    echo "\$example example, sun \$sun: exit code \$?" >>"\$out/examples.log"
  done
done
tar -cf "\$out/images.tar" -C "\$here" images
EOF
chmod +x "$bundle/run.sh"
du -sh "$bundle"
