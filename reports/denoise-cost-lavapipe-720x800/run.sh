#!/usr/bin/env bash
# Where the denoiser's time goes on lavapipe: builds fovea from COMMIT with one variant of
# glsl/denoise.comp at a time (each leaves out or changes one part of the pass; G, H and
# `tile` keep its output, bit for bit) and times the shipped Vive config on bunny-high at
# 720x800 with tools/time-configs.py: turning 0.34 degrees a frame, 8 frames, the median of
# frames 2-7, every binary in turn, twice.   bash run.sh COMMIT OUT [VARIANT...]   (VARIANT: head A B C D E F G H I tile)
set -euo pipefail
commit=$1 out=$2; shift 2
variants=("$@")
[ ${#variants[@]} -gt 0 ] || variants=(head A B C D E F G H I tile)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(git -C "$here" rev-parse --show-toplevel)
mkdir -p "$out"
tree=$(mktemp -d)/tree
git -C "$repo" worktree add -f --detach "$tree" "$commit" >/dev/null
trap 'git -C "$repo" worktree remove --force "$tree"' EXIT
d=glsl/denoise.comp
edit() { python3 - "$tree/$d" "$@" <<'PY'
import sys
path, pairs = sys.argv[1], sys.argv[2:]
s = open(path).read()
for old, new in zip(pairs[::2], pairs[1::2]):
    assert old in s, old
    s = s.replace(old, new, 1)
open(path, "w").write(s)
PY
}
# The albedo unpacked and divided only where the tap's bits (read by LOAD) differ from the centre's.
albedo_skip() {
  edit '    vec3 ap = pc.last != 0u ? albedo : pixel_albedo(p); // the last iteration read it above' \
       '    uint ap_bits = albedo_before[pixel_index(p)].albedo;
    vec3 ap = pc.last != 0u ? albedo : albedo_divisor(ap_bits);' \
       '            vec3 aq = pixel_albedo(q);
            vec3 apart = abs(aq - ap) / max(aq, ap);
            exponent += by_albedo * max(apart.r, max(apart.g, apart.b));' \
       "            uint aq_bits = $1;
            if (aq_bits != ap_bits) {
                vec3 aq = albedo_divisor(aq_bits);
                vec3 apart = abs(aq - ap) / max(aq, ap);
                exponent += by_albedo * max(apart.r, max(apart.g, apart.b));
            }"
}
ALBEDO=('vec3 aq = pixel_albedo(q);' 'vec3 aq = ap;')
NORMAL=('vec3 nq = from_octahedral(unpackSnorm2x16(sq.y));' 'vec3 nq = np;')
EXP=('w *= exp2(exponent);' 'w *= 1.0 + exponent;')
LOADS=('uvec4 sq = read_surface(q);' 'uvec4 sq = sp; sq.x += uint(dx);'
       'vec4 tap = read_input(q);' 'vec4 tap = centre + vec4(float(dx), float(dy), 0, 0) * 0.001;')
for v in "${variants[@]}"; do
  git -C "$tree" checkout -q -- glsl src
  case $v in
    head) ;;
    A) edit "${ALBEDO[@]}" ;;                                   # no albedo load or weight
    B) edit "${NORMAL[@]}" ;;                                   # no normal decode
    C) edit "${ALBEDO[@]}" "${NORMAL[@]}" "${EXP[@]}" ;;         # A + B + no exp2
    D) edit "${ALBEDO[@]}" "${NORMAL[@]}" "${EXP[@]}" "${LOADS[@]}" ;; # C + no tap loads
    E) edit '    const float KERNEL[3]' '    if (sigma >= 0.0) { pass_through(p, centre + vec4(sigma * 1e-9), albedo); return; }
    const float KERNEL[3]' ;;                                  # no tap loop at all
    F) edit 'for (int i = 0; i < 9; ++i) {
        ivec2 o' 'for (int i = 0; i < 1; ++i) {
        ivec2 o' ;;                                           # one variance tap, not 9
    G) edit '#extension GL_GOOGLE_include_directive : require' '#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require' \
            '    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {' '    [[unroll]] for (int dy = -2; dy <= 2; ++dy) {
        [[unroll]] for (int dx = -2; dx <= 2; ++dx) {' ;;    # loops unrolled (same output)
    H) albedo_skip 'albedo_before[pixel_index(q)].albedo' ;;   # albedo unpacked only where its bits differ (same output)
    I) albedo_skip 'pixel_surface(pixel_index(q) + 1u).y' ;;   # H with a texel load in place of the albedo's (wrong output)
    tile) git -C "$tree" apply "$here/tile-denoise.patch" "$here/tile-passes.patch" ;; # shared-memory tiles (same output)
    *) echo "unknown variant $v" >&2; exit 2 ;;
  esac
  (cd "$tree" && CARGO_TARGET_DIR="$repo/target" cargo build --release -q)
  cp "$repo/target/release/fovea" "$out/fovea-$v"
done
git -C "$tree" checkout -q -- glsl src
# Timed as tools/time-configs.py times configs: every binary in turn, the whole set twice.
bins=()
for v in "${variants[@]}"; do bins+=(--bin "$v=$out/fovea-$v"); done
python3 "$repo/tools/time-configs.py" "${bins[@]}" --scene bunny-high \
  --config vive="$repo/assets/foveation/vive-pro-eye.toml" --frames 8 --turn-deg 0.34 \
  --rounds 2 --out "$out/times.csv"
