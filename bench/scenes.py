#!/usr/bin/env python3
"""pathlab against Mitsuba 3 on every reference scene of tests/data, in one run on
one machine (bench/run.sh scenes starts it with a venv holding `mitsuba`):

1. speed: samples per second of both renderers on the same scene file at the same resolution,
   spp and depth (Mitsuba's max_depth is ours + 1), pathlab with the independent sampler as
   Mitsuba's scenes use; each rate the median of --reps runs, the two renderers taking turns;
2. equal-time error: Mitsuba renders at --spp and its time is the budget; pathlab, with its
   default settings (sampler and all), renders at the spp its own measured rate allows in that
   time; each image's RMSE against the scene's reference (Mitsuba, 16 x 256 spp), the median
   over --reps images on each side (pathlab's with seeds 1, 2, ...); also net of the
   reference's own noise (its standard-error image), which adds the same to both errors; and
   the ratio of the root mean squared errors over the images (net, at the budget) with its
   standard error;
3. the same equal-time error with pathlab's own default sampler, Sobol (`--sampler sobol`, at
   the spp its rate with Sobol allows), which it takes where a scene file names no sampler:
   these files name `independent`, which pathlab honours, so (2) compares the same estimator
   with the same kind of samples, and (3) what pathlab's sampler gains on top

Mitsuba's variant is llvm_ad_rgb (JIT-compiled, as wide as the CPU's vectors: 16 lanes with
AVX-512); its first render of each configuration compiles kernels and is not timed. Each
Mitsuba measurement runs in a process of its own, gone before pathlab starts (after a render
Mitsuba's worker threads keep a core busy for seconds)."""
import argparse, json, os
import numpy as np
import mitsuba as mi
import mitsuba_runs
from machine import cpu_line, pathlab_build


# (name in the table, folder under tests/data, pathlab -m, reference's depth)
CASES = [
    ("cornell-box", "cornell-box", "inf", "inf"),
    ("cornell-box -m 1", "cornell-box", "1", "2"),
    ("cornell-rough", "cornell-rough", "inf", "inf"),
    ("cornell-spheres", "cornell-spheres", "inf", "inf"),
    ("sky-spheres", "sky-spheres", "inf", "inf"),
    ("cornell-thinlens", "cornell-thinlens", "inf", "inf"),
]

ap = argparse.ArgumentParser()
ap.add_argument("--pathlab", required=True)
ap.add_argument("--data", required=True, help="tests/data")
ap.add_argument("--work", required=True)
ap.add_argument("--spp", type=int, default=256)
ap.add_argument("--reps", type=int, default=3, help="speed runs per renderer, taken in turns")
ap.add_argument("--only", nargs="*", help="names of the cases to run (default: all)")
args = ap.parse_args()

variant = mitsuba_runs.pick_variant()


def mitsuba_render(scene, max_depth, spp, rep):
    return mitsuba_runs.render(variant, scene, max_depth, spp, rep)


def pathlab_render(scene, depth, extra, name):
    return mitsuba_runs.pathlab_render(args.pathlab, scene, ["-m", depth] + extra,
                                       f"{args.work}/{name}.exr")


print(f"{cpu_line()}; Mitsuba 3 {mi.__version__} {variant}; {pathlab_build(args.pathlab)} on all threads; {args.spp} spp;"
      f" rates are medians of {args.reps} runs taken in turns")
print(f"{'scene':<18} {'Mitsuba S/s':>12} {'pathlab S/s':>12} {'ratio':>6}   {'Mitsuba RMSE':>12}"
      f" {'pathlab spp':>11} {'time used':>9} {'pathlab RMSE':>12} {'RMSE ratio':>10} {'at budget':>9}"
      f" {'net of ref':>10} {'net, budget':>11} {'mean sq., net, budget':>21}"
      f" {'Sobol spp':>9} {'Sobol: mean sq., net, budget':>28}")
results = {"cpu": cpu_line(), "variant": variant, "spp": args.spp, "cases": {}}
os.makedirs(args.work, exist_ok=True)
for name, folder, depth, ref_depth in CASES:
    if args.only and name not in args.only:
        continue
    scene = os.path.join(args.data, folder, "scene.xml")
    ref = np.asarray(mi.Bitmap(os.path.join(args.data, folder, f"mean-maxdepth-{ref_depth}.exr")),
                     dtype=np.float64)[..., :3]
    stderr = os.path.join(args.data, folder, f"stderr-maxdepth-{ref_depth}.exr")
    ref_var = mitsuba_runs.reference_variance(stderr) if os.path.exists(stderr) else None
    pixels = ref.shape[0] * ref.shape[1]
    mitsuba_depth = -1 if depth == "inf" else int(depth) + 1
    tag = folder + ("" if depth == "inf" else f"-m{depth}")
    def pathlab(flags, kind):
        return pathlab_render(scene, depth, flags, f"{kind}-{tag}")
    c = mitsuba_runs.compare(
        args.reps, args.spp, pixels, ref,
        lambda rep: mitsuba_render(scene, mitsuba_depth, args.spp, rep),
        pathlab, ref_var=ref_var)
    # Equal time with Sobol samples: the same budget (Mitsuba's median time), the spp
    # pathlab's rate with Sobol allows.
    spp_s, errs_s, secs_s = mitsuba_runs.equal_time(
        args.reps, args.spp, pixels, ref, c["mitsuba_seconds"], pathlab,
        ["--sampler", "sobol"], "-sobol")
    budget_s = (secs_s / c["mitsuba_seconds"]) ** 0.5
    ratio_s, se_s = mitsuba_runs.mean_square_ratio(errs_s, c["mitsuba_rmses"], ref_var or 0.0)
    c["sobol_spp"] = spp_s
    c["sobol_rmses"] = errs_s
    c["sobol_rmse_ratio_mean_net_at_budget"] = ratio_s * budget_s if ratio_s is not None else None
    c["sobol_rmse_ratio_mean_net_at_budget_se"] = se_s * budget_s if se_s is not None else None
    results["cases"][name] = c
    print(f"{name:<18} {c['mitsuba_rate']:12.3e} {c['pathlab_rate']:12.3e} {c['ratio']:6.2f}"
          f"   {c['mitsuba_rmse']:12.5f} {c['pathlab_spp']:11d}"
          f" {c['pathlab_seconds'] / c['mitsuba_seconds']:9.2f} {c['pathlab_rmse']:12.5f}"
          f" {c['rmse_ratio']:10.2f} {c['rmse_ratio_at_budget']:9.2f}"
          f" {mitsuba_runs.fmt(c['rmse_ratio_net'], 10)}"
          f" {mitsuba_runs.fmt(c['rmse_ratio_net_at_budget'], 11)}"
          f" {mitsuba_runs.fmt_se(c['rmse_ratio_mean_net_at_budget'], c['rmse_ratio_mean_net_at_budget_se'], 21)}"
          f" {spp_s:9d}"
          f" {mitsuba_runs.fmt_se(c['sobol_rmse_ratio_mean_net_at_budget'], c['sobol_rmse_ratio_mean_net_at_budget_se'], 28)}",
          flush=True)
json.dump(results, open(f"{args.work}/scenes.json", "w"), indent=1)
