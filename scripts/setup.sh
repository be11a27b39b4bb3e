#!/usr/bin/env bash
# Installs the Debian packages voxlab needs, but only those that are missing.
# Safe to run repeatedly; needs root (or sudo) only when something is missing.
set -euo pipefail
packages=(
  cmake g++ make pkg-config ccache python3-glad
  libglfw3-dev libimgui-dev libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev zlib1g-dev openimageio-tools libosmesa6-dev libgl-dev libegl-dev
  libgtest-dev libembree-dev xvfb xauth libcmark-dev
  clang libclang-rt-dev llvm  # sanitized build and the libFuzzer target (scripts/build-asan.sh)
  chromium  # headless browser for the handout test (tests/cli/handout.cmake)
  fonts-dejavu-core  # the presenter mode's narrative type (src/inspect/panel_presenter.cpp)
  python3-pil  # scripts/make_sponza.py reduces Sponza's textures (only to regenerate scenes/sponza)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "voxlab setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
