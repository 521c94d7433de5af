#!/usr/bin/env bash
# Runs the Windows archive that tools/build-windows.sh wrote under Debian's Wine, whose Vulkan
# (winevulkan, through Wine's X11 driver: hence Xvfb) reaches the host's lavapipe:
#
#   1. fovea.exe --version
#   2. fovea.exe render of cornell at 64x64 with a fixed seed, whose EXR must equal the Linux
#      build's for the same arguments bit for bit (same SPIR-V, same driver)
#   3. a 10-frame fovea.exe xr session on sim_headset.dll through openxr_loader.dll, the
#      archive's manifest registered as the active runtime, which must exit cleanly and
#      leave complete session files
#   4. fovea.exe xr --probe on the same runtime, which must see its eye gaze delivered
#
# from the unpacked archive, without the validation layer (there is no Windows build of it
# here; the Linux test suite runs the same code under it). For Wine only, a stand-in bcryptprimitives.dll (tools/windows/) goes beside the
# exe: Wine 8.0 lacks ProcessPrng, which Rust's standard library imports. It is never shipped.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$repo"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
for p in wine wine64 xvfb xauth unzip; do
  if ! dpkg -s "$p" >/dev/null 2>&1; then
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q wine wine64 xvfb xauth unzip
    break
  fi
done

archive=$(ls dist/fovea-*-windows-x86_64.zip 2>/dev/null | head -n 1)
if [ -z "$archive" ]; then
  echo "wine-check: no dist/fovea-*-windows-x86_64.zip: run tools/build-windows.sh first" >&2
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unzip -q "$archive" -d "$work"
app=$(ls -d "$work"/fovea-*-windows-x86_64)
x86_64-w64-mingw32-gcc-posix -shared -O2 -o "$app/bcryptprimitives.dll" \
  tools/windows/bcryptprimitives.c tools/windows/bcryptprimitives.def -ladvapi32

unset FOVEA_VALIDATION
export WINEPREFIX="$work/prefix" WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
started=$(date +%s)
# One X server for every Wine process of the run (wineserver outlives each command).
wine_in_x() { xvfb-run -a -s "-screen 0 640x480x24" sh -c 'wine "$@"; status=$?; wineserver -w; exit $status' wine "$@"; }
wine_in_x wineboot --init >/dev/null 2>&1 || true

fail() { echo "wine-check: FAILED: $*" >&2; exit 1; }
step() { echo "wine-check: $*"; }

# 1. --version
out=$(cd "$app" && wine_in_x ./fovea.exe --version 2>&1) || fail "fovea.exe --version: $out"
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n 1)
[[ "$out" == *"fovea $version"* ]] || fail "fovea.exe --version printed: $out"
step "fovea.exe --version: $out"

# 2. The same frame on Linux and under Wine.
render_args=(render --scene cornell --width 64 --height 64 --spp 4 --seed 7)
cargo build -q --bin fovea
linux_started=$(date +%s%N)
target/debug/fovea "${render_args[@]}" --out "$work/linux.png" >"$work/linux.log" 2>&1 ||
  fail "Linux render: $(cat "$work/linux.log")"
linux_ms=$((($(date +%s%N) - linux_started) / 1000000))
wine_started=$(date +%s%N)
(cd "$app" && wine_in_x ./fovea.exe "${render_args[@]}" --out windows.png) \
  >"$work/windows.log" 2>&1 || fail "fovea.exe render: $(cat "$work/windows.log")"
wine_ms=$((($(date +%s%N) - wine_started) / 1000000))
grep -q "llvmpipe" "$work/windows.log" || fail "fovea.exe did not render on lavapipe: $(cat "$work/windows.log")"
cmp -s "$work/linux.exr" "$app/windows.exr" ||
  fail "the EXR fovea.exe wrote differs from the Linux build's for: ${render_args[*]}"
gpu_ms() { sed -n 's/.*: \([0-9.]*\) ms GPU.*/\1/p' "$1" | head -n 1; }
step "fovea.exe render: EXR bit-identical to Linux's (${render_args[*]}); GPU time Linux $(gpu_ms "$work/linux.log") ms, Wine $(gpu_ms "$work/windows.log") ms; wall time (process start to exit) Linux ${linux_ms} ms, Wine ${wine_ms} ms"

# 3. A 10-frame session on the simulated headset through the OpenXR loader. Wine runs every
# program as an administrator, and the loader ignores XR_RUNTIME_JSON in an elevated process,
# so the manifest is made the active runtime the way a runtime's installer does (SteamVR's
# too): HKLM\SOFTWARE\Khronos\OpenXR\1, ActiveRuntime.
manifest=$(wine_in_x winepath -w "$app/sim-headset.json" 2>/dev/null | tr -d '\r')
wine_in_x reg add 'HKLM\SOFTWARE\Khronos\OpenXR\1' /v ActiveRuntime /t REG_SZ /d "$manifest" /f \
  >/dev/null 2>&1 || fail "could not register the simulated headset as the active OpenXR runtime"
(cd "$app" && XR_RUNTIME_JSON="$manifest" \
  wine_in_x ./fovea.exe xr --frames 10 --size 64x64 --session session) >"$work/xr.log" 2>&1 ||
  fail "fovea.exe xr: $(cat "$work/xr.log")"
rows=$(($(wc -l <"$app/session/frames.csv") - 1))
[ "$rows" -eq 20 ] || fail "session/frames.csv has $rows rows, not 10 frames x 2 eyes: $(cat "$work/xr.log")"
grep -q '"frames"' "$app/session/session.json" || fail "session/session.json is incomplete"
grep -q "fovea simulated headset" "$app/session/session.json" ||
  fail "the session did not run on the simulated headset: $(cat "$app/session/session.json")"
step "fovea.exe xr: 10 frames on sim_headset.dll through openxr_loader.dll, session files complete"
grep -E "^OpenXR runtime" "$work/xr.log" || true
# 4. The probe a headset user runs first, on the same runtime.
(cd "$app" && wine_in_x ./fovea.exe xr --probe) >"$work/probe.log" 2>&1 ||
  fail "fovea.exe xr --probe: $(cat "$work/probe.log")"
grep -q "eye gaze:          delivered" "$work/probe.log" ||
  fail "fovea.exe xr --probe did not see the simulated eye gaze: $(cat "$work/probe.log")"
step "fovea.exe xr --probe: $(grep -E '^eye gaze:' "$work/probe.log")"
echo "wine-check: all passed in $(($(date +%s) - started)) s"
