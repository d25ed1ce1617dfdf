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
#   bash deploy/build-variants.sh --install   # and install pathlab and its variants into the
#                                             # folder of the `pathlab` on PATH (else
#                                             # ~/.cargo/bin), all three of this checkout
#
# Each variant builds in a target folder of its own (target/variants/LEVEL), with the `dist`
# profile (Cargo.toml: the whole program optimised as one unit): the first build takes about
# three times as long as the baseline's, later ones recompile what changed and link again.
# A level whose extensions this CPU lacks (as /proc/cpuinfo lists them) is not built.
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
into=""
if [ -n "$install" ]; then
    installed="$(command -v pathlab || true)"
    into="$(dirname "${installed:-$HOME/.cargo/bin/pathlab}")"
    mkdir -p "$into"
    # The baseline first, so that the variants copied after it are the newer files, and all
    # three come from this checkout.
    if [ "$(realpath "$base")" != "$(realpath "$into/pathlab" 2>/dev/null || true)" ]; then
        cp "$base" "$into/pathlab"
    fi
    echo "build-variants: installed pathlab into $into"
fi
# With an explicit --target, RUSTFLAGS reach only the build's own code, not the build scripts
# that run on this CPU during the build (a v4 build script dies on a CPU without AVX-512).
host="$(rustc -vV | sed -n 's/^host: //p')"
# The extensions whose absence rules a level out at once, before a build that could not be
# checked (the variant's own test of its level, `--version` below, is the one that counts).
# shellcheck source=deploy/x86-levels.sh
source "$root/deploy/x86-levels.sh"
for level in x86-64-v3 x86-64-v4; do
    missing="$(x86_level_missing "$level")"
    if [ -n "$missing" ]; then
        echo "build-variants: this CPU lacks$missing: $level not built"
        rm -f "$root/target/release/pathlab-$level"
        continue
    fi
    # The `dist` profile: the release build optimised as one unit (Cargo.toml).
    RUSTFLAGS="-C target-cpu=$level" CARGO_TARGET_DIR="$root/target/variants/$level" \
        cargo build --profile dist --quiet -p pathlab --target "$host"
    built="$root/target/variants/$level/$host/dist/pathlab"
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
    if [ -n "$into" ]; then
        cp "$built" "$into/pathlab-$level"
        echo "build-variants: installed pathlab-$level into $into"
    fi
done
echo "build-variants: on this CPU \`pathlab\` runs the $("$base" --version | sed 's/.*(\(.*\))/\1/') build"
[ -z "$failed" ]
