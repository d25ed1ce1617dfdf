"""The Python module against the command line on the same render: samples per second of
`pathlab.render` and of `pathlab render`, in turns, medians of the repetitions. A benchmark,
not a test.

    python bench/python_vs_cli.py PATHLAB_BINARY [--scene cornell-box] [--spp 256] [--reps 9]

Run it with the Python that has the `pathlab` wheel installed (`bash bench/run.sh python` builds
one into target/bench/pyvenv). Both sides time the render loop only: the command line's JSON
`seconds`, and `pathlab.render` on a scene already built (its first render), including the
copy-free hand-over of the image to numpy.
"""

import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import pathlab
from machine import cpu_line


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--scene", default="cornell-box")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--reps", type=int, default=9)
    args = ap.parse_args()
    scene = pathlab.load(args.scene)
    w, h = scene.resolution
    samples = w * h * args.spp
    pathlab.render(scene, spp=1)  # builds the scene once
    py_rates, cli_rates = [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "image.exr")
        for _ in range(args.reps):
            start = time.perf_counter()
            pathlab.render(scene, spp=args.spp, seed=0)
            py_rates.append(samples / (time.perf_counter() - start))
            run = subprocess.run(
                [args.binary, "render", args.scene, "-s", str(args.spp), "-o", out, "--json", "-q"],
                check=True, capture_output=True, text=True)
            cli_rates.append(json.loads(run.stdout)["samples_per_second"])
    py, cli = statistics.median(py_rates), statistics.median(cli_rates)
    print(f"CPU: {cpu_line()}")
    print(f"{args.scene}, {args.spp} spp, medians of {args.reps} runs in turns")
    print(f"| | samples/s |\n|---|---|\n| pathlab.render (Python) | {py:.3e} |\n| pathlab render (CLI) | {cli:.3e} |")
    print(f"Python / CLI: {py / cli:.3f}")


if __name__ == "__main__":
    main()
