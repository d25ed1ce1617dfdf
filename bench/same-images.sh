#!/usr/bin/env bash
# Renders the same images with two pathlab binaries and says, per case, whether they are the
# same to the bit (every EXR channel: mean, variance, sample count). A check for changes that
# must not change images (refactoring); not a test. Needs python3 with numpy and OpenEXR.
#
#   bench/same-images.sh OLD/pathlab NEW/pathlab
set -euo pipefail
old="$1"; new="$2"
root="$(cd "$(dirname "$0")/.." && pwd)"
data="$root/tests/data"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cases=(
    "default|-r 96 96 -s 32"
    "independent|-r 96 96 -s 32 --sampler independent"
    "direct-hemisphere|-r 96 96 -s 16 --integrator direct --direct hemisphere"
    "path-bsdf-only|-r 64 64 -s 16 --lighting bsdf"
    "adaptive-two-stage|-r 64 64 -a -s 256"
    "adaptive-course|-r 64 64 -a -s 256 --adaptive-rule course"
    "adaptive-neyman|-r 64 64 -a -s 256 --adaptive-rule neyman"
    "target-error|-r 64 64 --target-error 0.03"
    "crop|-r 96 96 -s 16 --crop 10 10 50 40"
    "mitsuba-spheres|$data/cornell-spheres/scene.xml -r 64 64 -s 16"
    "mitsuba-sky|$data/sky-spheres/scene.xml -r 64 64 -s 16"
    "mitsuba-roughplastic|$data/mitsuba-suite/tests/scenes/bsdf_spheres/test_roughplastic_nonlinear_path.xml -r 48 48 -s 8"
    "mitsuba-principled|$data/mitsuba-suite/tests/scenes/bsdf_spheres/test_texturedprincipled1_path.xml -r 48 48 -s 8"
    "mitsuba-bumpmap|$data/mitsuba-suite/tests/scenes/bsdf_spheres/test_bumpmap_path.xml -r 48 48 -s 8"
    "pbrt-cornell|$data/bitterli/cornell-box/scene-v4.pbrt -r 64 64 -s 16"
    "bvh-view|-r 64 64 -s 1 --integrator bvh"
    "shards|-r 64 64 -s 16"
)
same=0; total=0
for c in "${cases[@]}"; do
    name="${c%%|*}"; flags="${c#*|}"
    for bin in old new; do
        exe="$old"; [ "$bin" = new ] && exe="$new"
        if [ "$name" = shards ]; then
            # Four shards merged (the merge is the image).
            parts=()
            for i in 0 1 2 3; do
                # shellcheck disable=SC2086
                "$exe" render $flags --shard "$i/4" -q -o "$out/$name.$bin.$i.plf"
                parts+=("$out/$name.$bin.$i.plf")
            done
            "$exe" merge "$out/$name.$bin.exr" "${parts[@]}" >/dev/null 2>&1
        else
            # shellcheck disable=SC2086
            "$exe" render $flags --aov variance,samples -q -o "$out/$name.$bin.exr"
        fi
    done
    result="$(python3 - "$out/$name.old.exr" "$out/$name.new.exr" <<'PY'
import sys, OpenEXR, numpy as np
def channels(path):
    return {k: np.asarray(v.pixels).tobytes() for k, v in OpenEXR.File(path).channels().items()}
a, b = channels(sys.argv[1]), channels(sys.argv[2])
print("identical" if a == b else "DIFFERENT")
PY
)"
    total=$((total + 1)); [ "$result" = identical ] && same=$((same + 1))
    echo "$name: $result"
done
echo "$same of $total cases identical"
