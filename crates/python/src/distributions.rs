//! The distributions of `pathlab_mc::distribution` as Python classes whose `sample` and `pdf`
//! take and return numpy arrays: the exponential (by inversion), piecewise-constant densities
//! in 1D and 2D, and the alias method's table for discrete outcomes.

use crate::arrays::{rows, rows_out, value_error, values, values_out};
use glam::Vec2;
use numpy::{PyArray1, PyArray2};
use pathlab_mc::distribution;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Uniform numbers in [0, 1): a `ValueError` for any outside (an inversion would return
/// nonsense for them).
fn unit_values(u: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v = values(u, "u")?;
    if let Some(bad) = v.iter().find(|x| !(0.0..1.0).contains(*x)) {
        return Err(PyValueError::new_err(format!("u: {bad} is outside [0, 1)")));
    }
    Ok(v)
}

/// `f` of each value of `x` (a number or an `(n,)` array), as an array.
fn map_values<'py, T: numpy::Element>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    what: &str,
    f: impl Fn(f64) -> T,
) -> PyResult<Bound<'py, PyArray1<T>>> {
    Ok(values_out(
        py,
        values(x, what)?.into_iter().map(f).collect(),
    ))
}

/// `f` of each uniform number of `u` (checked to lie in [0, 1)), as an array.
fn map_uniform<'py, T: numpy::Element>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
    f: impl Fn(f64) -> T,
) -> PyResult<Bound<'py, PyArray1<T>>> {
    Ok(values_out(py, unit_values(u)?.into_iter().map(f).collect()))
}

/// Weights: finite, non-negative, with a positive sum.
fn weights(w: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let a = crate::arrays::f64_array(w, "weights")?;
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    let total: f64 = v.iter().sum();
    if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) || !(total > 0.0 && total.is_finite()) {
        return Err(PyValueError::new_err(
            "weights: every weight must be finite and >= 0, with a positive sum",
        ));
    }
    Ok(v)
}

/// The exponential distribution of rate λ, sampled by inversion: x = -ln(1 - U)/λ.
#[pyclass(module = "pathlab", frozen)]
struct Exponential(distribution::Exponential);

#[pymethods]
impl Exponential {
    #[new]
    fn new(lam: f64) -> PyResult<Self> {
        Ok(Exponential(
            distribution::Exponential::new(lam).map_err(value_error)?,
        ))
    }

    /// The rate λ.
    #[getter]
    fn lam(&self) -> f64 {
        self.0.lambda()
    }

    /// The mean 1/λ.
    #[getter]
    fn mean(&self) -> f64 {
        self.0.mean()
    }

    /// The variance 1/λ².
    #[getter]
    fn variance(&self) -> f64 {
        self.0.variance()
    }

    /// x = -ln(1 - u)/λ for each u in [0, 1).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_uniform(py, u, |u| self.0.sample(u))
    }

    /// The density λ e^(-λx) (0 for x < 0).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_values(py, x, "x", |x| self.0.pdf(x))
    }

    /// The distribution function 1 - e^(-λx).
    fn cdf<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_values(py, x, "x", |x| self.0.cdf(x))
    }

    fn __repr__(&self) -> String {
        format!("Exponential(lam={})", self.0.lambda())
    }
}

/// A piecewise-constant density on `[lo, hi]` proportional to `weights` (equal pieces),
/// sampled by inverting its CDF.
#[pyclass(module = "pathlab", frozen)]
struct Piecewise1D(distribution::PiecewiseConstant1D);

#[pymethods]
impl Piecewise1D {
    #[new]
    #[pyo3(signature = (weights, lo=0.0, hi=1.0))]
    fn new(weights: &Bound<'_, PyAny>, lo: f32, hi: f32) -> PyResult<Self> {
        let w: Vec<f32> = self::weights(weights)?.iter().map(|&x| x as f32).collect();
        Ok(Piecewise1D(
            distribution::PiecewiseConstant1D::new(&w, lo, hi).map_err(value_error)?,
        ))
    }

    /// The integral of the weights over the domain (the normalisation).
    #[getter]
    fn integral(&self) -> f32 {
        self.0.integral()
    }

    /// `(lo, hi)`.
    #[getter]
    fn domain(&self) -> (f32, f32) {
        self.0.domain()
    }

    /// Points for uniform numbers in [0, 1).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_uniform(py, u, |u| self.0.sample(u as f32).x as f64)
    }

    /// The density at each point (0 outside the domain).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_values(py, x, "x", |x| self.0.pdf(x as f32) as f64)
    }

    fn __repr__(&self) -> String {
        let (lo, hi) = self.0.domain();
        format!("Piecewise1D({} pieces on [{lo}, {hi}])", self.0.len())
    }
}

/// A piecewise-constant density over a rectangle, proportional to a `(rows, columns)` array
/// of weights (row `j` at y in the `j`-th band), sampled by its marginal and conditional CDFs.
#[pyclass(module = "pathlab", frozen)]
struct Piecewise2D {
    dist: distribution::PiecewiseConstant2D,
    shape: (usize, usize),
}

#[pymethods]
impl Piecewise2D {
    #[new]
    #[pyo3(signature = (weights, domain=((0.0, 1.0), (0.0, 1.0))))]
    fn new(weights: &Bound<'_, PyAny>, domain: ((f32, f32), (f32, f32))) -> PyResult<Self> {
        let a = crate::arrays::f64_array(weights, "weights")?;
        let shape = a.as_array().shape().to_vec();
        let [nv, nu] = shape[..] else {
            return Err(PyValueError::new_err(format!(
                "weights: expected a 2D array (rows, columns), got shape {shape:?}"
            )));
        };
        let w: Vec<f32> = self::weights(weights)?.iter().map(|&x| x as f32).collect();
        let ((x0, x1), (y0, y1)) = domain;
        let dist = distribution::PiecewiseConstant2D::new(
            &w,
            nu,
            nv,
            Vec2::new(x0, y0),
            Vec2::new(x1, y1),
        )
        .map_err(value_error)?;
        Ok(Piecewise2D {
            dist,
            shape: (nv, nu),
        })
    }

    /// The integral of the weights over the rectangle.
    #[getter]
    fn integral(&self) -> f32 {
        self.dist.integral()
    }

    /// Points `(n, 2)` for uniform points `(n, 2)` of [0, 1)².
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let mut out = Vec::new();
        for [a, b] in rows::<2>(u, "u")? {
            if !((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b)) {
                return Err(PyValueError::new_err(format!(
                    "u: ({a}, {b}) is outside [0, 1)²"
                )));
            }
            let (p, _) = self.dist.sample(Vec2::new(a as f32, b as f32));
            out.push([p.x as f64, p.y as f64]);
        }
        Ok(rows_out(py, out))
    }

    /// The density at points `(n, 2)` (0 outside the rectangle).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = rows::<2>(p, "p")?
            .into_iter()
            .map(|[x, y]| self.dist.pdf(Vec2::new(x as f32, y as f32)) as f64)
            .collect();
        Ok(values_out(py, v))
    }

    fn __repr__(&self) -> String {
        format!("Piecewise2D({} x {} cells)", self.shape.0, self.shape.1)
    }
}

/// Discrete outcomes `0..n` with probabilities proportional to `weights`, sampled in constant
/// time by the alias method (Walker; Vose's construction).
#[pyclass(module = "pathlab", frozen)]
struct AliasTable(distribution::AliasTable);

#[pymethods]
impl AliasTable {
    #[new]
    fn new(weights: &Bound<'_, PyAny>) -> PyResult<Self> {
        let w = self::weights(weights)?;
        Ok(AliasTable(
            distribution::AliasTable::new(&w).map_err(value_error)?,
        ))
    }

    fn __len__(&self) -> usize {
        self.0.len()
    }

    /// Outcomes (int64) for uniform numbers in [0, 1).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        map_uniform(py, u, |u| self.0.sample(u as f32).index as i64)
    }

    /// The probability of each outcome `i` (0 for any outside `0..n`).
    fn pmf<'py>(
        &self,
        py: Python<'py>,
        i: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_values(py, i, "i", |i| {
            if i >= 0.0 && i.fract() == 0.0 && (i as usize) < self.0.len() {
                self.0.pmf(i as usize)
            } else {
                0.0
            }
        })
    }

    fn __repr__(&self) -> String {
        format!("AliasTable({} outcomes)", self.0.len())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Exponential>()?;
    m.add_class::<Piecewise1D>()?;
    m.add_class::<Piecewise2D>()?;
    m.add_class::<AliasTable>()?;
    Ok(())
}
