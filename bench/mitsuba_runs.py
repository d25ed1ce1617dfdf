"""What bench/mitsuba_bench.py and bench/scenes.py share: Mitsuba's variant, its timed renders
in processes of their own, and the RMSE of an image against a reference.

Run as a script (`python3 bench/mitsuba_runs.py VARIANT SCENE MAX_DEPTH SPP OUT.npy`) it is
one timed render: the first render compiles the kernels and is not timed; it prints the
seconds of the second and saves its image. Each Mitsuba measurement runs so, in a process
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


def render(variant, scene, max_depth, spp):
    """One timed Mitsuba render in a process of its own: (seconds, image)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "img.npy")
        cmd = [sys.executable, __file__, variant, scene, str(max_depth), str(spp), out]
        seconds = float(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        return seconds, np.load(out)


def rmse(img, ref):
    return float(np.sqrt(np.mean((np.asarray(img, dtype=np.float64)[..., :3] - ref) ** 2)))


if __name__ == "__main__":
    _, variant, scene_path, max_depth, spp, out = sys.argv
    mi.set_variant(variant)
    scene = mi.load_file(scene_path, spp=int(spp), max_depth=int(max_depth))
    # Seeds far from the small ones the reference images' 16 runs may have used, so that the
    # timed image is not one of the runs its error is measured against.
    mi.render(scene, spp=int(spp), seed=1_000_001)  # compiles the kernels
    start = time.perf_counter()
    img = np.array(mi.render(scene, spp=int(spp), seed=1_000_002))
    print(time.perf_counter() - start)
    np.save(out, img)
