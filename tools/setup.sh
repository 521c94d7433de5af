#!/usr/bin/env bash
# Installs everything fovea needs on Debian bookworm (idempotent; run as root or with sudo).
# Mesa 25 (lavapipe, Vulkan 1.4 with timestamps) comes from bookworm-backports; bookworm's own
# Mesa 22 lacks features we rely on.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

BACKPORTS=/etc/apt/sources.list.d/fovea-bookworm-backports.sources
if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  $SUDO tee "$BACKPORTS" >/dev/null <<'SRC'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
# Vulkan from backports: driver (lavapipe), loader, headers, validation layers, tools.
$SUDO apt-get install -y -q -t bookworm-backports \
  mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers vulkan-tools \
  glslang-dev glslang-tools spirv-tools libshaderc-dev
# Build tools and the OpenXR loader (the loader is only dlopen'ed at run time).
$SUDO apt-get install -y -q build-essential pkg-config cmake libopenxr-loader1 libopenxr-dev
# `fovea view`: the X11 and Wayland client libraries winit loads at run time, and Xvfb (a
# virtual X server) with xauth, which the viewer tests open their windows on.
$SUDO apt-get install -y -q xvfb xauth libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 \
  libxkbcommon0 libxkbcommon-x11-0 libwayland-client0 libwayland-cursor0
# Weston, whose headless backend the Wayland viewer test opens its window on.
$SUDO apt-get install -y -q weston
# The XR tests: Khronos' hello_xr (libopenxr-utils), run against the simulated headset, and
# the OpenXR core validation layer fovea's session is checked under.
$SUDO apt-get install -y -q libopenxr-utils openxr-layer-corevalidation

echo "setup: Vulkan devices:"
vulkaninfo --summary 2>/dev/null | grep -E "deviceName|apiVersion|driverInfo" || true
