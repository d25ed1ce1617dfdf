//! `integrate(f, domain, n)`: the estimator F_N = 1/N Σ f(X_i)/p(X_i) of a Python function
//! over a box, with a standard error valid for every sampler; and `chi2_test(samples, pdf)`:
//! Pearson's goodness-of-fit test of samples against a density, as the test suites of pathlab
//! run it.

use crate::arrays::{f64_array, positive_u32, value_error, values};
use crate::sampling::points;
use numpy::PyArrayMethods;
use pathlab_mc::estimator::{looks_heavy_tailed, replicate_estimate, RunningStats};
use pathlab_mc::sampler::SamplerKind;
use pathlab_mc::stats::{chi2_test_discrete, cos_theta_phi, Chi2Grid};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::f64::consts::TAU;

/// Points handed to the integrand per call.
const CHUNK: u32 = 1 << 20;

/// A Monte Carlo estimate with its uncertainty.
#[pyclass(module = "pathlab", frozen, get_all)]
#[derive(Clone)]
struct Estimate {
    /// The estimate F_N.
    mean: f64,
    /// Its standard error.
    std_error: f64,
    /// The variance of one term f/p (for stratified and Sobol samples: the replicates'
    /// variance scaled to one sample, to compare with independent samples).
    variance: f64,
    /// Samples drawn.
    n: u64,
    /// The two-sided 95% confidence interval.
    ci95: (f64, f64),
}

#[pymethods]
impl Estimate {
    /// The standard error relative to the estimate.
    #[getter]
    fn relative_error(&self) -> f64 {
        if self.std_error == 0.0 {
            0.0
        } else {
            self.std_error / self.mean.abs()
        }
    }

    fn __float__(&self) -> f64 {
        self.mean
    }

    fn __repr__(&self) -> String {
        format!(
            "Estimate({} ± {} (standard error), 95% CI [{}, {}], n={})",
            self.mean, self.std_error, self.ci95.0, self.ci95.1, self.n
        )
    }
}

impl From<pathlab_mc::estimator::Estimate> for Estimate {
    fn from(e: pathlab_mc::estimator::Estimate) -> Self {
        Estimate {
            mean: e.mean,
            std_error: e.std_error,
            variance: e.variance,
            n: e.n,
            ci95: e.ci95,
        }
    }
}

/// The box: `[(lo, hi), ...]`, or one `(lo, hi)` for an interval.
fn domain(d: &Bound<'_, PyAny>) -> PyResult<Vec<(f64, f64)>> {
    let intervals: Vec<(f64, f64)> = match d.extract::<(f64, f64)>() {
        Ok(one) => vec![one],
        Err(_) => d.extract().map_err(|_| {
            PyValueError::new_err("domain: expected (lo, hi) or a sequence of (lo, hi) pairs")
        })?,
    };
    if intervals.is_empty() || intervals.len() > 64 {
        return Err(PyValueError::new_err(format!(
            "domain: {} intervals; 1 to 64 dimensions are supported",
            intervals.len()
        )));
    }
    for (i, &(lo, hi)) in intervals.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(PyValueError::new_err(format!(
                "domain: interval {i} is ({lo}, {hi}); it needs finite bounds with lo < hi"
            )));
        }
    }
    Ok(intervals)
}

/// f/p of `n` points of `kind` with `seed`, uniform in the box (p = 1/volume), calling `f` on
/// at most [`CHUNK`] points at a time.
fn weighted_terms(
    f: &Bound<'_, PyAny>,
    box_: &[(f64, f64)],
    kind: SamplerKind,
    n: u32,
    seed: u64,
) -> PyResult<Vec<f64>> {
    let py = f.py();
    let d = box_.len();
    let volume: f64 = box_.iter().map(|(lo, hi)| hi - lo).product();
    let mut terms = Vec::with_capacity(n as usize);
    for start in (0..n).step_by(CHUNK as usize) {
        let indices = start..start.saturating_add(CHUNK).min(n);
        let m = indices.len();
        let chunk = py.detach(|| {
            let mut x = points(kind, n, d, seed, indices);
            for p in x.chunks_exact_mut(d) {
                for (xi, (lo, hi)) in p.iter_mut().zip(box_) {
                    *xi = lo + (hi - lo) * *xi;
                }
            }
            x
        });
        let array = numpy::ndarray::Array2::from_shape_vec((m, d), chunk)
            .expect("m points of d coordinates");
        let arg = numpy::IntoPyArray::into_pyarray(array, py);
        let out = f.call1((arg.clone(),))?;
        let a = f64_array(&out, "the integrand's values")?;
        let v = a.as_array();
        if v.len() != m || v.ndim() > 2 {
            return Err(PyValueError::new_err(format!(
                "the integrand returned shape {:?} for {m} points; it must return one value per point, shape ({m},)",
                v.shape()
            )));
        }
        for (k, &fx) in v.iter().enumerate() {
            if !fx.is_finite() {
                let point = arg.readonly();
                let at: Vec<String> = point
                    .as_array()
                    .row(k)
                    .iter()
                    .map(|x| format!("{x}"))
                    .collect();
                return Err(PyValueError::new_err(format!(
                    "the integrand is {fx} at ({}): its integral cannot be estimated",
                    at.join(", ")
                )));
            }
            terms.push(fx * volume);
        }
    }
    Ok(terms)
}

/// Estimate the integral of f over a box by F_N = 1/N Σ f(X_i)/p(X_i), X_i uniform in the box
/// (p = 1/volume).
///
/// `f` takes an (n, d) array of points and returns n values; `domain` is `(lo, hi)` or a list
/// of `(lo, hi)`, one per dimension. Independent samples give the standard error from their
/// sample variance; "stratified" and "sobol" points, which are not independent, from
/// `replicates` independent randomisations of n / replicates points each. Returns an Estimate
/// (mean, std_error, ci95, ...); warns when one sample carries much of the variance (a
/// heavy-tailed f/p, whose error is not to be trusted).
#[pyfunction]
#[pyo3(signature = (f, domain, n, sampler="independent", seed=0, replicates=16))]
fn integrate(
    f: &Bound<'_, PyAny>,
    domain: &Bound<'_, PyAny>,
    n: i64,
    sampler: &str,
    seed: u64,
    replicates: i64,
) -> PyResult<Estimate> {
    if !f.is_callable() {
        return Err(PyValueError::new_err(
            "f: expected a function of an (n, d) array returning n values",
        ));
    }
    let box_ = self::domain(domain)?;
    let n = positive_u32(n, "n")?;
    let kind: SamplerKind = sampler.parse().map_err(value_error)?;
    let reps = positive_u32(replicates, "replicates")?;
    let (estimate, all_terms) = if kind == SamplerKind::Independent || reps < 2 {
        let terms = weighted_terms(f, &box_, kind, n, seed)?;
        let mut stats = RunningStats::new();
        terms.iter().for_each(|&t| stats.push(t));
        (stats.estimate(), terms)
    } else {
        // Independent randomisations (seeds) of n / R samples: the replicates' means are
        // independent, so their spread gives the error (as `pathlab integrate` does).
        let per = (n / reps).max(1);
        let mut means = Vec::with_capacity(reps as usize);
        let mut all = Vec::new();
        for r in 0..reps {
            let terms = weighted_terms(
                f,
                &box_,
                kind,
                per,
                seed.wrapping_add(r as u64 * 0x9e37_79b9),
            )?;
            means.push(terms.iter().sum::<f64>() / terms.len() as f64);
            all.extend(terms);
        }
        (replicate_estimate(&means, per as u64), all)
    };
    let share = largest_share(&all_terms);
    if looks_heavy_tailed(share, all_terms.len() as u64) {
        crate::scene::warn(
            f.py(),
            &format!(
                "one of the {} samples carries {:.0}% of the sample variance: f/p looks heavy-tailed (infinite variance, or a divergent integral), so the standard error and interval are not to be trusted",
                all_terms.len(),
                100.0 * share
            ),
        )?;
    }
    Ok(estimate.into())
}

/// max (t - mean)² / Σ (t - mean)² over the terms.
fn largest_share(terms: &[f64]) -> f64 {
    let mean = terms.iter().sum::<f64>() / terms.len().max(1) as f64;
    let (sum, largest) = terms.iter().fold((0.0f64, 0.0f64), |(s, l), t| {
        let d = (t - mean) * (t - mean);
        (s + d, l.max(d))
    });
    if sum > 0.0 {
        largest / sum
    } else {
        0.0
    }
}

/// The outcome of a chi-square test.
#[pyclass(module = "pathlab", frozen, get_all)]
struct ChiSquareTest {
    /// Pearson's statistic over the pooled cells.
    statistic: f64,
    /// The probability of a statistic at least this large if the samples follow the pdf (0
    /// when a sample fell where the pdf is 0).
    p_value: f64,
    /// Degrees of freedom.
    dof: usize,
    /// Samples tested.
    samples: u64,
    /// Samples that fell where the pdf is zero.
    impossible_samples: u64,
}

#[pymethods]
impl ChiSquareTest {
    /// Whether the test does not reject the pdf at significance `alpha`.
    #[pyo3(signature = (alpha=0.01))]
    fn passes(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyResult<Py<PyAny>> {
        let py = slf.py();
        let pair = (slf.statistic, slf.p_value).into_pyobject(py)?;
        Ok(pair.try_iter()?.into_any().unbind())
    }

    fn __repr__(&self) -> String {
        format!(
            "ChiSquareTest(statistic={:.3}, dof={}, p_value={:.4}, samples={}{})",
            self.statistic,
            self.dof,
            self.p_value,
            self.samples,
            if self.impossible_samples > 0 {
                format!(", impossible_samples={}", self.impossible_samples)
            } else {
                String::new()
            }
        )
    }
}

impl From<pathlab_mc::stats::ChiSquareTest> for ChiSquareTest {
    fn from(t: pathlab_mc::stats::ChiSquareTest) -> Self {
        ChiSquareTest {
            statistic: t.statistic,
            p_value: t.p_value,
            dof: t.dof,
            samples: t.samples,
            impossible_samples: t.impossible_samples,
        }
    }
}

/// The pdf's values at `nodes`, converted to what it takes (`x` of each node for 1D, the node
/// for 2D, the direction of (cos θ, φ) for directions), from one call.
fn pdf_at(pdf: &Bound<'_, PyAny>, nodes: &[[f64; 2]], kind: Kind) -> PyResult<Vec<f64>> {
    let py = pdf.py();
    let arg = match kind {
        Kind::Line => {
            crate::arrays::values_out(py, nodes.iter().map(|p| p[0]).collect()).into_any()
        }
        Kind::Plane => crate::arrays::rows_out(py, nodes.to_vec()).into_any(),
        Kind::Directions => {
            let dirs: Vec<[f64; 3]> = nodes
                .iter()
                .map(|&[z, phi]| {
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    [r * phi.cos(), r * phi.sin(), z]
                })
                .collect();
            crate::arrays::rows_out(py, dirs).into_any()
        }
    };
    let out = pdf.call1((arg,))?;
    let v = values(&out, "the pdf's values")?;
    if v.len() != nodes.len() {
        return Err(PyValueError::new_err(format!(
            "the pdf returned {} values for {} points; it must return one per point",
            v.len(),
            nodes.len()
        )));
    }
    if let Some(bad) = v.iter().find(|p| !(p.is_finite() && **p >= 0.0)) {
        return Err(PyValueError::new_err(format!(
            "the pdf returned {bad}; a density is finite and >= 0"
        )));
    }
    Ok(v)
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Line,
    Plane,
    Directions,
}

/// Pearson's chi-square goodness-of-fit test of samples against a density.
///
/// - numbers, shape (n,): `pdf(x)` on `domain=(lo, hi)`, in `bins` bins;
/// - points, shape (n, 2): `pdf(p)` per unit area on `domain=((x0, x1), (y0, y1))`, in
///   `bins=(nx, ny)`;
/// - directions, shape (n, 3): `pdf(w)` per unit solid angle, binned in (cos θ, φ) over the
///   sphere, in `bins=(n_cos_theta, n_phi)`;
/// - integer outcomes, shape (n,), with `pdf` an array of their probabilities.
///
/// Without `bins`, about 20 samples per bin (at most 64 bins in 1D, 32 x 32 in 2D, 32 x 64
/// for directions).
/// The pdf is called once, on an array of every quadrature node (4x4 Gauss–Legendre pieces of
/// 4 nodes per bin); a pdf that jumps inside a bin is integrated only approximately, so put its
/// jumps on bin edges. Mass outside the domain is one more cell, so a pdf that does not
/// integrate to one is rejected. Returns a ChiSquareTest (statistic, p_value, dof, ...).
#[pyfunction]
#[pyo3(signature = (samples, pdf, domain=None, bins=None))]
fn chi2_test(
    samples: &Bound<'_, PyAny>,
    pdf: &Bound<'_, PyAny>,
    domain: Option<&Bound<'_, PyAny>>,
    bins: Option<&Bound<'_, PyAny>>,
) -> PyResult<ChiSquareTest> {
    if !pdf.is_callable() {
        return discrete(samples, pdf);
    }
    let a = f64_array(samples, "samples")?;
    let view = a.as_array();
    let shape = view.shape().to_vec();
    let flat: Vec<f64> = view.iter().copied().collect();
    let (kind, pts, dom): (Kind, Vec<[f64; 2]>, [[f64; 2]; 2]) = match shape.as_slice() {
        [_] => {
            let Some(d) = domain else {
                return Err(PyValueError::new_err(
                    "domain: 1D samples need the interval (lo, hi) to bin",
                ));
            };
            let (lo, hi): (f64, f64) = d.extract()?;
            (Kind::Line, flat.iter().map(|&x| [x, 0.5]).collect(), [[lo, hi], [0.0, 1.0]])
        }
        [_, 2] => {
            let Some(d) = domain else {
                return Err(PyValueError::new_err(
                    "domain: 2D samples need the rectangle ((x0, x1), (y0, y1)) to bin",
                ));
            };
            let ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)) = d.extract()?;
            let pts = flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
            (Kind::Plane, pts, [[x0, x1], [y0, y1]])
        }
        [_, 3] => {
            if domain.is_some() {
                return Err(PyValueError::new_err(
                    "domain: directions are binned over the whole sphere, in (cos θ, φ); give no domain",
                ));
            }
            let pts = flat
                .chunks_exact(3)
                .map(|c| cos_theta_phi([c[0], c[1], c[2]]))
                .collect();
            (Kind::Directions, pts, [[-1.0, 1.0], [0.0, TAU]])
        }
        _ => {
            return Err(PyValueError::new_err(format!(
                "samples: expected shape (n,) for numbers, (n, 2) for points or (n, 3) for directions, got {shape:?}"
            )))
        }
    };
    if let Some(bad) = dom
        .iter()
        .find(|[lo, hi]| !(lo.is_finite() && hi.is_finite() && lo < hi))
    {
        return Err(PyValueError::new_err(format!(
            "domain: ({}, {}) needs finite bounds with lo < hi",
            bad[0], bad[1]
        )));
    }
    let res = match (bins, kind) {
        (Some(b), Kind::Line) => [positive_u32(b.extract()?, "bins")? as usize, 1],
        (Some(b), _) => {
            let (x, y): (i64, i64) = b.extract()?;
            [
                positive_u32(x, "bins")? as usize,
                positive_u32(y, "bins")? as usize,
            ]
        }
        // By default about 20 samples per bin (were they spread evenly), so that cells are
        // not pooled away: at most 64 bins, 32 x 32 or 32 x 64, at least 4 per axis.
        (None, kind) => {
            // An even count per axis keeps the middle (the horizon z = 0) on a bin edge.
            let k = |cells: f64| (cells.sqrt() as usize / 2 * 2).clamp(4, 32);
            let per_bin = pts.len() as f64 / 20.0;
            match kind {
                Kind::Line => [(per_bin as usize / 2 * 2).clamp(4, 64), 1],
                Kind::Plane => [k(per_bin), k(per_bin)],
                Kind::Directions => [k(per_bin / 2.0), 2 * k(per_bin / 2.0)],
            }
        }
    };
    if res[0] * res[1] > 1 << 20 {
        return Err(PyValueError::new_err(format!(
            "bins: {} x {} is more than 2^20 bins",
            res[0], res[1]
        )));
    }
    let grid = Chi2Grid::new(dom, res);
    let values = pdf_at(pdf, &grid.nodes(), kind)?;
    let n = pts.len();
    let test = grid
        .test(pts, &values)
        .expect("one pdf value per quadrature node, checked above");
    if test.dof == 0 && test.impossible_samples == 0 {
        crate::scene::warn(
            samples.py(),
            &format!(
                "chi2_test: {n} samples in {} x {} bins leave no cell with 5 expected samples to test: the p-value of 1 says nothing; use more samples or fewer bins",
                res[0], res[1]
            ),
        )?;
    }
    Ok(test.into())
}

/// The discrete test: integer outcomes against an array of probabilities.
fn discrete(
    samples: &Bound<'_, PyAny>,
    probabilities: &Bound<'_, PyAny>,
) -> PyResult<ChiSquareTest> {
    let p = values(probabilities, "pdf (probabilities of outcomes 0, 1, ...)")?;
    if p.is_empty() || p.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(PyValueError::new_err(
            "pdf: expected a function, or probabilities of outcomes 0, 1, ... (finite, >= 0)",
        ));
    }
    let mut counts = vec![0u64; p.len()];
    for s in values(samples, "samples")? {
        if !(s >= 0.0 && s.fract() == 0.0 && (s as usize) < p.len()) {
            return Err(PyValueError::new_err(format!(
                "samples: outcome {s} is not one of 0..{}",
                p.len()
            )));
        }
        counts[s as usize] += 1;
    }
    Ok(chi2_test_discrete(&counts, &p).into())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Estimate>()?;
    m.add_class::<ChiSquareTest>()?;
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(chi2_test, m)?)?;
    Ok(())
}
