"""The Monte Carlo toolkit on numpy arrays: the warps and distributions pass the chi-square
test against their own pdfs (and a wrong pdf is rejected), samplers' points, and the estimator
`integrate` against known integrals."""

import math

import numpy as np
import pytest

import pathlab

N = 40_000
# Significance of each test that should pass: with ~15 of them, a false alarm has a chance of
# about 1.5e-4 per run.
ALPHA = 1e-5


def u2(seed=1, n=N):
    return pathlab.uniform_points(n, 2, seed=seed)


WARPS = [
    ("hemisphere", pathlab.sample_uniform_hemisphere, pathlab.uniform_hemisphere_pdf),
    ("cosine", pathlab.sample_cosine_hemisphere, pathlab.cosine_hemisphere_pdf),
    ("sphere", pathlab.sample_uniform_sphere, pathlab.uniform_sphere_pdf),
    (
        "cone",
        # cos θmax = 0.5 lies on a bin edge (32 bins over [-1, 1]): the quadrature integrates a
        # density that jumps inside a bin only approximately.
        lambda u: pathlab.sample_uniform_cone(u, 0.5),
        lambda w: pathlab.uniform_cone_pdf(w, 0.5),
    ),
]


@pytest.mark.parametrize("name, sample, pdf", WARPS, ids=[w[0] for w in WARPS])
def test_direction_warps_pass_the_chi_square_test_against_their_pdfs(name, sample, pdf):
    w = sample(u2())
    assert w.shape == (N, 3)
    assert np.allclose(np.linalg.norm(w, axis=1), 1, atol=1e-5)
    t = pathlab.chi2_test(w, pdf)
    assert t.passes(ALPHA), t
    statistic, p_value = t
    assert (statistic, p_value) == (t.statistic, t.p_value)


def test_a_wrong_pdf_is_rejected():
    w = pathlab.sample_cosine_hemisphere(u2())
    assert pathlab.chi2_test(w, pathlab.uniform_hemisphere_pdf).p_value < 1e-9
    # Directions below the horizon, where the pdf is zero, fail outright.
    flipped = w * np.array([1, 1, -1])
    t = pathlab.chi2_test(flipped, pathlab.cosine_hemisphere_pdf)
    assert t.p_value == 0 and t.impossible_samples == N
    # A pdf that integrates to 2 leaves no mass for the outside cell: rejected.
    assert pathlab.chi2_test(w, lambda d: 2 * pathlab.cosine_hemisphere_pdf(d)).p_value < 1e-9


def test_the_disk_and_the_triangle_are_uniform():
    p = pathlab.sample_uniform_disk_concentric(u2(seed=2))
    t = pathlab.chi2_test(p, pathlab.uniform_disk_pdf, domain=((-1, 1), (-1, 1)), bins=(24, 24))
    assert t.passes(ALPHA), t
    b = pathlab.sample_uniform_triangle(u2(seed=3))
    assert np.allclose(b.sum(axis=1), 1)
    # (b0, b1) is uniform on the half of the unit square below the diagonal: density 2 there.
    t = pathlab.chi2_test(b[:, :2], lambda p: 2.0 * (p.sum(axis=1) <= 1), domain=((0, 1), (0, 1)))
    assert t.passes(ALPHA), t


def test_the_exponential_by_inversion():
    exp = pathlab.Exponential(2.0)
    u = pathlab.uniform_points(N, 1, seed=4)[:, 0]
    x = exp.sample(u)
    assert np.allclose(x, -np.log(1 - u) / 2.0)
    t = pathlab.chi2_test(x, exp.pdf, domain=(0, 4))
    assert t.passes(ALPHA), t
    assert abs(x.mean() - exp.mean) < 4 * math.sqrt(exp.variance / N)
    # Rate 1 is not rate 2.
    assert pathlab.chi2_test(x, pathlab.Exponential(1.0).pdf, domain=(0, 4)).p_value < 1e-9
    with pytest.raises(ValueError, match="outside"):
        exp.sample([0.5, 1.0])
    with pytest.raises(ValueError):
        pathlab.Exponential(-1.0)


def test_piecewise_densities_and_the_alias_table():
    weights = [1.0, 0.0, 3.0, 2.0]
    d = pathlab.Piecewise1D(weights, 0.0, 2.0)
    x = d.sample(pathlab.uniform_points(N, 1, seed=5)[:, 0])
    t = pathlab.chi2_test(x, d.pdf, domain=(0, 2), bins=16)
    assert t.passes(ALPHA), t
    grid = np.array([[1.0, 2.0, 0.5], [4.0, 0.0, 1.0]])
    d2 = pathlab.Piecewise2D(grid)
    p = d2.sample(u2(seed=6))
    t = pathlab.chi2_test(p, d2.pdf, domain=((0, 1), (0, 1)), bins=(6, 4))
    assert t.passes(ALPHA), t
    alias = pathlab.AliasTable(weights)
    i = alias.sample(pathlab.uniform_points(N, 1, seed=7)[:, 0])
    assert i.dtype == np.int64 and len(alias) == 4
    pmf = alias.pmf(np.arange(4))
    assert np.allclose(pmf, np.array(weights) / 6)
    t = pathlab.chi2_test(i, pmf)
    assert t.passes(ALPHA), t
    assert pathlab.chi2_test(i, [0.25, 0.25, 0.25, 0.25]).p_value < 1e-9
    with pytest.raises(ValueError, match="positive sum"):
        pathlab.AliasTable([0.0, 0.0])
    with pytest.raises(ValueError, match="2D array"):
        pathlab.Piecewise2D([1.0, 2.0])


def test_sampler_points():
    for sampler in ("independent", "stratified", "sobol"):
        x = pathlab.uniform_points(1024, 3, sampler=sampler, seed=1)
        assert x.shape == (1024, 3)
        assert np.all((x >= 0) & (x < 1))
        assert np.array_equal(x, pathlab.uniform_points(1024, 3, sampler=sampler, seed=1))
    # Stratified and Sobol points put exactly n/16 points in each of 16 strips of a 1D
    # projection; independent ones do not.
    for sampler in ("stratified", "sobol"):
        counts = np.bincount((pathlab.uniform_points(1024, 2, sampler=sampler)[:, 0] * 16).astype(int))
        assert np.all(counts == 64), (sampler, counts)
    with pytest.raises(ValueError, match="unknown sampler"):
        pathlab.uniform_points(10, 2, sampler="halton")
    with pytest.raises(ValueError, match="n -5"):
        pathlab.uniform_points(-5, 2)


# The worksheet's integral: ∫∫ exp(-(x² + y²)/2) over [-2, 2]², estimated by 16/n Σ f(X_i).
GAUSS_EXACT = 2 * math.pi * math.erf(2 / math.sqrt(2)) ** 2


def gauss(p):
    return np.exp(-(p**2).sum(axis=1) / 2)


@pytest.mark.parametrize("sampler", ["independent", "stratified", "sobol"])
def test_integrate_finds_the_worksheet_gaussian_within_4_standard_errors(sampler):
    e = pathlab.integrate(gauss, [(-2, 2), (-2, 2)], 100_000, sampler=sampler, seed=11)
    assert e.n == 100_000
    assert abs(e.mean - GAUSS_EXACT) < 4 * e.std_error, e
    assert e.ci95[0] < e.mean < e.ci95[1]
    assert 0 < e.std_error < 0.02


def test_integrate_is_the_plain_estimator_on_the_sampler_points():
    x = pathlab.uniform_points(5000, 2, seed=3) * 4 - 2
    e = pathlab.integrate(gauss, [(-2, 2), (-2, 2)], 5000, seed=3)
    assert e.mean == pytest.approx(16 * gauss(x).mean(), rel=1e-12)
    assert e.std_error == pytest.approx(16 * gauss(x).std(ddof=1) / math.sqrt(5000), rel=1e-9)
    # Past one call's 2^20 points, the points are still the sampler's, in order.
    n = (1 << 20) + 5000
    x = pathlab.uniform_points(n, 1, sampler="sobol", seed=4)[:, 0]
    e = pathlab.integrate(lambda p: p[:, 0] ** 2, (0, 1), n, sampler="sobol", seed=4, replicates=1)
    assert e.mean == pytest.approx((x**2).mean(), rel=1e-12)
    # One interval for one dimension.
    assert float(pathlab.integrate(lambda p: p[:, 0], (0, 1), 1000)) == pytest.approx(0.5, abs=0.05)


def test_integrate_rejects_bad_input_and_warns_of_heavy_tails():
    with pytest.raises(ValueError, match="function"):
        pathlab.integrate(3.0, (0, 1), 10)
    with pytest.raises(ValueError, match="lo < hi"):
        pathlab.integrate(gauss, [(2, -2)], 10)
    with pytest.raises(ValueError, match="one value per point"):
        pathlab.integrate(lambda p: p, [(0, 1), (0, 1)], 10)
    with pytest.raises(ValueError, match="not finite|is inf|is nan"):
        with np.errstate(divide="ignore"):
            pathlab.integrate(lambda p: 1 / (p[:, 0] * 0), (0, 1), 10)
    with pytest.raises(ZeroDivisionError):
        pathlab.integrate(lambda p: 1 / 0, (0, 1), 10)
    with pytest.warns(UserWarning, match="heavy-tailed"):
        pathlab.integrate(lambda p: 1 / p[:, 0], (0, 1), 100_000)


def test_chi2_test_rejects_bad_input():
    w = pathlab.sample_uniform_sphere(u2(n=100))
    with pytest.raises(ValueError, match="shape"):
        pathlab.chi2_test(np.zeros((10, 4)), pathlab.uniform_sphere_pdf)
    with pytest.raises(ValueError, match="interval"):
        pathlab.chi2_test(np.zeros(10), lambda x: x)
    with pytest.raises(ValueError, match="one per point"):
        pathlab.chi2_test(w, lambda d: np.ones(3))
    with pytest.raises(ValueError, match="finite and >= 0"):
        pathlab.chi2_test(w, lambda d: -pathlab.uniform_sphere_pdf(d))
    with pytest.raises(ValueError, match="not one of"):
        pathlab.chi2_test([0, 1, 7], [0.5, 0.5])


def test_chi2_test_bins_suit_the_sample_count():
    # 2,000 uniform directions: the default bins leave cells to test, so a wrong pdf is caught.
    w = pathlab.sample_uniform_sphere(u2(seed=9, n=2000))
    t = pathlab.chi2_test(w, pathlab.uniform_sphere_pdf)
    assert t.dof > 10 and t.passes(ALPHA), t
    assert pathlab.chi2_test(w, lambda d: 3 * d[:, 2] ** 2 / (4 * np.pi)).p_value < 1e-6
    # Asked-for bins too fine for the samples: a warning, not a silent p-value of 1.
    with pytest.warns(UserWarning, match="says nothing"):
        pathlab.chi2_test(w[:50], pathlab.uniform_sphere_pdf, bins=(32, 64))
