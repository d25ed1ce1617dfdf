#!/usr/bin/env bash
# Samples per second of `pathlab render` on the built-in Cornell box, at -m inf and -m 1.
# A benchmark, not a test: run it on an otherwise idle machine and compare numbers taken in one
# run. Usage: bench/render.sh [SPP] [THREADS]   (defaults: 64 spp, all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
spp="${1:-64}"
threads="${2:-0}"
cargo build --release --quiet
out="$(mktemp -d)"
printf '%-8s %10s %14s %14s %8s\n' depth seconds samples/s rays/s threads
for depth in inf 1; do
    json="$(target/release/pathlab render -s "$spp" -m "$depth" -t "$threads" -q --json -o "$out/cornell-$depth.exr")"
    python3 - "$depth" <<PY "$json"
import json, sys
d = json.loads(sys.argv[2])
print(f"{sys.argv[1]:<8} {d['seconds']:10.2f} {d['samples_per_second']:14.3e} {d['rays_per_second']:14.3e} {d['threads']:8d}")
PY
done
rm -rf "$out"
