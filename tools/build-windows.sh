#!/usr/bin/env bash
# Cross-builds fovea for Windows (x86_64-pc-windows-gnu, mingw-w64) on Debian and writes
#
#     dist/fovea-<version>-windows-x86_64.zip
#
# with fovea.exe, the OpenXR loader (openxr_loader.dll, built from the sources the openxr-sys
# crate vendors), the simulated headset (sim_headset.dll + sim-headset.json, its runtime
# manifest, library path relative to the manifest), the mingw runtime DLLs fovea.exe imports,
# the assets and README-windows.txt. The Vulkan loader is Windows' own (vulkan-1.dll comes
# with every GPU driver). Shaders are compiled on this host by glslc, as for Linux.
#
# Run after tools/setup.sh (as root or with sudo); it installs what it needs itself: Debian's
# mingw-w64 gcc/g++ with posix threads (Rust's standard library and nv-flip's C++ need them),
# cmake and zip, and the x86_64-pc-windows-gnu target of the Rust toolchain.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$repo"
TARGET=x86_64-pc-windows-gnu
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

need_packages=()
for p in gcc-mingw-w64-x86-64-posix g++-mingw-w64-x86-64-posix cmake zip; do
  dpkg -s "$p" >/dev/null 2>&1 || need_packages+=("$p")
done
if [ ${#need_packages[@]} -gt 0 ]; then
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${need_packages[@]}"
fi
if ! rustc --print target-libdir --target "$TARGET" >/dev/null 2>&1 ||
   [ ! -d "$(rustc --print target-libdir --target "$TARGET")" ]; then
  if ! command -v rustup >/dev/null 2>&1; then
    echo "build-windows: the Rust toolchain has no $TARGET standard library and there is no" >&2
    echo "build-windows: rustup to add it: install Rust with rustup, then run this again." >&2
    exit 1
  fi
  rustup target add "$TARGET"
fi

# The C and C++ of dependencies (nv-flip's FLIP, the OpenXR loader) with the same compilers.
export CC_x86_64_pc_windows_gnu=x86_64-w64-mingw32-gcc-posix
export CXX_x86_64_pc_windows_gnu=x86_64-w64-mingw32-g++-posix
export AR_x86_64_pc_windows_gnu=x86_64-w64-mingw32-ar
# The archive carries no debug information (the Linux release build keeps its line tables).
export CARGO_PROFILE_RELEASE_DEBUG=0
started=$(date +%s)
cargo build --release --target "$TARGET" -p fovea -p sim-headset --bin fovea --lib
out="target/$TARGET/release"

# The OpenXR loader as a DLL, from the SDK sources openxr-sys ships (fovea loads it at run
# time, like libopenxr_loader.so on Linux). mingw's winapifamily.h lacks
# WINAPI_PARTITION_SYSTEM, which the loader tests together with the desktop partition.
sdk=$(cargo metadata --format-version 1 --filter-platform "$TARGET" |
  sed -n 's/.*"manifest_path":"\([^"]*openxr-sys-[^"]*\)\/Cargo.toml".*/\1/p' | head -n 1)/OpenXR-SDK
loader_build="target/$TARGET/openxr-loader"
if [ ! -f "$loader_build/src/loader/libopenxr_loader.dll" ]; then
  if [ ! -f "$sdk/CMakeLists.txt" ]; then
    echo "build-windows: the OpenXR SDK sources were not found under the openxr-sys crate ($sdk)" >&2
    exit 1
  fi
  cmake -S "$sdk" -B "$loader_build" -DCMAKE_SYSTEM_NAME=Windows \
    -DCMAKE_C_COMPILER=x86_64-w64-mingw32-gcc-posix \
    -DCMAKE_CXX_COMPILER=x86_64-w64-mingw32-g++-posix \
    -DCMAKE_RC_COMPILER=x86_64-w64-mingw32-windres \
    -DCMAKE_BUILD_TYPE=Release -DDYNAMIC_LOADER=ON -DBUILD_API_LAYERS=OFF -DBUILD_TESTS=OFF \
    -DBUILD_CONFORMANCE_TESTS=OFF -DBUILD_WITH_SYSTEM_JSONCPP=OFF \
    -DCMAKE_C_FLAGS=-DWINAPI_PARTITION_SYSTEM=0 -DCMAKE_CXX_FLAGS=-DWINAPI_PARTITION_SYSTEM=0 \
    -DCMAKE_SHARED_LINKER_FLAGS="-static-libgcc -static-libstdc++ -static" >/dev/null
  cmake --build "$loader_build" --target openxr_loader -j "$(nproc)" >/dev/null
fi

version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n 1)
name="fovea-$version-windows-x86_64"
stage="dist/$name"
rm -rf "$stage" "dist/$name.zip"
mkdir -p "$stage"
cp "$out/fovea.exe" "$out/sim_headset.dll" "$stage/"
cp "$loader_build/src/loader/libopenxr_loader.dll" "$stage/openxr_loader.dll"
cat >"$stage/sim-headset.json" <<'JSON'
{
    "file_format_version": "1.0.0",
    "runtime": {
        "name": "fovea simulated headset",
        "library_path": "sim_headset.dll"
    }
}
JSON
cp -r assets "$stage/assets"
cp tools/windows/README-windows.txt "$stage/"
# The mingw runtime DLLs the binaries import (Windows has none of them): each one found by
# the cross-compiler, and again for what those import in turn.
mingw_dll() { x86_64-w64-mingw32-g++-posix -print-file-name="$1"; }
imports() { x86_64-w64-mingw32-objdump -p "$1" | sed -n 's/.*DLL Name: \(lib[^ ]*\.dll\)/\1/p'; }
pending=("$stage/fovea.exe" "$stage/sim_headset.dll" "$stage/openxr_loader.dll")
while [ ${#pending[@]} -gt 0 ]; do
  binary=${pending[0]}
  pending=("${pending[@]:1}")
  for dll in $(imports "$binary"); do
    [ -f "$stage/$dll" ] && continue
    found=$(mingw_dll "$dll")
    if [ "$found" = "$dll" ] || [ ! -f "$found" ]; then
      # Not a mingw DLL that the compiler knows: the posix thread library sits beside it.
      found=$(find /usr/x86_64-w64-mingw32 /usr/lib/gcc/x86_64-w64-mingw32 -name "$dll" -path '*posix*' -o -name "$dll" -path '*/lib/*' 2>/dev/null | head -n 1)
    fi
    if [ -z "$found" ] || [ ! -f "$found" ]; then
      echo "build-windows: $binary imports $dll, which no mingw-w64 package here provides" >&2
      exit 1
    fi
    cp "$found" "$stage/"
    pending+=("$stage/$dll")
  done
done
# Symbols are for debuggers this archive does not ship (the mingw runtime alone carries 20 MB).
x86_64-w64-mingw32-strip --strip-unneeded "$stage"/*.exe "$stage"/*.dll
(cd dist && zip -q -r "$name.zip" "$name")
elapsed=$(($(date +%s) - started))
echo "build-windows: wrote dist/$name.zip ($(du -h "dist/$name.zip" | cut -f1)) in ${elapsed} s"
