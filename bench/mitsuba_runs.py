"""What bench/mitsuba_bench.py, bench/scenes.py and bench/suite.py share: Mitsuba's variant,
its timed renders in processes of their own, and the RMSE of an image against a reference.

Run as a script (`python3 bench/mitsuba_runs.py VARIANT SCENE MAX_DEPTH SPP OUT.npy [SEED=N]
[NAME=VALUE ...]`) it is one timed render: the first render compiles the kernels and is not
timed; it prints the seconds of the second (and what integrator it rendered) and saves its
image. Each Mitsuba measurement runs so, in a process
that has exited before pathlab starts: after a render, Mitsuba's worker threads keep a core
busy for seconds, which would slow whatever runs next."""
import os, subprocess, sys, tempfile, time
import numpy as np
import mitsuba as mi


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
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "img.npy")
        cmd = [sys.executable, __file__, variant, scene, str(max_depth), str(spp), out,
               f"SEED={SEED + rep}"]
        stdout = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        seconds = float(stdout.splitlines()[0])
        return seconds, np.load(out)


def render_file(variant, scene, spp, params, rep=0):
    """One timed Mitsuba render of a scene file with `$NAME` parameters `params` (a dict of
    strings), in a process of its own, as `render` (`rep` as there): (seconds, image, what was
    rendered). A
    `moment` integrator (Mitsuba's test suite wraps its scenes' integrators in one, to record
    second moments) is replaced by the integrator it wraps, with the same settings, so that
    Mitsuba does only the work pathlab does."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "img.npy")
        cmd = [sys.executable, __file__, variant, scene, "-", str(spp), out, f"SEED={SEED + rep}"]
        cmd += [f"{k}={v}" for k, v in params.items()]
        lines = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.split("\n")
        return float(lines[0]), np.load(out), lines[1]


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


# Seeds far from the small ones the reference images' 16 runs may have used, so that a timed
# image is not one of the runs its error is measured against.
SEED = 1_000_002


def rmse(img, ref):
    return float(np.sqrt(np.mean((np.asarray(img, dtype=np.float64)[..., :3] - ref) ** 2)))


if __name__ == "__main__":
    # VARIANT SCENE MAX_DEPTH SPP OUT [NAME=VALUE ...]; MAX_DEPTH "-" leaves the file's.
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
