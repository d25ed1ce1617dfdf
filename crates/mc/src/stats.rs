//! Statistical tests for Monte Carlo code: is a sampler's output distributed as its `pdf` says,
//! and does an estimate agree with the truth within its error?
//!
//! - [`chi2_test_2d`] / [`chi2_test_1d`]: Pearson's chi-square goodness-of-fit test of samples
//!   against a density, over a grid of bins. The expected count of each bin is the density
//!   integrated over the bin (Gauss–Legendre quadrature) times the number of samples; the mass
//!   outside the grid forms one more cell, so a density that does not integrate to one is
//!   caught too. Cells expecting fewer than [`MIN_EXPECTED`] samples are pooled, as the
//!   chi-square approximation needs; a sample in a cell of zero expectation fails outright.
//!   This is how pbrt-v4 and Mitsuba 3 test their warps and BSDFs.
//! - [`chi2_test_discrete`]: the same for counts of discrete outcomes.
//! - [`z_test`] and [`z_test_two_sample`]: is an estimate within its standard error of a known
//!   value, or of another independent estimate?
//! - [`f_test_variance_ratio`]: is one estimator's variance smaller than another's?
//! - [`bonferroni`]: the per-test significance level that keeps the chance of any false alarm
//!   in a suite of `m` tests at most `alpha`.
//!
//! ```
//! use pathlab_mc::rng::Pcg32;
//! use pathlab_mc::stats::chi2_test_2d;
//! let mut rng = Pcg32::new(1, 2);
//! let pts: Vec<[f64; 2]> = (0..20_000).map(|_| [rng.uniform_f64(), rng.uniform_f64()]).collect();
//! let t = chi2_test_2d(pts, |_, _| 1.0, [[0.0, 1.0], [0.0, 1.0]], [10, 10]);
//! assert!(t.p_value > 1e-4, "{t:?}");
//! ```

use statrs::distribution::{ChiSquared, ContinuousCDF, FisherSnedecor, Normal};

/// Cells expecting fewer samples than this are pooled before computing the statistic.
pub const MIN_EXPECTED: f64 = 5.0;

/// Pieces per axis and bin of the quadrature that integrates the density over a bin.
const QUADRATURE_SUBDIVISIONS: usize = 4;

/// The outcome of a chi-square goodness-of-fit test.
#[derive(Clone, Debug, PartialEq)]
pub struct ChiSquareTest {
    /// Pearson's statistic Σ (observed - expected)² / expected over the pooled cells.
    pub statistic: f64,
    /// Degrees of freedom: cells after pooling, minus one.
    pub dof: usize,
    /// Probability of a statistic at least this large if the samples follow the density.
    /// Zero when a sample fell where the density is zero.
    pub p_value: f64,
    /// Number of samples tested.
    pub samples: u64,
    /// Number of cells before pooling (bins, plus the outside cell when it is used).
    pub cells: usize,
    /// Samples that fell in a cell whose expected count is (numerically) zero.
    pub impossible_samples: u64,
}

impl ChiSquareTest {
    /// Whether the test does *not* reject the density at significance level `alpha`.
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }
}

/// The per-test significance level for `m` tests so that the chance of any false rejection in
/// the whole suite is at most `alpha` (Bonferroni correction: `alpha / m`).
pub fn bonferroni(alpha: f64, m: usize) -> f64 {
    alpha / m.max(1) as f64
}

/// Chi-square test of 2D samples against the density `pdf(x, y)` (with respect to dx dy) over
/// the rectangle `domain = [[x0, x1], [y0, y1]]` cut into `res = [nx, ny]` bins (closed: a
/// sample on an upper edge counts in the last bin; samples outside count in a cell of their own
/// that expects the mass the density leaves out).
///
/// To test directions, map them to a parameterisation whose measure is the density's: for a
/// solid-angle pdf use `(cos θ, φ)`, since dω = d(cos θ) dφ.
pub fn chi2_test_2d(
    samples: impl IntoIterator<Item = [f64; 2]>,
    pdf: impl Fn(f64, f64) -> f64,
    domain: [[f64; 2]; 2],
    res: [usize; 2],
) -> ChiSquareTest {
    chi2_test_2d_with_quadrature(samples, pdf, domain, res, QUADRATURE_SUBDIVISIONS)
}

/// [`chi2_test_2d`] with each bin's expected mass integrated on `subdivisions`² pieces (4-point
/// Gauss–Legendre on each axis of each piece): more for densities with narrow peaks or
/// discontinuities inside bins, whose expected counts the default would get wrong.
pub fn chi2_test_2d_with_quadrature(
    samples: impl IntoIterator<Item = [f64; 2]>,
    pdf: impl Fn(f64, f64) -> f64,
    domain: [[f64; 2]; 2],
    res: [usize; 2],
    subdivisions: usize,
) -> ChiSquareTest {
    let grid = Chi2Grid {
        subdivisions,
        ..Chi2Grid::new(domain, res)
    };
    let masses = grid
        .bins()
        .map(|(xr, yr)| quadrature_2d(&pdf, xr, yr, subdivisions));
    grid.test_masses(samples, masses)
}

/// Chi-square test of 1D samples against the density `pdf(x)` over `[x0, x1]` in `bins` bins.
pub fn chi2_test_1d(
    samples: impl IntoIterator<Item = f64>,
    pdf: impl Fn(f64) -> f64,
    domain: [f64; 2],
    bins: usize,
) -> ChiSquareTest {
    chi2_test_2d(
        samples.into_iter().map(|x| [x, 0.5]),
        |x, _| pdf(x),
        [domain, [0.0, 1.0]],
        [bins, 1],
    )
}

/// Chi-square test of counts of discrete outcomes against their probabilities. `observed[i]`
/// is how often outcome `i` came up; `probabilities` should sum to one (any shortfall becomes
/// an extra cell that expects the missing mass and observed nothing).
pub fn chi2_test_discrete(observed: &[u64], probabilities: &[f64]) -> ChiSquareTest {
    let n: u64 = observed.iter().sum();
    let k = observed.len().max(probabilities.len());
    let mut obs: Vec<f64> = (0..k)
        .map(|i| observed.get(i).copied().unwrap_or(0) as f64)
        .collect();
    let mut exp: Vec<f64> = (0..k)
        .map(|i| probabilities.get(i).copied().unwrap_or(0.0) * n as f64)
        .collect();
    let total: f64 = probabilities.iter().sum();
    obs.push(0.0);
    exp.push((1.0 - total).max(0.0) * n as f64);
    chi2_from_cells(&obs, &exp, n)
}

/// Pools small cells, then computes Pearson's statistic and its p-value.
fn chi2_from_cells(observed: &[f64], expected: &[f64], n: u64) -> ChiSquareTest {
    // A cell whose expectation is a rounding error away from zero counts as impossible.
    let zero = 1e-9 * n as f64;
    let mut impossible = 0u64;
    let mut cells: Vec<(f64, f64)> = Vec::with_capacity(observed.len());
    for (&o, &e) in observed.iter().zip(expected) {
        if e <= zero {
            impossible += o as u64;
        } else {
            cells.push((e, o));
        }
    }
    let cell_count = cells.len();
    if impossible > 0 {
        return ChiSquareTest {
            statistic: f64::INFINITY,
            dof: cell_count.saturating_sub(1),
            p_value: 0.0,
            samples: n,
            cells: cell_count,
            impossible_samples: impossible,
        };
    }
    // Pool the cells of smallest expectation until the pool reaches MIN_EXPECTED.
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut statistic = 0.0;
    let mut dof_cells = 0usize;
    let (mut pool_e, mut pool_o) = (0.0, 0.0);
    for &(e, o) in &cells {
        if e < MIN_EXPECTED || (pool_e > 0.0 && pool_e < MIN_EXPECTED) {
            pool_e += e;
            pool_o += o;
        } else {
            statistic += (o - e) * (o - e) / e;
            dof_cells += 1;
        }
    }
    if pool_e > 0.0 {
        statistic += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof_cells += 1;
    }
    let dof = dof_cells.saturating_sub(1);
    let p_value = if dof == 0 {
        1.0
    } else {
        ChiSquared::new(dof as f64)
            .map(|d| d.sf(statistic))
            .unwrap_or(0.0)
    };
    ChiSquareTest {
        statistic,
        dof,
        p_value,
        samples: n,
        cells: cell_count,
        impossible_samples: 0,
    }
}

/// Gauss–Legendre nodes and weights of order 4 on [-1, 1].
const GAUSS_NODES: [f64; 4] = [
    -0.861_136_311_594_052_6,
    -0.339_981_043_584_856_3,
    0.339_981_043_584_856_3,
    0.861_136_311_594_052_6,
];
const GAUSS_WEIGHTS: [f64; 4] = [
    0.347_854_845_137_453_8,
    0.652_145_154_862_546_1,
    0.652_145_154_862_546_1,
    0.347_854_845_137_453_8,
];

/// ∫∫ f over a rectangle: each axis cut into [`QUADRATURE_SUBDIVISIONS`] pieces with a
/// 4-point Gauss–Legendre rule on each. Exact for polynomials of degree 7 per axis, and no node
/// lies on an edge, so a density that jumps at bin edges (piecewise-constant ones) is
/// integrated exactly when its pieces align with the bins.
fn quadrature_2d(
    f: &impl Fn(f64, f64) -> f64,
    xr: [f64; 2],
    yr: [f64; 2],
    subdivisions: usize,
) -> f64 {
    let mut sum = 0.0;
    let scale = quadrature_nodes(xr, yr, subdivisions, |x, y, w| sum += w * f(x, y));
    sum * scale
}

/// Visits the nodes of [`quadrature_2d`]'s rule over a rectangle, in its order, as
/// `node(x, y, weight)`; returns the factor the weighted sum is multiplied by.
fn quadrature_nodes(
    xr: [f64; 2],
    yr: [f64; 2],
    subdivisions: usize,
    mut node: impl FnMut(f64, f64, f64),
) -> f64 {
    let m = subdivisions.max(1);
    let (hx, hy) = ((xr[1] - xr[0]) / m as f64, (yr[1] - yr[0]) / m as f64);
    for j in 0..m {
        let cy = yr[0] + (j as f64 + 0.5) * hy;
        for (ny, wy) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
            let y = cy + 0.5 * hy * ny;
            for i in 0..m {
                let cx = xr[0] + (i as f64 + 0.5) * hx;
                for (nx, wx) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                    node(cx + 0.5 * hx * nx, y, wx * wy);
                }
            }
        }
    }
    0.25 * hx * hy
}

/// [`chi2_test_2d`] for a density evaluated many points at a time (a vectorised function in
/// another language, a GPU kernel): [`Chi2Grid::nodes`] lists the points where the density is
/// needed, and [`Chi2Grid::test`] takes its values there. The result is the same as
/// [`chi2_test_2d_with_quadrature`]'s for the same density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Grid {
    /// `[[x0, x1], [y0, y1]]`.
    pub domain: [[f64; 2]; 2],
    /// Bins per axis.
    pub res: [usize; 2],
    /// Quadrature pieces per axis and bin.
    pub subdivisions: usize,
}

impl Chi2Grid {
    /// The grid [`chi2_test_2d`] uses for `domain` and `res`.
    pub fn new(domain: [[f64; 2]; 2], res: [usize; 2]) -> Self {
        Chi2Grid {
            domain,
            res: [res[0].max(1), res[1].max(1)],
            subdivisions: QUADRATURE_SUBDIVISIONS,
        }
    }

    /// Each bin's rectangle, row by row.
    fn bins(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2])> {
        let [nx, ny] = self.res;
        let [[x0, x1], [y0, y1]] = self.domain;
        let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        (0..ny).flat_map(move |iy| {
            (0..nx).map(move |ix| {
                let (bx, by) = (x0 + ix as f64 * dx, y0 + iy as f64 * dy);
                ([bx, bx + dx], [by, by + dy])
            })
        })
    }

    /// The points where the density is needed, bin by bin.
    pub fn nodes(&self) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        for (xr, yr) in self.bins() {
            quadrature_nodes(xr, yr, self.subdivisions, |x, y, _| out.push([x, y]));
        }
        out
    }

    /// The test of `samples` against the density whose values at [`Chi2Grid::nodes`] are
    /// `pdf_at_nodes` (`None` if their number is not the nodes').
    pub fn test(
        &self,
        samples: impl IntoIterator<Item = [f64; 2]>,
        pdf_at_nodes: &[f64],
    ) -> Option<ChiSquareTest> {
        let per_bin = (4 * self.subdivisions.max(1)).pow(2);
        let bins = self.res[0] * self.res[1];
        if pdf_at_nodes.len() != bins * per_bin {
            return None;
        }
        let masses = self
            .bins()
            .zip(pdf_at_nodes.chunks(per_bin))
            .map(|((xr, yr), values)| {
                let mut k = 0;
                let mut sum = 0.0;
                let scale = quadrature_nodes(xr, yr, self.subdivisions, |_, _, w| {
                    sum += w * values[k];
                    k += 1;
                });
                sum * scale
            });
        Some(self.test_masses(samples, masses))
    }

    /// The test of `samples` against the bins' probabilities `masses` (row by row).
    fn test_masses(
        &self,
        samples: impl IntoIterator<Item = [f64; 2]>,
        masses: impl Iterator<Item = f64>,
    ) -> ChiSquareTest {
        let [nx, ny] = self.res;
        let [[x0, x1], [y0, y1]] = self.domain;
        let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        let mut observed = vec![0.0f64; nx * ny + 1];
        let mut n = 0u64;
        for [x, y] in samples {
            n += 1;
            // The domain is closed: a sample on its upper edge (cos θ = 1, a direction along
            // the axis, which rounding does give) falls in the last bin.
            let inside = x >= x0 && x <= x1 && y >= y0 && y <= y1;
            let cell = if inside {
                let ix = (((x - x0) / dx) as usize).min(nx - 1);
                let iy = (((y - y0) / dy) as usize).min(ny - 1);
                iy * nx + ix
            } else {
                nx * ny
            };
            observed[cell] += 1.0;
        }
        let mut expected = vec![0.0f64; nx * ny + 1];
        let mut total = 0.0;
        for (e, mass) in expected.iter_mut().zip(masses) {
            *e = mass * n as f64;
            total += mass;
        }
        expected[nx * ny] = (1.0 - total).max(0.0) * n as f64;
        chi2_from_cells(&observed, &expected, n)
    }
}

/// The azimuth atan2(y, x), in [0, 2π).
#[inline]
pub fn azimuth(y: f64, x: f64) -> f64 {
    let phi = y.atan2(x);
    if phi < 0.0 {
        phi + std::f64::consts::TAU
    } else {
        phi
    }
}

/// (cos θ, φ) of a unit direction `[x, y, z]`: the parameterisation in which a density per unit
/// solid angle is a density per unit area (dω = d(cos θ) dφ), for chi-square tests of
/// directions.
#[inline]
pub fn cos_theta_phi(d: [f64; 3]) -> [f64; 2] {
    [d[2], azimuth(d[1], d[0])]
}

/// The outcome of a z-test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZTest {
    /// The standardised difference.
    pub z: f64,
    /// Two-sided p-value, P(|Z| ≥ |z|) for a standard normal Z.
    pub p_value: f64,
}

impl ZTest {
    /// Whether |z| ≤ `max_abs_z`.
    pub fn within(&self, max_abs_z: f64) -> bool {
        self.z.abs() <= max_abs_z
    }
}

fn z_from(diff: f64, se: f64) -> ZTest {
    let z = if se > 0.0 {
        diff / se
    } else if diff == 0.0 {
        0.0
    } else {
        f64::INFINITY.copysign(diff)
    };
    let p_value = if z.is_finite() {
        2.0 * Normal::standard().sf(z.abs())
    } else {
        0.0
    };
    ZTest { z, p_value }
}

/// z = (estimate - truth) / std_error: is an estimate consistent with a known value?
pub fn z_test(estimate: f64, std_error: f64, truth: f64) -> ZTest {
    z_from(estimate - truth, std_error)
}

/// z = (a - b) / √(se_a² + se_b²): are two independent estimates of one quantity consistent?
pub fn z_test_two_sample(a: f64, se_a: f64, b: f64, se_b: f64) -> ZTest {
    z_from(a - b, (se_a * se_a + se_b * se_b).sqrt())
}

/// One-sided F-test that the variance behind the estimate `var_a` (with `dof_a` degrees of
/// freedom) exceeds the one behind `var_b` (with `dof_b`). Returns the p-value of the ratio
/// `var_a / var_b` under the hypothesis that both variances are equal (for variances estimated
/// from roughly normal values: `n - 1` degrees of freedom for a sample variance around the
/// sample mean, `n` for a mean square around a known value).
pub fn f_test_variance_ratio(var_a: f64, dof_a: u64, var_b: f64, dof_b: u64) -> f64 {
    if dof_a == 0 || dof_b == 0 {
        return 1.0;
    }
    if var_b <= 0.0 {
        return if var_a > 0.0 { 0.0 } else { 1.0 };
    }
    FisherSnedecor::new(dof_a as f64, dof_b as f64)
        .map(|f| f.sf(var_a / var_b))
        .unwrap_or(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_is_exact_for_polynomials() {
        let v = quadrature_2d(&|x, y| x.powi(7) + y * y + 1.0, [0.0, 2.0], [1.0, 3.0], 4);
        // ∫0^2∫1^3 (x⁷ + y² + 1) dy dx = 2·2⁸/8 + 2·26/3 + 4
        let exact = 64.0 + 52.0 / 3.0 + 4.0;
        assert!((v - exact).abs() < 1e-10);
    }

    #[test]
    fn a_tabulated_density_gives_the_streamed_test_to_the_bit() {
        let mut rng = crate::rng::Pcg32::new(7, 3);
        let pts: Vec<[f64; 2]> = (0..5_000)
            .map(|_| {
                let x = rng.uniform_f64().sqrt();
                [x * 2.0 - 0.5, rng.uniform_f64() * 3.0]
            })
            .collect();
        let pdf = |x: f64, y: f64| if y < 3.0 { (x + 0.5) / 6.0 } else { 0.0 };
        let domain = [[-0.5, 1.5], [0.0, 3.0]];
        let streamed = chi2_test_2d(pts.iter().copied(), pdf, domain, [12, 7]);
        let grid = Chi2Grid::new(domain, [12, 7]);
        let values: Vec<f64> = grid.nodes().iter().map(|p| pdf(p[0], p[1])).collect();
        assert_eq!(
            grid.test(pts.iter().copied(), &values),
            Some(streamed.clone())
        );
        assert!(streamed.p_value > 1e-4, "{streamed:?}");
        // A density of the wrong shape is told apart, and too few values are refused.
        let wrong: Vec<f64> = grid.nodes().iter().map(|_| 1.0 / 6.0).collect();
        assert!(grid.test(pts.iter().copied(), &wrong).unwrap().p_value < 1e-6);
        assert_eq!(grid.test(pts.iter().copied(), &values[1..]), None);
    }

    #[test]
    fn impossible_samples_fail() {
        let t = chi2_test_1d(
            [0.1, 0.2, 0.9],
            |x| if x < 0.5 { 2.0 } else { 0.0 },
            [0.0, 1.0],
            10,
        );
        assert_eq!(t.impossible_samples, 1);
        assert_eq!(t.p_value, 0.0);
    }

    #[test]
    fn z_test_values() {
        let t = z_test(1.0 + 1.96, 1.0, 1.0);
        assert!((t.p_value - 0.05).abs() < 1e-3);
        assert!(z_test_two_sample(1.0, 0.3, 1.0, 0.4).z.abs() < 1e-15);
        assert_eq!(z_test(1.0, 0.0, 1.0).z, 0.0);
        assert!(!z_test(1.1, 0.0, 1.0).within(4.0));
    }

    #[test]
    fn f_test_detects_a_large_ratio() {
        assert!(f_test_variance_ratio(10.0, 29, 1.0, 29) < 1e-6);
        assert!(f_test_variance_ratio(1.0, 29, 1.0, 29) > 0.4);
    }
}
