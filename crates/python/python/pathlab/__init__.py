"""pathlab: a physically based Monte Carlo renderer and Monte Carlo toolkit, with numpy in and out.

Render a scene::

    import pathlab
    scene = pathlab.load("cornell-box")              # a built-in scene, or any file pathlab reads
    image = pathlab.render(scene, spp=64, seed=0)    # float32 array (H, W, 3) of linear radiance
    pathlab.write("box.png", image)

and the toolkit the renderer is built on: samplers (`uniform_points`), warps with their pdfs
(`sample_cosine_hemisphere`, `cosine_hemisphere_pdf`, ...), distributions (`Exponential`,
`Piecewise1D`, `Piecewise2D`, `AliasTable`), the estimator `integrate` and the goodness-of-fit
test `chi2_test`.
"""

import numpy as _np

from . import _pathlab
from ._pathlab import (  # noqa: F401  (re-exported)
    AliasTable,
    ChiSquareTest,
    Estimate,
    Exponential,
    Piecewise1D,
    Piecewise2D,
    Scene,
    SceneError,
    __version__,
    chi2_test,
    cosine_hemisphere_pdf,
    integrate,
    load,
    png_bytes,
    sample_cosine_hemisphere,
    sample_uniform_cone,
    sample_uniform_disk_concentric,
    sample_uniform_hemisphere,
    sample_uniform_sphere,
    sample_uniform_triangle,
    uniform_cone_pdf,
    uniform_disk_pdf,
    uniform_hemisphere_pdf,
    uniform_points,
    uniform_sphere_pdf,
    write,
)

__all__ = [
    "AliasTable", "ChiSquareTest", "Estimate", "Exponential", "Image", "Piecewise1D",
    "Piecewise2D", "Scene", "SceneError", "chi2_test", "cosine_hemisphere_pdf", "integrate",
    "load", "png_bytes", "read", "render", "sample_cosine_hemisphere", "sample_uniform_cone",
    "sample_uniform_disk_concentric", "sample_uniform_hemisphere", "sample_uniform_sphere",
    "sample_uniform_triangle", "uniform_cone_pdf", "uniform_disk_pdf", "uniform_hemisphere_pdf",
    "uniform_points", "uniform_sphere_pdf", "write",
]


class Image(_np.ndarray):
    """A numpy array of linear radiance, shape (H, W, 3) (or (H, W)), that a notebook shows.

    It is an ordinary ``numpy.ndarray`` (a view of the render's buffer, not a copy); only its
    ``_repr_png_`` is added, which Jupyter calls to display it as an sRGB PNG. Set
    ``exposure`` (stops) to brighten or darken the display.
    """

    exposure = 0.0

    def __array_wrap__(self, obj, *args, **kwargs):
        # A reduction to one number (image.mean()) gives a number, not a 0-d Image.
        if obj.ndim == 0:
            return obj[()]
        return super().__array_wrap__(obj, *args, **kwargs)

    def _repr_png_(self):
        if self.ndim not in (2, 3) or (self.ndim == 3 and self.shape[2] != 3) or self.size == 0:
            return None
        return png_bytes(_np.asarray(self), exposure=float(self.exposure))


def _image(array):
    return array.view(Image)


def render(scene, spp=None, seed=0, max_depth=None, integrator=None, direct=None, sampler=None,
           resolution=None, threads=0, aovs=(), lighting=None):
    """Render ``scene`` and return its linear radiance as a float32 array (H, W, 3).

    Arguments left as ``None`` take the scene file's setting, then pathlab's default:

    - ``spp``: samples per pixel (the file's, else 64);
    - ``seed``: the seed of every pixel's random numbers (same seed, same image, for any
      thread count);
    - ``max_depth``: the longest path in bounces (the file's, else unbounded with Russian
      roulette);
    - ``integrator``: ``"path"`` (default), ``"direct"``, or the debug views ``"normals"``,
      ``"depth"``, ``"bvh"``;
    - ``direct``: with ``integrator="direct"``, the strategy ``"hemisphere"``, ``"cosine"``,
      ``"light"`` or ``"mis"`` (default);
    - ``lighting``: how the path tracer finds light at each vertex: ``"mis"`` (light and BSDF
      sampling combined, default), ``"bsdf"`` (BSDF sampling only) or ``"light"`` (light
      sampling only);
    - ``sampler``: ``"independent"``, ``"stratified"`` or ``"sobol"`` (the file's, else sobol);
    - ``resolution``: ``(width, height)`` for this render (else ``scene.resolution``);
    - ``threads``: worker threads (0: every core);
    - ``aovs``: extra outputs; when given, a dict is returned with ``"image"`` and each of
      ``"variance"`` (each pixel's variance of its mean, (H, W, 3); an honest squared standard
      error with the independent sampler), ``"samples"`` (samples per pixel, (H, W)) and
      ``"bounce:K"`` (the light that arrives after exactly K bounces, rendered with the same
      seed; the path tracer only).

    The GIL is released while rendering. Ctrl-C (KeyboardInterrupt) stops the render within a
    fraction of a second and raises.
    """
    out = _pathlab.render(scene, spp=spp, seed=seed, max_depth=max_depth, integrator=integrator,
                          direct=direct, lighting=lighting, sampler=sampler,
                          resolution=resolution, threads=threads,
                          aovs=[aovs] if isinstance(aovs, str) else list(aovs))
    if isinstance(out, dict):
        return {k: (_image(v) if k == "image" or k.startswith("bounce:") else v)
                for k, v in out.items()}
    return _image(out)


def read(path):
    """Read an image (OpenEXR, PNG, JPEG, HDR, BMP) as a float32 array (H, W, 3) of linear
    values; 8-bit formats are decoded from sRGB."""
    return _image(_pathlab.read(path))
