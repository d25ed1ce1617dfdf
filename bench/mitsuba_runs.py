"""What bench/mitsuba_bench.py, bench/scenes.py and bench/suite.py share: Mitsuba's variant,
its timed renders in processes of their own, and the RMSE of an image against a reference.

Run as a script (`python3 bench/mitsuba_runs.py VARIANT SCENE MAX_DEPTH SPP OUT.npy [SEED=N]
[NAME=VALUE ...]`) it is one timed render: the first render compiles the kernels and is not
timed; it prints the seconds of the second (and what integrator it rendered) and saves its
image. Each Mitsuba measurement runs so, in a process that has exited before pathlab starts:
after a render, Mitsuba's worker threads keep a core busy for seconds, which would slow
whatever runs next."""
import json, os, subprocess, sys, tempfile, time
import numpy as np
import mitsuba as mi

# Seeds far from the small ones the reference images' 16 runs may have used, so that a timed
# image is not one of the runs its error is measured against.
SEED = 1_000_002



def pick_variant():
    """llvm_ad_rgb (JIT-compiled, as wide as the CPU's vectors; needs libLLVM through
    DRJIT_LIBLLVM_PATH), else scalar_rgb, which it says on standard error."""
    try:
        mi.set_variant("llvm_ad_rgb")
        return "llvm_ad_rgb"
    except Exception as e:  # no LLVM: the scalar variant, much slower
        mi.set_variant("scalar_rgb")
        print(f"note: llvm_ad_rgb unavailable ({e}); using scalar_rgb", file=sys.stderr)
        return "scalar_rgb"


def render(variant, scene, max_depth, spp, rep=0):
    """One timed Mitsuba render in a process of its own: (seconds, image). Repetition `rep`
    renders with a seed of its own, so that repeated renders are different images."""
    seconds, img, _ = timed(variant, scene, str(max_depth), spp, {}, rep)
    return seconds, img


def render_file(variant, scene, spp, params, rep=0):
    """One timed Mitsuba render of a scene file with `$NAME` parameters `params` (a dict of
    strings), its own depth, as `render` (`rep` as there): (seconds, image, what was
    rendered). A `moment` integrator (Mitsuba's test suite wraps its scenes' integrators in
    one, to record second moments) is replaced by the integrator it wraps, with the same
    settings, so that Mitsuba does only the work pathlab does."""
    return timed(variant, scene, "-", spp, params, rep)


def timed(variant, scene, max_depth, spp, params, rep):
    """This file run as a script (see above) in a process of its own."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "img.npy")
        cmd = [sys.executable, __file__, variant, scene, max_depth, str(spp), out,
               f"SEED={SEED + rep}"] + [f"{k}={v}" for k, v in params.items()]
        lines = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.splitlines()
        return float(lines[0]), np.load(out), lines[1]


def pathlab_render(pathlab, scene, flags, out):
    """`pathlab render SCENE FLAGS -o OUT` (quiet, JSON): its statistics and the image."""
    cmd = [pathlab, "render", scene, "-q", "--json", "-o", out] + flags
    stats = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return stats, np.asarray(mi.Bitmap(out), dtype=np.float64)[..., :3]


def unwrapped(integrator):
    """The integrator a `moment` integrator wraps, rebuilt from its printed settings (Mitsuba
    exposes them no other way), or `integrator` itself; and a line saying which."""
    text = str(integrator)
    if "integrators = [" not in text:
        return integrator, text.split("[")[0]
    inner = text.split("integrators = [", 1)[1]
    name = inner.strip().split("[")[0]
    kinds = {"PathIntegrator": "path", "DirectIntegrator": "direct",
             "ParticleTracerIntegrator": "ptracer"}
    if name not in kinds:
        return integrator, f"moment({name}) as written"
    settings = {"type": kinds[name]}
    for line in inner.split("]")[0].splitlines():
        if "=" in line:
            key, value = (x.strip().rstrip(",") for x in line.split("=", 1))
            try:
                settings[key] = int(value)
            except ValueError:
                if value in ("true", "false", "1", "0"):
                    settings[key] = value in ("true", "1")
    return mi.load_dict(settings), f"{name}{ {k: v for k, v in settings.items() if k != 'type'} }"


def compare(reps, spp, pixels, ref, mitsuba, pathlab, mitsuba_settings=None, ref_var=None):
    """One scene measured both ways, as bench/scenes.py, bench/suite.py and
    bench/pbrt_scenes.py report it.

    Speed: `reps` renders at `spp` by each renderer, taking turns (`mitsuba(rep)` gives
    (seconds, image); `pathlab(flags, kind)` gives (its JSON statistics, image), pathlab with
    the independent sampler as the scenes ask); each rate the median. Equal time: Mitsuba's
    median time is the budget; pathlab, with its default settings, renders at the spp its own
    rate at those settings allows, `reps` times with seeds 1, 2, ... That rate is probed by a
    render as long as the speed runs (`spp`): a short probe counts the start of a render
    (threads, film) against too few samples and would leave part of the budget unused.
    Errors are RMSE against `ref`, medians over the repetitions on each side: a scene's error
    is heavy-tailed (a few bright pixels), so one image's RMSE says little. Where the scene's
    own settings differ from the speed runs' (`mitsuba_settings(rep)`, rendering them, as
    `mitsuba` does), Mitsuba's budget and error come from renders at those settings. The
    probe's rate misses the equal-time renders' by up to a fifth on a busy machine, so the
    error ratio is also given scaled to exactly the budget (`rmse_ratio_at_budget`).

    An image's squared error against a reference is its own error plus the reference's: with
    `ref_var`, the mean over pixels of the reference's variance (its standard error squared),
    the errors net of it are given too (`rmse_ratio_net`, and at the budget): the reference's
    noise adds the same to both sides, so it pulls the ratio towards one and flatters the
    renderer with the larger error."""
    rates_m, rates_p, times_m, errs_m = [], [], [], []
    for rep in range(reps):
        t_m, img_m = mitsuba(rep)
        rates_m.append(pixels * spp / t_m)
        if mitsuba_settings is not None:
            t_m, img_m = mitsuba_settings(rep)
        times_m.append(t_m)
        errs_m.append(rmse(img_m, ref))
        stats, _ = pathlab(["-s", str(spp), "--sampler", "independent"], "speed")
        rates_p.append(stats["samples_per_second"])
    rate_m, rate_p = float(np.median(rates_m)), float(np.median(rates_p))
    t_m, e_m = float(np.median(times_m)), float(np.median(errs_m))
    spp_p, errs_p, secs = equal_time(reps, spp, pixels, ref, t_m, pathlab)
    e_p = float(np.median(errs_p))
    ratio = e_p / e_m if e_m > 0 else None
    net = None
    if ref_var is not None and e_m * e_m > ref_var:
        net = max(e_p * e_p - ref_var, 0.0) ** 0.5 / (e_m * e_m - ref_var) ** 0.5
    budget = (secs / t_m) ** 0.5 if t_m > 0 else None
    mean_ratio, mean_se = mean_square_ratio(errs_p, errs_m, ref_var or 0.0)
    return {
        "mitsuba_rate": rate_m, "pathlab_rate": rate_p, "ratio": rate_p / rate_m,
        "mitsuba_runs": rates_m, "pathlab_runs": rates_p, "mitsuba_seconds": t_m,
        "mitsuba_rmse": e_m, "mitsuba_rmses": errs_m, "pathlab_spp": spp_p,
        "pathlab_seconds": secs, "pathlab_rmse": e_p,
        "pathlab_rmses": errs_p, "rmse_ratio": ratio,
        # The error ratio had pathlab used exactly Mitsuba's time: a Monte Carlo image's RMSE
        # falls as 1/sqrt(time), so a render that overran the budget by a factor k is scaled
        # up by sqrt(k) (the reference's own error being small against both).
        "rmse_ratio_at_budget": ratio * budget if ratio is not None and budget is not None
        else None,
        "reference_variance": ref_var, "rmse_ratio_net": net,
        "rmse_ratio_net_at_budget": net * budget if net is not None and budget is not None
        else None,
        # The ratio of the root mean squared errors over the repetitions (net of the
        # reference's noise where it is known), at the budget, and its standard error.
        "rmse_ratio_mean_net_at_budget": mean_ratio * budget
        if mean_ratio is not None and budget is not None else None,
        "rmse_ratio_mean_net_at_budget_se": mean_se * budget
        if mean_se is not None and budget is not None else None,
    }


def equal_time(reps, spp, pixels, ref, budget, pathlab, flags=(), kind=""):
    """pathlab's equal-time renders, as `compare` makes them: its rate with `flags` probed by a
    render at `spp`, then `reps` renders (seeds 1, 2, ...) at the spp that rate allows in
    `budget` seconds (`kind` tells their files apart). Returns that spp, the renders' RMSEs
    against `ref` and their median time."""
    flags = list(flags)
    probe, _ = pathlab(["-s", str(spp)] + flags, "probe" + kind)
    spp_p = max(1, int(budget * probe["samples_per_second"] / pixels))
    errs, secs = [], []
    for rep in range(reps):
        stats, img = pathlab(["-s", str(spp_p), "--seed", str(rep + 1)] + flags, "equal-time" + kind)
        errs.append(rmse(img, ref))
        secs.append(stats["seconds"])
    return spp_p, errs, float(np.median(secs))


def mean_square_ratio(errs_p, errs_m, ref_var):
    """√(mean squared error of `errs_p` / that of `errs_m`), each less `ref_var`, and its
    standard error (delta method, from the spread of the squared errors over the images).

    The expected squared error is what an image's error is on average; the median of a few
    images' errors is robust to one bright outlier, but where the error is heavy-tailed (a few
    pixels catching a small bright source) it sits below the mean by more for the renderer
    that took fewer samples, so a ratio of medians does not estimate the ratio of expected
    errors. With three images each the standard error is itself rough."""
    a = np.array(errs_p, dtype=np.float64) ** 2 - ref_var
    b = np.array(errs_m, dtype=np.float64) ** 2 - ref_var
    if len(a) < 2 or len(b) < 2 or b.mean() <= 0 or a.mean() <= 0:
        return None, None
    r = float((a.mean() / b.mean()) ** 0.5)
    rel_var = (a.var(ddof=1) / len(a) / a.mean() ** 2 + b.var(ddof=1) / len(b) / b.mean() ** 2) / 4
    return r, r * float(rel_var ** 0.5)


def reference_variance(stderr_path):
    """The mean over pixels and channels of a reference's variance, from its standard-error
    image."""
    se = np.asarray(mi.Bitmap(stderr_path), dtype=np.float64)[..., :3]
    return float(np.mean(se * se))


def reference_variance_of_mean(sample_variance_path, spp):
    """The mean over pixels and channels of a reference's variance, from its per-sample
    variance image (as Mitsuba's test suite stores it) and the samples per pixel it took."""
    var = np.asarray(mi.Bitmap(sample_variance_path), dtype=np.float64)[..., :3]
    return float(np.mean(var)) / spp


def fmt(x, width, digits=2):
    """`x` to `digits` decimals in `width` columns, or a dash where it is missing."""
    return f"{x:{width}.{digits}f}" if x is not None else f"{'-':>{width}}"


def fmt_se(x, se, width, digits=2):
    """`x ± se` to `digits` decimals in `width` columns, or a dash where `x` is missing."""
    if x is None:
        return f"{'-':>{width}}"
    return f"{f'{x:.{digits}f} ± {se:.{digits}f}' if se is not None else f'{x:.{digits}f}':>{width}}"


def rmse(img, ref):
    return float(np.sqrt(np.mean((np.asarray(img, dtype=np.float64)[..., :3] - ref) ** 2)))


if __name__ == "__main__":
    # VARIANT SCENE MAX_DEPTH SPP OUT [SEED=N] [NAME=VALUE ...]; MAX_DEPTH "-" leaves the
    # file's.
    variant, scene_path, max_depth, spp, out = sys.argv[1:6]
    mi.set_variant(variant)
    params = dict(a.split("=", 1) for a in sys.argv[6:])
    seed = int(params.pop("SEED", SEED))
    if max_depth != "-":
        params["max_depth"] = int(max_depth)
    scene = mi.load_file(scene_path, spp=int(spp), **params)
    integrator, rendered = unwrapped(scene.integrator())
    mi.render(scene, integrator=integrator, spp=int(spp), seed=SEED - 1)  # compiles kernels
    start = time.perf_counter()
    img = np.array(mi.render(scene, integrator=integrator, spp=int(spp), seed=seed))
    print(time.perf_counter() - start)
    print(rendered)
    np.save(out, img)
