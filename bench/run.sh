#!/usr/bin/env bash
# pathlab against Embree (BVH build and ray throughput on the same rays) and Mitsuba 3 (render
# speed and equal-time error on the Cornell box), and the Python module against the command line,
# as ratios measured in one run on one machine.
# A benchmark, not a test. Needs the project's shared tools (../shared, or PATHLAB_SHARED),
# network access to Debian's packages and PyPI the first time, and root (or sudo) for apt.
#
#   bench/run.sh            # everything
#   bench/run.sh rays       # Embree only
#   bench/run.sh render     # Mitsuba, the Cornell box in detail
#   bench/run.sh scenes     # Mitsuba, every reference scene (speed and equal-time error)
#   bench/run.sh suite      # Mitsuba, the scenes of Mitsuba's own test suite (the same)
#   bench/run.sh pbrt       # Mitsuba, Bitterli's pbrt-v4 scenes written as Mitsuba XML (the same)
#   bench/run.sh python     # the Python module against the command line, same render
#
# Results go to target/bench/ (JSON per measurement) and a table on stdout. The renders run
# `pathlab` with the build for this CPU (deploy/build-variants.sh makes it first);
# PATHLAB_BENCH_BASELINE=1 runs the baseline build.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="${PATHLAB_SHARED:-$root/../shared}"
work="$root/target/bench"
what="${1:-all}"
mkdir -p "$work"
cd "$root"
# The obvhs feature adds that crate's BVH as a second baseline to `pathlab-bench rays`.
cargo build --release --quiet -p pathlab -p pathlab-bench --features pathlab-bench/obvhs
pathlab="$root/target/release/pathlab"
bench="$root/target/release/pathlab-bench"
# `pathlab` as its users run it: with the build for this CPU beside it (deploy/build-variants.sh,
# which checks that it renders what the baseline renders). PATHLAB_BENCH_BASELINE=1 measures
# the baseline build instead.
if [ -n "${PATHLAB_BENCH_BASELINE:-}" ]; then
    export PATHLAB_NO_VARIANT=1
elif [ "$what" != rays ]; then
    bash "$root/deploy/build-variants.sh"
fi

apt_install() {
    local sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get install -y "$@" >/dev/null
}

if [ "$what" = all ] || [ "$what" = rays ]; then
    [ -e /usr/include/embree3/rtcore.h ] || apt_install libembree-dev
    cc -O3 -o "$work/embree_bench" "$shared/tools/embree-bench/embree_bench.c" -lembree3 -lpthread -lm
    cc -O2 -o "$work/embree_memory" "$root/bench/embree_memory.c" -lembree3
    meshes=()
    for spec in "blob 200000" "blob 1000000" "soup 100000"; do
        set -- $spec
        name="$1$(( $2 / 1000 ))k"
        [ -e "$work/$name.obj" ] || python3 "$shared/tools/meshgen.py" "$1" "$2" "$work/$name.obj" >/dev/null
        meshes+=("$name")
    done
    for scene in maxplanck CBbunny; do
        [ -e "$work/$scene.obj" ] || "$bench" obj "$root/tests/data/cs184/$scene.dae" "$work/$scene.obj" >/dev/null
        meshes+=("$scene")
    done
    # `pathlab-bench` built as `pathlab` runs on this CPU (the AVX-512 or AVX2 build that
    # deploy/build-variants.sh makes; Embree picks its AVX-512 or AVX2 kernels at run time
    # too), unless PATHLAB_BENCH_BASELINE is set.
    if [ -z "${PATHLAB_BENCH_BASELINE:-}" ] && [ "$(uname -m)" = x86_64 ]; then
        host="$(rustc -vV | sed -n 's/^host: //p')"
        # shellcheck source=deploy/x86-levels.sh
        source "$root/deploy/x86-levels.sh"
        for level in x86-64-v4 x86-64-v3; do
            [ -z "$(x86_level_missing "$level")" ] || continue
            RUSTFLAGS="-C target-cpu=$level" CARGO_TARGET_DIR="$root/target/variants/$level" \
                cargo build --profile dist --quiet -p pathlab-bench --features obvhs --target "$host"
            bench="$root/target/variants/$level/$host/dist/pathlab-bench"
            break
        done
    fi
    echo "rays: $bench"
    threads="$(nproc)"
    # Embree and pathlab take turns, PATHLAB_BENCH_REPS times (default 3) per mesh; the table
    # takes each rate's median, so that one disturbed run moves no ratio.
    reps="${PATHLAB_BENCH_REPS:-3}"
    for m in "${meshes[@]}"; do
        # Embree's bytes per triangle (its memory monitor), once: the build's memory does
        # not vary by more than its allocator's blocks.
        "$work/embree_memory" "$work/$m.obj" > "$work/$m.embree_memory.txt"
        for rep in $(seq "$reps"); do
            "$work/embree_bench" "$work/$m.obj" "$threads" "$work/$m.rays" > "$work/$m.embree.$rep.txt"
            "$bench" rays "$work/$m.obj" "$work/$m.rays" --repeat 5 --json > "$work/$m.pathlab.$rep.json"
        done
    done
    python3 "$root/bench/rays_table.py" "$work" "$reps" "${meshes[@]}"
fi

mitsuba_venv() {
    venv="$work/venv"
    [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
    "$venv/bin/python" -c "import mitsuba, numpy" 2>/dev/null || "$venv/bin/pip" install --quiet mitsuba numpy
    llvm="$(ls /usr/lib/x86_64-linux-gnu/libLLVM-19.so 2>/dev/null || true)"
    if [ -z "$llvm" ]; then
        apt_install libllvm19 || true
        llvm="$(ls /usr/lib/x86_64-linux-gnu/libLLVM-19.so 2>/dev/null || true)"
    fi
}

if [ "$what" = all ] || [ "$what" = render ]; then
    mitsuba_venv
    DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" "$root/bench/mitsuba_bench.py" \
        --pathlab "$pathlab" --scene "$root/tests/data/cornell-box/scene.xml" \
        --reference "$root/tests/data/cornell-box/mean-maxdepth-inf.exr" \
        --work "$work"
fi

if [ "$what" = all ] || [ "$what" = scenes ]; then
    mitsuba_venv
    DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" "$root/bench/scenes.py" \
        --pathlab "$pathlab" --data "$root/tests/data" --work "$work" \
        --spp "${PATHLAB_BENCH_SPP:-256}" --reps "${PATHLAB_BENCH_REPS:-3}"
fi

if [ "$what" = all ] || [ "$what" = suite ]; then
    mitsuba_venv
    DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" "$root/bench/suite.py" \
        --pathlab "$pathlab" --suite "$root/tests/data/mitsuba-suite/tests/scenes" \
        --work "$work/suite" --spp "${PATHLAB_BENCH_SUITE_SPP:-1024}" \
        --reps "${PATHLAB_BENCH_REPS:-3}"
fi

if [ "$what" = all ] || [ "$what" = pbrt ]; then
    mitsuba_venv
    DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" "$root/bench/pbrt_scenes.py" \
        --pathlab "$pathlab" --data "$root/tests/data" --work "$work/pbrt" \
        --spp "${PATHLAB_BENCH_SPP:-256}" --reps "${PATHLAB_BENCH_REPS:-3}"
fi

if [ "$what" = all ] || [ "$what" = python ]; then
    pyvenv="$work/pyvenv"
    [ -x "$pyvenv/bin/python" ] || python3 -m venv "$pyvenv"
    "$pyvenv/bin/pip" install --quiet maturin numpy
    rm -rf "$work/wheels"
    "$pyvenv/bin/maturin" build --quiet --release -m "$root/crates/python/Cargo.toml" -o "$work/wheels"
    "$pyvenv/bin/pip" install --quiet --force-reinstall --no-deps "$work"/wheels/pathlab-*.whl
    # The module is one build for every CPU: the command line's baseline build is its peer.
    PATHLAB_NO_VARIANT=1 "$pyvenv/bin/python" "$root/bench/python_vs_cli.py" "$pathlab" --reps "${PATHLAB_BENCH_REPS:-9}"
fi
