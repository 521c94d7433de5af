#!/usr/bin/env bash
# Installs everything fovea needs on Debian bookworm (idempotent; run as root or with sudo).
# Mesa 25 (lavapipe, Vulkan 1.4 with timestamps) comes from bookworm-backports; bookworm's own
# Mesa 22 lacks features we rely on.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

BACKPORTS=/etc/apt/sources.list.d/fovea-bookworm-backports.sources
# The mirror that serves bookworm's main suite here, as apt's own sources name it (deb822
# .sources files or one-line .list entries); backports comes from the same mirror.
bookworm_mirror() {
  local f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk 'BEGIN { RS = ""; FS = "\n" }
      {
        uri = ""; suite = 0
        for (i = 1; i <= NF; i++) {
          if ($i ~ /^URIs:/) { sub(/^URIs:[ \t]*/, "", $i); split($i, u, /[ \t]+/); uri = u[1] }
          if ($i ~ /^Suites:/ && $i ~ /(^|[ \t])bookworm([ \t]|$)/) suite = 1
        }
        if (uri != "" && suite) { print uri; exit }
      }' "$f"
  done
  { cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null || true; } |
    awk '$1 == "deb" { for (i = 2; i <= NF; i++) if ($i !~ /^\[/) { if ($(i + 1) == "bookworm") print $i; break } }'
}
if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  MIRROR=$(bookworm_mirror | awk 'NR == 1')
  if [ -z "$MIRROR" ]; then
    echo "setup: no apt source names Debian bookworm's main suite; add one (or a bookworm-backports" >&2
    echo "setup: source) to /etc/apt/sources.list.d/ and run this again." >&2
    exit 1
  fi
  $SUDO tee "$BACKPORTS" >/dev/null <<SRC
Types: deb
URIs: $MIRROR
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
fi

export DEBIAN_FRONTEND=noninteractive
# Another apt or dpkg (an unattended upgrade, an install in another shell) may hold apt's locks:
# wait for it, up to FOVEA_APT_LOCK_WAIT seconds (apt prints who holds the lock while it
# waits), rather than fail at once.
# `apt-get install` waits by itself (DPkg::Lock::Timeout); `apt-get update` does not wait for
# the lists lock (apt 2.6), so it is tried again every 5 s while the lock is what failed.
APT_LOCK_WAIT=${FOVEA_APT_LOCK_WAIT:-600}
apt_get() {
  if ! $SUDO apt-get -o DPkg::Lock::Timeout="$APT_LOCK_WAIT" "$@"; then
    echo "setup: apt-get $* failed. If another apt or dpkg still held its lock after" >&2
    echo "setup: ${APT_LOCK_WAIT} s, let it finish (or raise FOVEA_APT_LOCK_WAIT) and run this again." >&2
    return 1
  fi
}
apt_update() {
  local started out
  started=$(date +%s)
  while ! out=$($SUDO apt-get update -q 2>&1); do
    if ! grep -q "Could not get lock" <<<"$out" ||
      [ $(($(date +%s) - started)) -ge "$APT_LOCK_WAIT" ]; then
      echo "$out" >&2
      echo "setup: apt-get update failed (see above). If another apt or dpkg held its lock for" >&2
      echo "setup: ${APT_LOCK_WAIT} s, let it finish (or raise FOVEA_APT_LOCK_WAIT) and run this again." >&2
      return 1
    fi
    echo "setup: another apt or dpkg holds apt's lists lock ($(grep -o 'held by process.*' <<<"$out" | head -1)); waiting"
    sleep 5
  done
  echo "$out"
}
apt_update
# Vulkan from backports: driver (lavapipe), loader, headers, validation layers, tools.
apt_get install -y -q -t bookworm-backports \
  mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers vulkan-tools
# Build tools, glslc (build.rs compiles the shaders with it) and the OpenXR loader (the loader
# is only dlopen'ed at run time).
apt_get install -y -q build-essential pkg-config cmake glslc libopenxr-loader1 libopenxr-dev
# `fovea view`: the X11 and Wayland client libraries winit loads at run time, and Xvfb (a
# virtual X server) with xauth, which the viewer tests open their windows on.
apt_get install -y -q xvfb xauth libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 \
  libxkbcommon0 libxkbcommon-x11-0 libwayland-client0 libwayland-cursor0
# Weston, whose headless backend the Wayland viewer test opens its window on.
apt_get install -y -q weston
# The XR tests: Khronos' hello_xr (libopenxr-utils), run against the simulated headset, and
# the OpenXR core validation layer fovea's session is checked under.
apt_get install -y -q libopenxr-utils openxr-layer-corevalidation
# glTF content as people author it: the Khronos sample models Debian ships (BoxTextured,
# 2CylinderEngine, TextureTransformTest, ...) under /usr/share/assimp/models/glTF2/, which the
# real-content tests render and users can try first.
apt_get install -y -q assimp-testmodels

echo "setup: Vulkan devices:"
vulkaninfo --summary 2>/dev/null | grep -E "deviceName|apiVersion|driverInfo" || true
