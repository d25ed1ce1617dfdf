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
   (refs/NAME_ref_rgb.exr), the median over --reps images on each side.

Mitsuba's variant is llvm_ad_rgb (see mitsuba_runs.py); each of its renders runs in a process
of its own, after an untimed render that compiles its kernels."""
import argparse, glob, json, os, subprocess
import numpy as np
import mitsuba as mi
import mitsuba_runs
from machine import cpu_line

ap = argparse.ArgumentParser()
ap.add_argument("--pathlab", required=True)
ap.add_argument("--suite", required=True, help="tests/data/mitsuba-suite/tests/scenes")
ap.add_argument("--work", required=True)
ap.add_argument("--spp", type=int, default=1024)
ap.add_argument("--reps", type=int, default=3, help="speed runs per renderer, taken in turns")
ap.add_argument("--only", nargs="*", help="folders or file stems to run (default: all)")
args = ap.parse_args()

variant = mitsuba_runs.pick_variant()


def pathlab_render(scene, integrator, extra, out):
    cmd = [args.pathlab, "render", scene, "-D", f"integrator={integrator}", "-q", "--json",
           "-o", out] + extra
    stats = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return stats, np.asarray(mi.Bitmap(out), dtype=np.float64)[..., :3]


files = sorted(glob.glob(os.path.join(args.suite, "*", "*.xml")))
print(f"{cpu_line()}; Mitsuba 3 {mi.__version__} {variant}; pathlab on all threads; {args.spp} spp;"
      f" rates are medians of {args.reps} runs taken in turns")
print(f"{'scene':<52} {'Mitsuba S/s':>11} {'pathlab S/s':>11} {'ratio':>6}   {'Mitsuba RMSE':>12}"
      f" {'pathlab spp':>11} {'pathlab RMSE':>12} {'RMSE ratio':>10}")
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
    pixels = ref.shape[0] * ref.shape[1]
    tag = f"suite-{folder}-{stem}"
    rates_m, rates_p, times_m, errs_m = [], [], [], []
    try:
        mitsuba_runs.render_file(variant, path, 1, {"integrator": integrator})
    except subprocess.CalledProcessError as e:
        why = (e.stderr or "").strip().splitlines()[-1:] or ["no message"]
        print(f"{folder}/{stem:<40} Mitsuba cannot render it here: {why[0][-160:]}", flush=True)
        continue
    for rep in range(args.reps):
        t_m, img_m, rendered = mitsuba_runs.render_file(variant, path, args.spp,
                                                        {"integrator": integrator}, rep)
        rates_m.append(pixels * args.spp / t_m)
        times_m.append(t_m)
        errs_m.append(mitsuba_runs.rmse(img_m, ref))
        stats, _ = pathlab_render(path, integrator,
                                  ["-s", str(args.spp), "--sampler", "independent"],
                                  f"{args.work}/speed-{tag}.exr")
        rates_p.append(stats["samples_per_second"])
    rate_m, rate_p = float(np.median(rates_m)), float(np.median(rates_p))
    t_m, e_m = float(np.median(times_m)), float(np.median(errs_m))
    probe, _ = pathlab_render(path, integrator, ["-s", "64"], f"{args.work}/probe-{tag}.exr")
    spp_p = max(1, int(t_m * probe["samples_per_second"] / pixels))
    # As many equal-time images as Mitsuba's, each with its own seed: these images' errors
    # are heavy-tailed (a few pixels of glossy highlights), so one RMSE says little.
    errs_p, secs_p = [], []
    for rep in range(args.reps):
        stats, img = pathlab_render(path, integrator, ["-s", str(spp_p), "--seed", str(rep + 1)],
                                    f"{args.work}/equal-time-{tag}.exr")
        errs_p.append(mitsuba_runs.rmse(img, ref))
        secs_p.append(stats["seconds"])
    e_p = float(np.median(errs_p))
    stats = {"seconds": float(np.median(secs_p))}
    label = f"{folder}/{stem}"
    results["cases"][label] = {
        "mitsuba_integrator": rendered, "mitsuba_rate": rate_m, "pathlab_rate": rate_p,
        "ratio": rate_p / rate_m, "mitsuba_runs": rates_m, "pathlab_runs": rates_p,
        "mitsuba_seconds": t_m, "mitsuba_rmse": e_m, "pathlab_spp": spp_p,
        "pathlab_seconds": stats["seconds"], "pathlab_rmse": e_p,
        "rmse_ratio": e_p / e_m if e_m > 0 else None,
    }
    print(f"{label:<52} {rate_m:11.3e} {rate_p:11.3e} {rate_p / rate_m:6.2f}   {e_m:12.5f}"
          f" {spp_p:11d} {e_p:12.5f} {e_p / max(e_m, 1e-30):10.2f}   [{rendered}]", flush=True)
json.dump(results, open(f"{args.work}/suite.json", "w"), indent=1)
ratios = [c["ratio"] for c in results["cases"].values()]
if ratios:
    print(f"geometric mean of the speed ratios: {float(np.exp(np.mean(np.log(ratios)))):.2f};"
          f" lowest {min(ratios):.2f}, highest {max(ratios):.2f}")
