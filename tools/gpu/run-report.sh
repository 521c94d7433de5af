#!/bin/sh
# fovea's GPU report from this bundle (tools/gpu-bundle.sh made it): is fovea real-time here?
#
#   run-report.sh [--quick] [--size WxH] [--scenes A,B] [--bundled-loader] OUT_DIR
#
# OUT_DIR gets frames.csv, passes.csv, spp.csv, spp-probes.csv, sessions.csv, report.json and
# report.md (`fovea gpu-report --help` says what each holds). Nothing comes from the network.
#
# The Vulkan loader (libvulkan.so.1): the system's when it has one, else this bundle's
# loader/ folder, else the Debian package in debs/, unpacked into loader/. To put one there by
# hand: on a Debian or Ubuntu machine with network, `apt-get download libvulkan1` in debs/.
# --bundled-loader uses the bundle's even where the system has one.
# The driver: the system's Vulkan driver files (ICDs); where there are none, NVIDIA's under
# /usr/local/nvidia (as on headless NVIDIA containers). VK_DRIVER_FILES still wins.
# fovea itself needs an x86-64 Linux with glibc 2.35 or newer and libstdc++ (Debian 12,
# Ubuntu 22.04 and later).
set -eu
here=$(cd "$(dirname "$0")" && pwd)

bundled=no
args=""
for a in "$@"; do
  if [ "$a" = "--bundled-loader" ]; then bundled=yes; else args="$args
$a"; fi
done

# Whether any of the paths (globs expanded) exists.
any_exists() {
  for f in "$@"; do
    if [ -e "$f" ]; then return 0; fi
  done
  return 1
}

has_system_loader() {
  ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1 ' ||
    any_exists /usr/lib/x86_64-linux-gnu/libvulkan.so.1 /usr/lib64/libvulkan.so.1 /usr/lib/libvulkan.so.1
}

if [ "$bundled" = yes ] || ! has_system_loader; then
  libdir="$here/loader/usr/lib/x86_64-linux-gnu"
  if [ ! -e "$libdir/libvulkan.so.1" ]; then
    deb=$(ls "$here"/debs/libvulkan1_*.deb 2>/dev/null | head -n 1 || true)
    if [ -z "$deb" ]; then
      echo "run-report: this machine has no Vulkan loader (libvulkan.so.1) and the bundle has none" >&2
      echo "run-report: in $here/loader or $here/debs. On a Debian or Ubuntu machine with network," >&2
      echo "run-report: run 'apt-get download libvulkan1' in $here/debs (tools/gpu-bundle.sh does)." >&2
      exit 1
    fi
    mkdir -p "$here/loader"
    if command -v dpkg-deb >/dev/null 2>&1; then
      dpkg-deb -x "$deb" "$here/loader"
    else
      (cd "$here/loader" && ar p "$deb" data.tar.xz | tar -xJ)
    fi
  fi
  LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  export LD_LIBRARY_PATH
  echo "run-report: Vulkan loader from the bundle ($libdir)"
fi

if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] &&
  ! any_exists /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json; then
  nvidia=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  if [ -f "$nvidia" ]; then
    VK_DRIVER_FILES=$nvidia
    export VK_DRIVER_FILES
    echo "run-report: Vulkan driver $nvidia"
  else
    echo "run-report: found no Vulkan driver file (ICD json) in /usr/share/vulkan/icd.d," >&2
    echo "run-report: /etc/vulkan/icd.d or $nvidia: install the GPU's Vulkan driver, or set" >&2
    echo "run-report: VK_DRIVER_FILES to its json" >&2
    exit 1
  fi
fi

# Word splitting on newlines only: arguments keep their spaces.
IFS='
'
# shellcheck disable=SC2086
exec "$here/fovea" gpu-report $args
