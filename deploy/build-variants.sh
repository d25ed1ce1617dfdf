#!/usr/bin/env bash
# Builds pathlab for newer x86-64 CPUs beside the baseline build: target/release/pathlab-x86-64-v3
# (AVX2, FMA, BMI) and pathlab-x86-64-v4 (AVX-512), each a whole build with -C target-cpu. When
# `pathlab` starts it runs the best of them this CPU can execute in its place
# (crates/cli/src/variant.rs); the baseline runs where none fits.
#
# Each variant this CPU can run is checked first: it must render the same images as the
# baseline, to the bit (EXR files byte for byte); one that differs is not installed, and the
# script fails. One this CPU cannot run is not installed either (it could not be checked).
#
#   bash deploy/build-variants.sh             # beside target/release/pathlab
#   bash deploy/build-variants.sh --install   # also beside the `pathlab` on PATH (after
#                                             # `cargo install --path crates/cli`)
#
# Each variant builds in a target folder of its own (target/variants/LEVEL): the first build
# takes as long as the baseline's, later ones only recompile what changed.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
install=""
[ "${1:-}" = "--install" ] && install=1
if [ "$(uname -m)" != x86_64 ]; then
    echo "build-variants: variants are x86-64 builds; nothing to do on $(uname -m)"
    exit 0
fi
cargo build --release --quiet -p pathlab
base="$root/target/release/pathlab"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Scenes that exercise every kind of code the render runs: triangle lights and the eight-lane
# path tracer, spheres, rough and smooth BSDFs, an environment map, a thin lens, the
# bidirectional path tracer, a pbrt-v4 scene, adaptive sampling and Sobol samples.
checks=(
    "render -s 4"
    "render tests/data/cornell-box/scene.xml -s 4 --sampler independent"
    "render tests/data/cornell-box/scene.xml -s 4 -m 1"
    "render tests/data/cornell-rough/scene.xml -s 4"
    "render tests/data/cornell-spheres/scene.xml -s 4"
    "render tests/data/sky-spheres/scene.xml -s 4"
    "render tests/data/cornell-thinlens/scene.xml -s 4"
    "render tests/data/bitterli/veach-mis/scene-v4.pbrt -s 2 --scale 0.25"
    "render tests/data/cornell-box/scene.xml -s 2 --integrator bdpt"
    "render tests/data/cornell-box/scene.xml -s 64 -a 16 0.2"
)

# `same LEVEL BINARY`: whether BINARY renders every check as the baseline does.
same() {
    local level="$1" binary="$2" k=0 ok=1
    for check in "${checks[@]}"; do
        k=$((k + 1))
        # shellcheck disable=SC2086
        PATHLAB_NO_VARIANT=1 "$base" $check -q -o "$work/base-$k.exr"
        # shellcheck disable=SC2086
        "$binary" $check -q -o "$work/$level-$k.exr"
        if ! cmp -s "$work/base-$k.exr" "$work/$level-$k.exr"; then
            echo "build-variants: $level renders 'pathlab $check' differently from the baseline" >&2
            ok=""
        fi
    done
    [ -n "$ok" ]
}

failed=""
for level in x86-64-v3 x86-64-v4; do
    RUSTFLAGS="-C target-cpu=$level" CARGO_TARGET_DIR="$root/target/variants/$level" \
        cargo build --release --quiet -p pathlab
    built="$root/target/variants/$level/release/pathlab"
    # A variant says its level in `--version`; one this CPU cannot run dies of an illegal
    # instruction instead.
    if ! "$built" --version 2>/dev/null | grep -q "($level)"; then
        echo "build-variants: this CPU cannot run $level code; not installed"
        rm -f "$root/target/release/pathlab-$level"
        continue
    fi
    if ! same "$level" "$built"; then
        rm -f "$root/target/release/pathlab-$level"
        failed=1
        continue
    fi
    # Copied after the baseline was built, so that the variant is the newer file (an older
    # one is taken for a stale build and not run).
    cp "$built" "$root/target/release/pathlab-$level"
    echo "build-variants: $level renders the ${#checks[@]} checks as the baseline does; installed as target/release/pathlab-$level"
    if [ -n "$install" ]; then
        installed="$(command -v pathlab || true)"
        if [ -z "$installed" ]; then
            echo "build-variants: no pathlab on PATH to install beside (cargo install --path crates/cli first)" >&2
            failed=1
        else
            cp "$built" "$(dirname "$installed")/pathlab-$level"
            echo "build-variants: installed beside $installed"
        fi
    fi
done
echo "build-variants: on this CPU \`pathlab\` runs the $("$base" --version | sed 's/.*(\(.*\))/\1/') build"
[ -z "$failed" ]
