#!/usr/bin/env python3
"""pathlab against Mitsuba 3 on Bitterli's pbrt-v4 scenes (tests/data/bitterli), in one run on
one machine (bench/run.sh pbrt starts it with a venv holding `mitsuba`). Mitsuba reads no
pbrt-v4, so `pathlab export` writes each scene as Mitsuba XML (meshes as PLY): the scene
pathlab loaded, which both renderers then render at a quarter of the file's resolution.

1. reference: Mitsuba's render of the exported file at --ref-spp (its own sampler, a seed of its
   own), made once and kept in the work folder;
2. speed: samples per second of both renderers at --spp with the independent sampler and the
   path tracer (Mitsuba's `max_depth` is pathlab's + 1, as the export writes it); each rate the
   median of --reps runs, the two renderers taking turns;
3. equal-time error: Mitsuba renders the exported file as written (its sampler `ldsampler`
   where the pbrt file asks for `sobol`) at --spp and its time is the budget; pathlab renders
   the .pbrt file with its default settings (the file's sampler and integrator: veach-bidir
   asks for the bidirectional path tracer, which Mitsuba 3 lacks) at the spp its own rate at
   those settings allows; each image's RMSE against the reference, medians over --reps images.

Each Mitsuba measurement runs in a process of its own, after an untimed render that compiles
its kernels (mitsuba_runs.py)."""
import argparse, json, os, re, subprocess
import numpy as np
import mitsuba as mi
import mitsuba_runs
from machine import cpu_line, pathlab_build

# (name, quarter resolution of the file's)
CASES = [("cornell-box", 256, 256), ("veach-mis", 320, 180), ("veach-bidir", 256, 256)]

ap = argparse.ArgumentParser()
ap.add_argument("--pathlab", required=True)
ap.add_argument("--data", required=True, help="tests/data")
ap.add_argument("--work", required=True)
ap.add_argument("--spp", type=int, default=256)
ap.add_argument("--ref-spp", type=int, default=4096)
ap.add_argument("--reps", type=int, default=3)
ap.add_argument("--only", nargs="*")
args = ap.parse_args()
variant = mitsuba_runs.pick_variant()
os.makedirs(args.work, exist_ok=True)


def export(pbrt, xml, w, h):
    subprocess.run([args.pathlab, "export", pbrt, "-r", str(w), str(h), "-o", xml],
                   check=True, capture_output=True, text=True)


print(f"{cpu_line()}; Mitsuba 3 {mi.__version__} {variant}; {pathlab_build(args.pathlab)} on all threads; {args.spp} spp;"
      f" rates are medians of {args.reps} runs taken in turns")
print(f"{'scene':<12} {'Mitsuba S/s':>12} {'pathlab S/s':>12} {'ratio':>6}   {'Mitsuba RMSE':>12}"
      f" {'pathlab spp':>11} {'time used':>9} {'pathlab RMSE':>12} {'RMSE ratio':>10} {'at budget':>9}")
results = {"cpu": cpu_line(), "variant": variant, "spp": args.spp, "cases": {}}
for name, w, h in CASES:
    if args.only and name not in args.only:
        continue
    pbrt = os.path.join(args.data, "bitterli", name, "scene-v4.pbrt")
    xml = os.path.join(args.work, f"{name}.xml")
    export(pbrt, xml, w, h)
    # The same scene with independent samples, for the speed runs.
    text = open(xml).read()
    independent = os.path.join(args.work, f"{name}-independent.xml")
    open(independent, "w").write(re.sub(r'<sampler type="\w+">', '<sampler type="independent">', text))
    pixels = w * h
    ref_path = os.path.join(args.work, f"{name}-ref-{args.ref_spp}.npy")
    if not os.path.exists(ref_path):
        _, ref, _ = mitsuba_runs.timed(variant, xml, "-", args.ref_spp, {}, 1000)
        np.save(ref_path, ref)
    ref = np.load(ref_path).astype(np.float64)[..., :3]

    def mitsuba(scene):
        return lambda rep: mitsuba_runs.timed(variant, scene, "-", args.spp, {}, rep)[:2]

    def pathlab(flags, kind):
        # The speed runs trace paths as Mitsuba does; the others take the file's integrator.
        extra = ["--integrator", "path"] if kind == "speed" else []
        return mitsuba_runs.pathlab_render(args.pathlab, pbrt, ["-r", str(w), str(h)] + flags
                                           + extra, f"{args.work}/{kind}-{name}.exr")

    c = mitsuba_runs.compare(args.reps, args.spp, pixels, ref, mitsuba(independent), pathlab,
                             mitsuba_settings=mitsuba(xml))
    results["cases"][name] = c
    print(f"{name:<12} {c['mitsuba_rate']:12.3e} {c['pathlab_rate']:12.3e} {c['ratio']:6.2f}"
          f"   {c['mitsuba_rmse']:12.5f} {c['pathlab_spp']:11d}"
          f" {c['pathlab_seconds'] / c['mitsuba_seconds']:9.2f}"
          f" {c['pathlab_rmse']:12.5f} {c['rmse_ratio']:10.2f} {c['rmse_ratio_at_budget']:9.2f}", flush=True)
json.dump(results, open(f"{args.work}/pbrt.json", "w"), indent=1)
