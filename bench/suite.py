#!/usr/bin/env python3
"""pathlab against Mitsuba 3 on Mitsuba's own render regression suite
(tests/data/mitsuba-suite/tests/scenes), in one run on one machine (bench/run.sh suite starts
it with a venv holding `mitsuba`): the scenes people bring, beyond the project's reference
scenes.

For each scene file NAME_INTEGRATOR.xml (`$integrator` set from its name, as Mitsuba's test
sets it; the volumetric ones are left out, pathlab has no media):
1. speed: samples per second of both renderers at the file's resolution and --spp, pathlab with
   the independent sampler as the files ask; each rate the median of --reps runs, the two
   renderers taking turns. Mitsuba's suite wraps each integrator in `moment` (second moments
   for its test); Mitsuba renders with the wrapped integrator alone, as pathlab does.
2. equal-time error: Mitsuba's median time is the budget; pathlab renders with its default
   settings at the spp its own rate allows; each image's RMSE against the suite's reference
   (refs/NAME_ref_rgb.exr), the median over --reps images on each side; also net of the
   reference's own noise (its per-sample variance refs/NAME_ref_rgb_var.exr over --ref-spp,
   the count Mitsuba's reference script renders by default), which adds the same to both.

Mitsuba's variant is llvm_ad_rgb (see mitsuba_runs.py); each of its renders runs in a process
of its own, after an untimed render that compiles its kernels."""
import argparse, glob, json, os, subprocess
import numpy as np
import mitsuba as mi
import mitsuba_runs
from machine import cpu_line, pathlab_build

ap = argparse.ArgumentParser()
ap.add_argument("--pathlab", required=True)
ap.add_argument("--suite", required=True, help="tests/data/mitsuba-suite/tests/scenes")
ap.add_argument("--work", required=True)
ap.add_argument("--spp", type=int, default=1024)
ap.add_argument("--reps", type=int, default=3, help="speed runs per renderer, taken in turns")
ap.add_argument("--only", nargs="*", help="folders or file stems to run (default: all)")
ap.add_argument("--ref-spp", type=int, default=32000,
                help="samples per pixel of the suite's references (Mitsuba's test_renders.py"
                     " renders them at 32000 unless told otherwise)")
args = ap.parse_args()

variant = mitsuba_runs.pick_variant()


def pathlab_render(scene, integrator, extra, out):
    return mitsuba_runs.pathlab_render(args.pathlab, scene,
                                       ["-D", f"integrator={integrator}"] + extra, out)


files = sorted(glob.glob(os.path.join(args.suite, "*", "*.xml")))
print(f"{cpu_line()}; Mitsuba 3 {mi.__version__} {variant}; {pathlab_build(args.pathlab)} on all threads; {args.spp} spp;"
      f" rates are medians of {args.reps} runs taken in turns")
print(f"{'scene':<52} {'Mitsuba S/s':>11} {'pathlab S/s':>11} {'ratio':>6}   {'Mitsuba RMSE':>12}"
      f" {'pathlab spp':>11} {'pathlab RMSE':>12} {'RMSE ratio':>10} {'net of ref':>10}")
results = {"cpu": cpu_line(), "variant": variant, "spp": args.spp, "cases": {}}
os.makedirs(args.work, exist_ok=True)
for path in files:
    folder = os.path.basename(os.path.dirname(path))
    stem = os.path.basename(path)[:-4]
    name, integrator = stem.rsplit("_", 1)
    if integrator == "volpath" or (args.only and folder not in args.only and stem not in args.only):
        continue
    ref_path = os.path.join(os.path.dirname(path), "refs", f"{name}_ref_rgb.exr")
    if not os.path.exists(ref_path):
        continue
    ref = np.asarray(mi.Bitmap(ref_path), dtype=np.float64)[..., :3]
    var_path = ref_path.replace(".exr", "_var.exr")
    ref_var = (mitsuba_runs.reference_variance_of_mean(var_path, args.ref_spp)
               if os.path.exists(var_path) else None)
    pixels = ref.shape[0] * ref.shape[1]
    tag = f"suite-{folder}-{stem}"
    rendered = []

    def mitsuba(rep):
        t, img, what = mitsuba_runs.render_file(variant, path, args.spp,
                                                {"integrator": integrator}, rep)
        rendered.append(what)
        return t, img

    # Mitsuba renders first, so a scene it cannot load fails before pathlab runs.
    try:
        c = mitsuba_runs.compare(
            args.reps, args.spp, pixels, ref, mitsuba,
            lambda flags, kind: pathlab_render(path, integrator, flags,
                                               f"{args.work}/{kind}-{tag}.exr"),
            ref_var=ref_var)
    except subprocess.CalledProcessError as e:
        if rendered:  # Mitsuba rendered it: the failure is pathlab's
            raise
        why = (e.stderr or "").strip().splitlines()[-1:] or ["no message"]
        print(f"{folder}/{stem:<40} Mitsuba cannot render it here: {why[0][-160:]}", flush=True)
        continue
    c["mitsuba_integrator"] = rendered[-1]
    label = f"{folder}/{stem}"
    results["cases"][label] = c
    print(f"{label:<52} {c['mitsuba_rate']:11.3e} {c['pathlab_rate']:11.3e} {c['ratio']:6.2f}"
          f"   {c['mitsuba_rmse']:12.5f} {c['pathlab_spp']:11d} {c['pathlab_rmse']:12.5f}"
          f" {c['rmse_ratio'] or float('nan'):10.2f} {mitsuba_runs.fmt(c['rmse_ratio_net'], 10)}"
          f"   [{rendered[-1]}]", flush=True)
json.dump(results, open(f"{args.work}/suite.json", "w"), indent=1)
ratios = [c["ratio"] for c in results["cases"].values()]
if ratios:
    print(f"geometric mean of the speed ratios: {float(np.exp(np.mean(np.log(ratios)))):.2f};"
          f" lowest {min(ratios):.2f}, highest {max(ratios):.2f}")
