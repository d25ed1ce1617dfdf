"""The course worksheet in Python, cell by cell (open it as a notebook with Jupytext or VS Code's
`# %%` cells, or run it: `python examples/notebook.py [--quick] [--out DIR]`).

1. Inversion sampling: x = -ln(1 - U)/λ draws the exponential distribution; its histogram
   against the pdf, and the chi-square test.
2. The estimator F_N = 16/N Σ f(X_i) of ∫∫ exp(-(x² + y²)/2) over [-2, 2]², with its standard
   error shrinking as 1/√N, for independent and Sobol points.
3. Direct lighting on the Cornell box by uniform hemisphere, cosine and light sampling: the
   same mean, very different variances.
"""

# %%
import argparse
import math
import sys
from pathlib import Path

import numpy as np

import pathlab

parser = argparse.ArgumentParser()
parser.add_argument("--quick", action="store_true", help="small sizes (for a test run)")
parser.add_argument("--out", default="worksheet", help="where the images go")
args, _ = parser.parse_known_args(sys.argv[1:])
out = Path(args.out)
out.mkdir(exist_ok=True)

# %% [markdown]
# ## 1. Inversion sampling of the exponential

# %%
lam = 2.0
exp = pathlab.Exponential(lam)
u = pathlab.uniform_points(10_000 if args.quick else 100_000, 1, seed=1)[:, 0]
x = exp.sample(u)  # = -ln(1 - u) / λ
counts, edges = np.histogram(x, bins=12, range=(0, 3))
width = edges[1] - edges[0]
print(f"exponential, λ = {lam}: {len(x)} samples, mean {x.mean():.4f} (exact {exp.mean})")
for c, lo in zip(counts, edges):
    expected = len(x) * (exp.cdf([lo + width])[0] - exp.cdf([lo])[0])
    print(f"  [{lo:4.2f}, {lo + width:4.2f})  {'#' * int(60 * c / counts.max()):<60} {c:6d}  (pdf says {expected:8.1f})")
test = pathlab.chi2_test(x, exp.pdf, domain=(0, 4))
print(f"  chi-square against the pdf: {test}")

# %% [markdown]
# ## 2. F_N = 16/N Σ f(X_i) over [-2, 2]²

# %%
exact = 2 * math.pi * math.erf(2 / math.sqrt(2)) ** 2


def f(p):
    return np.exp(-(p**2).sum(axis=1) / 2)


print(f"\n∫∫ exp(-(x² + y²)/2) over [-2, 2]², exact {exact:.6f}")
print(f"  {'N':>8}  {'independent':>22}  {'sobol (16 replicates)':>24}")
for k in range(2, 6 if args.quick else 7):
    n = 10**k
    a = pathlab.integrate(f, [(-2, 2), (-2, 2)], n, seed=k)
    b = pathlab.integrate(f, [(-2, 2), (-2, 2)], n, sampler="sobol", seed=k)
    print(f"  {n:>8}  {a.mean:10.6f} ± {a.std_error:.6f}  {b.mean:12.6f} ± {b.std_error:.6f}")

# %% [markdown]
# ## 3. Hemisphere, cosine and light sampling on the Cornell box

# %%
box = pathlab.load("cornell-box")
spp = 4 if args.quick else 16
size = (64, 64) if args.quick else (256, 256)
print(f"\nCornell box, direct lighting, {spp} samples per pixel, {size[0]}x{size[1]}")
for strategy in ("hemisphere", "cosine", "light"):
    r = pathlab.render(box, spp=spp, seed=1, integrator="direct", direct=strategy,
                       sampler="independent", resolution=size, aovs=("variance",))
    image, variance = r["image"], r["variance"]
    pixels = image.shape[0] * image.shape[1]
    se = math.sqrt(variance.astype(np.float64).sum() / 3) / pixels
    print(f"  {strategy:>10}: image mean {image.mean():.4f} ± {se:.4f}, "
          f"mean variance of one sample {variance.mean() * spp:.4f}")
    pathlab.write(out / f"direct-{strategy}.png", image)
print(f"  images in {out}/")
