#!/usr/bin/env bash
# Installs skybake's build and test dependencies from Debian 12 packages.
# Idempotent: packages already present are skipped, so re-running is cheap.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libopenexr-dev openexr
  libopenimageio-dev openimageio-tools
  libceres-dev libglm-dev libtbb-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libssl-dev libzstd-dev
  libgtest-dev libbenchmark-dev
  glslang-tools spirv-cross fonts-dejavu-core
  libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
  libvulkan-dev mesa-vulkan-drivers
  nodejs
)

as_root=""
[ "$(id -u)" -eq 0 ] || as_root="sudo"

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm is only needed for the independent KTX2 cross-check; some nodejs builds bundle it.
command -v npm >/dev/null 2>&1 || missing+=(npm)

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  $as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
