#!/usr/bin/env bash
# Fuzzes the glTF loader (fuzz/fuzz_targets/gltf_load.rs) for a bounded time, on one core:
#
#     tools/fuzz.sh [SECONDS]        (default 300)
#
# New interesting inputs go to fuzz/corpus/gltf_load/ (commit them after `cargo fuzz cmin`),
# a crash, hang (> 10 s) or out-of-memory (> 2 GiB) input to fuzz/artifacts/gltf_load/: fix
# the loader, then copy the input to fuzz/regressions/ named after what it triggered, where
# `cargo test --test gltf_fuzz_corpus` replays it on stable Rust. Reproduce one input with
#     tools/fuzz.sh run fuzz/artifacts/gltf_load/crash-...
# and shrink the corpus to the inputs that keep its coverage with
#     tools/fuzz.sh cmin
#
# How this works on the stable toolchain (no nightly to download here):
# - cargo-fuzz needs nightly for `-Zsanitizer=address` (its default) and cargo's `-Z` flags;
#   RUSTC_BOOTSTRAP=1 unlocks both on stable rustc/cargo. (The coverage instrumentation
#   itself, -Cpasses=sancov-module and -Cllvm-args, is stable.)
# - nv-flip's bundled C++ (tinyexr/miniz) trips AddressSanitizer's one-definition-rule check
#   at start-up, a false positive for this target: detect_odr_violation=0.
# - `-O` keeps cargo-fuzz from adding -Cdebug-assertions to every crate; fuzz/Cargo.toml turns
#   debug assertions and overflow checks back on for all crates but obvhs (see the comment
#   there: its debug-only BVH self-check would stop every run on a known, non-loader issue).
# - AddressSanitizer (cargo-fuzz's default) is kept, though the loader is safe Rust: its
#   allocator is what lets -malloc_limit_mb report one huge allocation as it is made.
#   `-s none` would not remove the need for RUSTC_BOOTSTRAP (the cargo -Z flags need it).
# The first build instruments the whole fovea library and its dependencies (about 10 min on
# one core); later runs only rebuild what changed.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
inputs=()
if [[ "${1:-}" == run ]]; then
    for input in "${@:2}"; do inputs+=("$(realpath "$input")"); done
fi
cd "$repo/fuzz"

if ! command -v cargo-fuzz >/dev/null 2>&1; then
    echo "installing cargo-fuzz from crates.io" >&2
    cargo install cargo-fuzz --locked
fi

export RUSTC_BOOTSTRAP=1
export CARGO_BUILD_JOBS=1
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_odr_violation=0"
libfuzzer_flags=(-rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 -max_len=16384 -print_final_stats=1)

if [[ "${1:-}" == cmin ]]; then
    exec cargo fuzz cmin -O gltf_load -- "${libfuzzer_flags[@]}"
fi
if [[ "${1:-}" == run ]]; then
    exec cargo fuzz run -O gltf_load "${inputs[@]}" -- "${libfuzzer_flags[@]}"
fi

seconds=${1:-300}
exec nice cargo fuzz run -O gltf_load -- \
    "${libfuzzer_flags[@]}" -max_total_time="$seconds"
