#!/usr/bin/env bash
# Do two fovea binaries render bit-identical images? Every built-in scene, mono and stereo,
# regular and thesis-foveated, both traversals, the layers view, and temporal sequences
# (thesis and the denoised config) are rendered by each, and their EXRs' pixels (linear f32
# radiance) compared bit for bit. For refactors that must not change what fovea draws.
#
#   tools/same-images.sh OLD_FOVEA NEW_FOVEA [--size WxH] [--keep DIR]
#
# Exit status 0 when every image is identical, 1 when any differs (each named), 2 on usage.
# Pixels are compared, not file bytes (examples/same_pixels.rs): older binaries wrote EXR
# chunks in a nondeterministic order.
set -euo pipefail

usage() {
    echo "usage: $0 OLD_FOVEA NEW_FOVEA [--size WxH] [--keep DIR]" >&2
    exit 2
}
[[ $# -ge 2 ]] || usage
old=$1 new=$2
shift 2
size=48x40 keep=""
while [[ $# -gt 0 ]]; do
    case $1 in
    --size) size=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    *) usage ;;
    esac
done
[[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "--size wants WxH, not '$size'" >&2; exit 2; }
w=${BASH_REMATCH[1]} h=${BASH_REMATCH[2]}
for bin in "$old" "$new"; do
    [[ -x $bin ]] || { echo "'$bin' is not an executable fovea binary" >&2; exit 2; }
done

root=$(dirname "$0")/..
work=${keep:-$(mktemp -d)}
mkdir -p "$work/old" "$work/new"
[[ -n $keep ]] || trap 'rm -rf "$work"' EXIT
# Three frames: a move, a turn and a still frame (the history carried by reprojection).
path=$work/path.csv
printf 'frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n0,0,0,0,0,0,0\n1,0.02,0,0,1,0,0\n2,0.02,0,0,1,0,0\n' >"$path"

scenes=$("$new" scenes | awk 'NR > 1 { print $1 }')
cases=()
for scene in $scenes; do
    for eyes in mono stereo; do
        stereo=(); [[ $eyes == stereo ]] && stereo=(--stereo)
        for traversal in software default; do
            trav=(); [[ $traversal == software ]] && trav=(--traversal software)
            for fov in off thesis; do
                cases+=("$scene-$eyes-$fov-$traversal|--scene $scene ${stereo[*]} ${trav[*]} --foveation $fov")
            done
        done
        cases+=("$scene-$eyes-layers-view|--scene $scene ${stereo[*]} --foveation thesis --debug layers --gaze corner")
        for config in thesis thesis-denoised; do
            file=$config
            [[ $config == thesis-denoised ]] && file=$root/assets/foveation/thesis-denoised.toml
            cases+=("$scene-$eyes-$config-temporal|--scene $scene ${stereo[*]} --foveation $file --camera-path $path --temporal on --fov vive-pro-eye")
        done
    done
done

for case in "${cases[@]}"; do
    name=${case%%|*} args=${case#*|}
    for side in old new; do
        bin=$old; [[ $side == new ]] && bin=$new
        out=$work/$side/$name
        if [[ $args == *--camera-path* ]]; then target=$out; else target=$out.exr; fi
        # shellcheck disable=SC2086 # args is a word list by design
        "$bin" render $args --width "$w" --height "$h" --out "$target" >"$work/$side-$name.log" 2>&1 ||
            { echo "FAILED: $side $name:" >&2; cat "$work/$side-$name.log" >&2; exit 1; }
    done
done
echo "${#cases[@]} cases at ${w}x$h rendered; comparing pixels"
cargo run --quiet --release --manifest-path "$root/Cargo.toml" --example same_pixels -- "$work/old" "$work/new"
