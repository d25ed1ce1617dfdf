"""Both renderers' estimators at equal samples per pixel: per-sample variance, squared bias and
mean squared error against the scene's reference, pathlab over Mitsuba 3.

    python3 bench/equal_spp.py --pathlab BIN --data tests/data [--images 6] [--spp 256]
        [--only cornell-box ...]

Each side renders `--images` images of every reference scene of `tests/data` (the file's own
settings: its independent sampler, box filter and depth) at `--spp`, with seeds of their own.
Per side, over the pixels and channels:
- the variance of one image (the images' sample variance per pixel, averaged), times spp: the
  per-sample variance;
- the mean over the images of each one's squared error against the reference, less the
  reference's own variance (its standard-error image squared): the net MSE, with its standard
  error over the images;
- the squared bias: the squared error of the images' mean, less the part of it that the
  images' variance and the reference's explain (about zero, and sometimes below it, when
  there is none).

Where the MSE ratio is one, the equal-time error ratio is 1/sqrt(samples/s ratio): what
`bench/scenes.py` measures at equal time then comes from speed alone. Not a test. Needs
Mitsuba 3 (`llvm_ad_rgb` through DRJIT_LIBLLVM_PATH, else `scalar_rgb`) and numpy; each
Mitsuba render runs in a process of its own (`bench/mitsuba_runs.py`)."""
import argparse, os, sys, tempfile
import numpy as np
import mitsuba as mi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_runs  # noqa: E402

SCENES = ["cornell-box", "cornell-rough", "cornell-spheres", "sky-spheres", "cornell-thinlens"]


def summary(images, ref, ref_var, spp):
    """(per-sample variance, net MSE, its standard error, squared bias) of a stack of images."""
    x = np.stack(images)
    k = len(images)
    var = float(x.var(axis=0, ddof=1).mean())
    mse = ((x - ref) ** 2).mean(axis=(1, 2, 3)) - ref_var
    bias2 = float(((x.mean(axis=0) - ref) ** 2).mean() - var / k - ref_var)
    return var * spp, float(mse.mean()), float(mse.std(ddof=1) / np.sqrt(k)), bias2


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pathlab", required=True, help="the pathlab binary")
    p.add_argument("--data", default="tests/data", help="the folder of the reference scenes")
    p.add_argument("--images", type=int, default=6, help="images per renderer and scene")
    p.add_argument("--spp", type=int, default=256, help="samples per pixel of each image")
    p.add_argument("--only", nargs="*", help="these scenes only")
    args = p.parse_args()
    if args.images < 2:
        p.error("--images: at least 2 (a variance needs two images)")
    variant = mitsuba_runs.pick_variant()
    print(f"Mitsuba 3 {mi.__version__} {variant}; {args.images} images of {args.spp} spp each side")
    print(f"{'scene':<18} {'side':<8} {'per-sample var':>14} {'net MSE':>10} {'± se':>8}"
          f" {'bias²':>9}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.only or SCENES:
            folder = os.path.join(args.data, name)
            scene = os.path.join(folder, "scene.xml")
            ref = np.asarray(mi.Bitmap(os.path.join(folder, "mean-maxdepth-inf.exr")),
                             dtype=np.float64)[..., :3]
            ref_var = mitsuba_runs.reference_variance(
                os.path.join(folder, "stderr-maxdepth-inf.exr"))
            sides = {"mitsuba": [], "pathlab": []}
            for k in range(args.images):
                _, img = mitsuba_runs.render(variant, scene, -1, args.spp, k)
                sides["mitsuba"].append(np.asarray(img, dtype=np.float64)[..., :3])
                _, img = mitsuba_runs.pathlab_render(
                    args.pathlab, scene, ["-s", str(args.spp), "--seed", str(k + 1)],
                    os.path.join(tmp, f"{name}-{k}.exr"))
                sides["pathlab"].append(img)
            rows = {}
            for side, images in sides.items():
                rows[side] = summary(images, ref, ref_var, args.spp)
                v, m, se, b = rows[side]
                print(f"{name:<18} {side:<8} {v:14.4e} {m:10.3e} {se:8.1e} {b:9.1e}")
            (vp, mp, sp, _), (vm, mm, sm, _) = rows["pathlab"], rows["mitsuba"]
            r = mp / mm
            r_se = r * ((sp / mp) ** 2 + (sm / mm) ** 2) ** 0.5
            print(f"{name:<18} pathlab/Mitsuba: per-sample variance {vp / vm:.3f},"
                  f" net MSE {r:.3f} ± {r_se:.3f};"
                  f" equal-time RMSE 0.6 needs {r / 0.36:.2f}× Mitsuba's samples/s", flush=True)


if __name__ == "__main__":
    main()
