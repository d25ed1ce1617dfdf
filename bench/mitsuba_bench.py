#!/usr/bin/env python3
"""pathlab against Mitsuba 3 on the Cornell box, in one run on one machine (bench/run.sh starts
it with a venv holding `mitsuba`):

1. speed: samples per second of both renderers at the same resolution, spp and depth
   (-m inf and -m 1; Mitsuba's max_depth is one more), and their ratio;
2. equal-time error: Mitsuba renders for its time at SPP; pathlab gets the same wall time
   (uniform Sobol at the spp its own rate allows, and error-driven `--time`), and each image's
   RMSE against the 4096-spp reference is printed.

Mitsuba's variant is llvm_ad_rgb (vectorised, JIT-compiled; needs libLLVM, DRJIT_LIBLLVM_PATH),
else scalar_rgb, which the output says. Its first render of each configuration compiles kernels
and is not timed. Each Mitsuba measurement runs in a process of its own that has exited before
pathlab starts: after a render, Mitsuba's worker threads keep a core busy (measured: a whole
core for seconds), which would slow whatever runs next."""
import argparse, json, subprocess
import numpy as np
import mitsuba as mi
import mitsuba_runs


ap = argparse.ArgumentParser()
ap.add_argument("--pathlab", required=True)
ap.add_argument("--scene", required=True)
ap.add_argument("--reference", required=True)
ap.add_argument("--work", required=True)
ap.add_argument("--spp", type=int, default=64)
ap.add_argument("--reps", type=int, default=3, help="speed runs per renderer, taken in turns")
args = ap.parse_args()

variant = mitsuba_runs.pick_variant()

rmse = mitsuba_runs.rmse

ref = np.asarray(mi.Bitmap(args.reference), dtype=np.float64)[..., :3]
height, width = ref.shape[:2]
pixels = width * height

def mitsuba_render(max_depth, spp):
    return mitsuba_runs.render(variant, args.scene, max_depth, spp)

def pathlab_render(depth, extra, name):
    out = f"{args.work}/{name}.exr"
    cmd = [args.pathlab, "render", "cornell-box", "-m", depth, "-q", "--json", "-o", out] + extra
    stats = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    img = np.asarray(mi.Bitmap(out), dtype=np.float64)[..., :3]
    return stats, img

print(f"Cornell box {width}x{height}, {args.spp} spp; Mitsuba 3 {mi.__version__} {variant}; pathlab, all threads;"
      f" medians of {args.reps} runs each")
print(f"{'depth':<6} {'Mitsuba samples/s':>18} {'pathlab samples/s':>18} {'ratio':>7}")
results = {"variant": variant, "spp": args.spp, "speed": {}, "equal_time": {}}
# Each renderer's rate is the median of --reps runs, the two taking turns, so that one run
# disturbed by the machine moves no ratio.
for depth, mitsuba_depth in (("inf", -1), ("1", 2)):
    rates_m, rates_p = [], []
    for _ in range(args.reps):
        t_m, _ = mitsuba_render(mitsuba_depth, args.spp)
        rates_m.append(pixels * args.spp / t_m)
        stats, _ = pathlab_render(depth, ["-s", str(args.spp), "--sampler", "independent"], f"speed-{depth}")
        rates_p.append(stats["samples_per_second"])
    rate_m, rate_p = float(np.median(rates_m)), float(np.median(rates_p))
    results["speed"][depth] = {"mitsuba": rate_m, "pathlab": rate_p, "ratio": rate_p / rate_m,
                               "mitsuba_runs": rates_m, "pathlab_runs": rates_p}
    print(f"{depth:<6} {rate_m:18.3e} {rate_p:18.3e} {rate_p / rate_m:7.2f}")

# Equal time at -m inf: Mitsuba at SPP sets the budget; each pathlab sampler gets the spp its
# own measured rate allows in that time, and --time gets the time itself.
t_m, img_m = mitsuba_render(-1, args.spp)
e_m = rmse(img_m, ref)
rows = [("Mitsuba", t_m, args.spp, e_m)]
for sampler in ("independent", "sobol"):
    probe, _ = pathlab_render("inf", ["-s", str(args.spp), "--sampler", sampler], f"rate-{sampler}")
    spp_p = max(1, int(t_m * probe["samples_per_second"] / pixels))
    stats, img = pathlab_render("inf", ["-s", str(spp_p), "--sampler", sampler], f"equal-time-{sampler}")
    rows.append((f"pathlab ({sampler}, uniform)", stats["seconds"], spp_p, rmse(img, ref)))
stats, img = pathlab_render("inf", ["--time", f"{t_m:.3f}"], "equal-time-progressive")
rows.append(("pathlab (--time, error-driven)", stats["seconds"], round(stats["samples"] / pixels), rmse(img, ref)))
print(f"\nequal time at -m inf ({t_m:.2f} s): RMSE against the reference")
print(f"{'renderer':<32} {'seconds':>8} {'spp':>8} {'RMSE':>10} {'RMSE / Mitsuba':>15}")
for name, secs, spp, e in rows:
    print(f"{name:<32} {secs:8.2f} {spp:>8} {e:10.5f} {e / e_m:15.2f}")
    results["equal_time"][name] = {"seconds": secs, "spp": spp, "rmse": e}
json.dump(results, open(f"{args.work}/mitsuba.json", "w"), indent=1)
