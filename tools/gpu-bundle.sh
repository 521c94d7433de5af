#!/usr/bin/env bash
# Builds, on this machine, a self-contained bundle for measuring fovea on a GPU machine that has
# no network (and maybe no Vulkan loader, no display):
#
#     dist/fovea-gpu/
#       fovea                  the stripped release binary (`fovea gpu-report` makes the report)
#       libsim_headset.so      the simulated headset as an OpenXR runtime, with manifest.json
#                              (fovea's own sessions use the copy linked into fovea)
#       run-report.sh          run-report.sh [--quick] [--size WxH] OUT_DIR
#       debs/libvulkan1_*.deb  Debian's Vulkan loader, for a machine without one
#       loader/                the same loader unpacked (run-report.sh uses it when needed)
#
# Carry dist/fovea-gpu to the GPU machine and run `fovea-gpu/run-report.sh OUT_DIR` there
# (README, "Measured on a GPU"). Run after tools/setup.sh.
#
#   tools/gpu-bundle.sh [--out DIR] [--prebuilt DIR]
#     --out DIR        the bundle's folder (default dist/fovea-gpu)
#     --prebuilt DIR   take fovea and libsim_headset.so from DIR instead of building them
#                      (the tests pack their own build this way)
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
out="$repo/dist/fovea-gpu"
prebuilt=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --prebuilt) prebuilt=$2; shift 2 ;;
    *) echo "gpu-bundle: unknown argument '$1'; use [--out DIR] [--prebuilt DIR]" >&2; exit 2 ;;
  esac
done

if [ -z "$prebuilt" ]; then
  (cd "$repo" && cargo build --release -p fovea -p sim-headset)
  prebuilt="$repo/target/release"
fi
for f in fovea libsim_headset.so; do
  if [ ! -f "$prebuilt/$f" ]; then
    echo "gpu-bundle: $prebuilt/$f is missing: build it (cargo build --release -p fovea -p sim-headset)" >&2
    exit 1
  fi
done

rm -rf "$out"
mkdir -p "$out/debs" "$out/loader"
install -m 755 "$prebuilt/fovea" "$out/fovea"
install -m 755 "$prebuilt/libsim_headset.so" "$out/libsim_headset.so"
strip "$out/fovea" "$out/libsim_headset.so"
cat >"$out/manifest.json" <<'JSON'
{
    "file_format_version": "1.0.0",
    "runtime": {
        "name": "fovea simulated headset",
        "library_path": "./libsim_headset.so"
    }
}
JSON
install -m 755 "$repo/tools/gpu/run-report.sh" "$out/run-report.sh"

# The Vulkan loader: Debian's package if apt can fetch it, else the files of the one installed
# here (tools/setup.sh installs libvulkan1); unpacked into loader/ either way.
if (cd "$out/debs" && apt-get download -q libvulkan1 >/dev/null 2>&1); then
  dpkg-deb -x "$out"/debs/libvulkan1_*.deb "$out/loader"
  echo "gpu-bundle: Vulkan loader from $(basename "$out"/debs/libvulkan1_*.deb)"
else
  libdir=/usr/lib/x86_64-linux-gnu
  if ! ls "$libdir"/libvulkan.so.1* >/dev/null 2>&1; then
    echo "gpu-bundle: could not download libvulkan1 and none is installed here: run tools/setup.sh" >&2
    exit 1
  fi
  mkdir -p "$out/loader$libdir"
  cp -a "$libdir"/libvulkan.so.1* "$out/loader$libdir/"
  echo "gpu-bundle: apt could not download libvulkan1; packed this machine's loader instead"
fi

size=$(du -sb "$out" | cut -f1)
echo "gpu-bundle: wrote $out ($((size / 1024 / 1024)) MiB); on the GPU machine run: $(basename "$out")/run-report.sh OUT_DIR"
