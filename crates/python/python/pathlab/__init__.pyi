"""Type stubs of the `pathlab` package (its Rust extension module re-exported)."""

from os import PathLike
from typing import Callable, Iterator, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
Vec3 = Tuple[float, float, float]

class SceneError(Exception):
    """A scene could not be read or built: the message names the file, the line and what was
    expected."""

class Image(np.ndarray):
    """A float32 array of linear radiance that a notebook displays (``_repr_png_``)."""

    exposure: float
    def _repr_png_(self) -> Optional[bytes]: ...

class Scene:
    """A scene read from a file or a built-in name."""

    @property
    def source(self) -> str: ...
    resolution: Tuple[int, int]
    """The image size (width, height) renders use unless told otherwise."""
    camera: dict
    """origin, target, up (tuples), fov (degrees), lens_radius, focal_distance; assign a dict
    with any of these keys to change them."""
    @property
    def spp(self) -> Optional[int]: ...
    @property
    def warnings(self) -> list[str]: ...
    def info(self) -> dict:
        """Counts of meshes, triangles, spheres; materials and lights by kind; the camera,
        resolution and bounds."""

def load(source: Union[str, PathLike], **params: object) -> Scene:
    """Load a scene: a built-in name (``"cornell-box"``, ...) or a file (Mitsuba XML, pbrt-v4,
    COLLADA, OBJ, PLY, glTF). ``params`` fill a Mitsuba file's ``$name`` defaults, as
    ``pathlab render -D name=value`` does. Raises SceneError with the file, line and what was
    expected."""

IntegratorName = Literal["path", "bdpt", "direct", "normals", "depth", "bvh"]
DirectName = Literal["hemisphere", "cosine", "light", "mis"]
SamplerName = Literal["independent", "stratified", "sobol"]
LightingName = Literal["mis", "bsdf", "light"]

@overload
def render(
    scene: Scene,
    spp: Optional[int] = ...,
    seed: int = ...,
    max_depth: Optional[int] = ...,
    integrator: Optional[IntegratorName] = ...,
    direct: Optional[DirectName] = ...,
    sampler: Optional[SamplerName] = ...,
    resolution: Optional[Tuple[int, int]] = ...,
    threads: int = ...,
    aovs: Tuple[()] = ...,
    lighting: Optional[LightingName] = ...,
) -> Image: ...
@overload
def render(
    scene: Scene,
    spp: Optional[int] = ...,
    seed: int = ...,
    max_depth: Optional[int] = ...,
    integrator: Optional[IntegratorName] = ...,
    direct: Optional[DirectName] = ...,
    sampler: Optional[SamplerName] = ...,
    resolution: Optional[Tuple[int, int]] = ...,
    threads: int = ...,
    aovs: Sequence[str] = ...,
    lighting: Optional[LightingName] = ...,
) -> dict[str, np.ndarray]: ...
def read(path: Union[str, PathLike]) -> Image:
    """An image (EXR, PNG, JPEG, HDR, BMP) as float32 (H, W, 3) linear values."""

def write(
    path: Union[str, PathLike],
    image: ArrayLike,
    exposure: float = 0.0,
    tonemap: Literal["srgb", "cs184"] = "srgb",
) -> None:
    """Write (H, W, 3) or (H, W) linear values: OpenEXR for .exr, else an 8-bit PNG after
    2^exposure and the tone map (srgb, or cs184: the course's renderer's)."""

def png_bytes(
    image: ArrayLike, exposure: float = 0.0, tonemap: Literal["srgb", "cs184"] = "srgb"
) -> bytes:
    """The image as the bytes of an 8-bit PNG file (exposure and tone map as write's)."""

def uniform_points(n: int, dims: int, sampler: SamplerName = ..., seed: int = ...) -> F64:
    """n points (n, dims) of [0, 1)^dims from the sampler: point i is its sample i."""

def sample_uniform_disk_concentric(u: ArrayLike) -> F64: ...
def uniform_disk_pdf(p: ArrayLike) -> F64: ...
def sample_uniform_hemisphere(u: ArrayLike) -> F64: ...
def uniform_hemisphere_pdf(w: ArrayLike) -> F64: ...
def sample_cosine_hemisphere(u: ArrayLike) -> F64: ...
def cosine_hemisphere_pdf(w: ArrayLike) -> F64: ...
def sample_uniform_sphere(u: ArrayLike) -> F64: ...
def uniform_sphere_pdf(w: ArrayLike) -> F64: ...
def sample_uniform_cone(u: ArrayLike, cos_theta_max: float) -> F64: ...
def uniform_cone_pdf(w: ArrayLike, cos_theta_max: float) -> F64: ...
def sample_uniform_triangle(u: ArrayLike) -> F64: ...

class Exponential:
    """Rate λ, sampled by inversion: x = -ln(1 - U)/λ."""

    def __init__(self, lam: float) -> None: ...
    @property
    def lam(self) -> float: ...
    @property
    def mean(self) -> float: ...
    @property
    def variance(self) -> float: ...
    def sample(self, u: ArrayLike) -> F64: ...
    def pdf(self, x: ArrayLike) -> F64: ...
    def cdf(self, x: ArrayLike) -> F64: ...

class Piecewise1D:
    def __init__(self, weights: ArrayLike, lo: float = 0.0, hi: float = 1.0) -> None: ...
    @property
    def integral(self) -> float: ...
    @property
    def domain(self) -> Tuple[float, float]: ...
    def sample(self, u: ArrayLike) -> F64: ...
    def pdf(self, x: ArrayLike) -> F64: ...

class Piecewise2D:
    def __init__(
        self,
        weights: ArrayLike,
        domain: Tuple[Tuple[float, float], Tuple[float, float]] = ((0.0, 1.0), (0.0, 1.0)),
    ) -> None: ...
    @property
    def integral(self) -> float: ...
    def sample(self, u: ArrayLike) -> F64: ...
    def pdf(self, p: ArrayLike) -> F64: ...

class AliasTable:
    def __init__(self, weights: ArrayLike) -> None: ...
    def __len__(self) -> int: ...
    def sample(self, u: ArrayLike) -> npt.NDArray[np.int64]: ...
    def pmf(self, i: ArrayLike) -> F64: ...

class Estimate:
    mean: float
    std_error: float
    variance: float
    n: int
    ci95: Tuple[float, float]
    @property
    def relative_error(self) -> float: ...
    def __float__(self) -> float: ...

def integrate(
    f: Callable[[F64], ArrayLike],
    domain: Union[Tuple[float, float], Sequence[Tuple[float, float]]],
    n: int,
    sampler: SamplerName = ...,
    seed: int = ...,
    replicates: int = ...,
) -> Estimate:
    """F_N = 1/N Σ f(X_i)/p(X_i) with X_i uniform in the box; f takes an (n, d) array and
    returns n values. Stratified and Sobol samples get their error from `replicates`
    independent randomisations."""

class ChiSquareTest:
    statistic: float
    p_value: float
    dof: int
    samples: int
    impossible_samples: int
    def passes(self, alpha: float = 0.01) -> bool: ...
    def __iter__(self) -> Iterator[float]: ...

def chi2_test(
    samples: ArrayLike,
    pdf: Union[Callable[[F64], ArrayLike], ArrayLike],
    domain: Optional[object] = None,
    bins: Optional[Union[int, Tuple[int, int]]] = None,
) -> ChiSquareTest:
    """Pearson's test of samples against a density: (n,) numbers on domain (lo, hi), (n, 2)
    points on ((x0, x1), (y0, y1)), (n, 3) directions against a solid-angle pdf, or integer
    outcomes against an array of probabilities."""
