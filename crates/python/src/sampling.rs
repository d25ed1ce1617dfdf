//! The samplers' points and the warps, vectorised over numpy arrays: `uniform_points(n, d)`
//! from the independent, stratified or Sobol sampler, and each warp from the unit square with
//! the pdf of what it returns (zero outside its domain).

use crate::arrays::{positive_u32, rows, rows_out, value_error, values_out};
use glam::{Vec2, Vec3};
use numpy::{PyArray1, PyArray2};
use pathlab_mc::sampler::{Sampler, SamplerKind};
use pathlab_mc::warp;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Most dimensions of `uniform_points`.
const MAX_POINT_DIMS: i64 = 1024;

/// n points of the unit cube [0, 1)^dims as an (n, dims) float64 array, point i being sample i
/// of the sampler: "independent", "stratified" (jittered) or "sobol" (Owen-scrambled), with
/// `seed`. Dimensions are drawn two at a time, as the renderer and `integrate` draw them.
#[pyfunction]
#[pyo3(signature = (n, dims, sampler="independent", seed=0))]
fn uniform_points<'py>(
    py: Python<'py>,
    n: i64,
    dims: i64,
    sampler: &str,
    seed: u64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = positive_u32(n, "n")?;
    if !(1..=MAX_POINT_DIMS).contains(&dims) {
        return Err(PyValueError::new_err(format!(
            "dims {dims}: must be between 1 and {MAX_POINT_DIMS}"
        )));
    }
    let kind: SamplerKind = sampler.parse().map_err(value_error)?;
    let d = dims as usize;
    let flat = py.detach(|| points(kind, n, d, seed, 0..n));
    let array = numpy::ndarray::Array2::from_shape_vec((n as usize, d), flat)
        .expect("n points of d coordinates");
    Ok(numpy::IntoPyArray::into_pyarray(array, py))
}

/// Samples `indices` of the sampler of `kind` set up for `n` samples, `d` coordinates each,
/// row-major.
pub fn points(
    kind: SamplerKind,
    n: u32,
    d: usize,
    seed: u64,
    indices: std::ops::Range<u32>,
) -> Vec<f64> {
    let mut s = kind.build(n, seed);
    let mut out = vec![0.0; indices.len() * d];
    for (i, x) in indices.zip(out.chunks_exact_mut(d)) {
        s.start_pixel_sample([0, 0], i, 0);
        s.next_point(x);
    }
    out
}

/// `f` applied to each `(u0, u1)` row of `u`.
fn warp_rows<'py, const O: usize>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
    f: impl Fn(Vec2) -> [f32; O],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let out = rows::<2>(u, "u")?
        .into_iter()
        .map(|[a, b]| f(Vec2::new(a as f32, b as f32)).map(|x| x as f64))
        .collect();
    Ok(rows_out(py, out))
}

/// `pdf` of each row of `x` (K coordinates).
fn pdf_rows<'py, const K: usize>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    what: &str,
    pdf: impl Fn([f32; K]) -> f32,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let out = rows::<K>(x, what)?
        .into_iter()
        .map(|r| pdf(r.map(|v| v as f32)) as f64)
        .collect();
    Ok(values_out(py, out))
}

fn v3(w: Vec3) -> [f32; 3] {
    w.to_array()
}

fn checked_cone(cos_theta_max: f64) -> PyResult<f32> {
    if !(-1.0..1.0).contains(&cos_theta_max) {
        return Err(PyValueError::new_err(format!(
            "cos_theta_max {cos_theta_max}: must be in [-1, 1)"
        )));
    }
    Ok(cos_theta_max as f32)
}

/// Points uniform on the unit disk (Shirley–Chiu concentric map): `(n, 2)`.
#[pyfunction]
fn sample_uniform_disk_concentric<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    warp_rows(py, u, |u| {
        warp::sample_uniform_disk_concentric(u).to_array()
    })
}

/// The density per unit area of points `(n, 2)` on the unit disk: 1/π inside, 0 outside.
#[pyfunction]
fn uniform_disk_pdf<'py>(
    py: Python<'py>,
    p: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    pdf_rows::<2>(py, p, "p", |[x, y]| warp::uniform_disk_pdf(Vec2::new(x, y)))
}

/// Directions uniform over the hemisphere z >= 0: `(n, 3)`.
#[pyfunction]
fn sample_uniform_hemisphere<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    warp_rows(py, u, |u| v3(warp::sample_uniform_hemisphere(u)))
}

/// The solid-angle density of directions `(n, 3)` uniform over the hemisphere: 1/(2π) where
/// z >= 0, else 0.
#[pyfunction]
fn uniform_hemisphere_pdf<'py>(
    py: Python<'py>,
    w: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    pdf_rows::<3>(py, w, "w", |[_, _, z]| {
        if z >= 0.0 {
            warp::uniform_hemisphere_pdf()
        } else {
            0.0
        }
    })
}

/// Cosine-weighted directions over the hemisphere z >= 0 (Malley's method): `(n, 3)`.
#[pyfunction]
fn sample_cosine_hemisphere<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    warp_rows(py, u, |u| v3(warp::sample_cosine_hemisphere(u)))
}

/// The solid-angle density cos θ/π of directions `(n, 3)` (0 below the horizon).
#[pyfunction]
fn cosine_hemisphere_pdf<'py>(
    py: Python<'py>,
    w: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    pdf_rows::<3>(py, w, "w", |[_, _, z]| {
        if z >= 0.0 {
            warp::cosine_hemisphere_pdf(z)
        } else {
            0.0
        }
    })
}

/// Directions uniform over the sphere: `(n, 3)`.
#[pyfunction]
fn sample_uniform_sphere<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    warp_rows(py, u, |u| v3(warp::sample_uniform_sphere(u)))
}

/// The solid-angle density 1/(4π) of directions `(n, 3)` uniform over the sphere.
#[pyfunction]
fn uniform_sphere_pdf<'py>(
    py: Python<'py>,
    w: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    pdf_rows::<3>(py, w, "w", |_| warp::uniform_sphere_pdf())
}

/// Directions uniform in the cone about +z with cos θ >= `cos_theta_max`: `(n, 3)`.
#[pyfunction]
fn sample_uniform_cone<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
    cos_theta_max: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = checked_cone(cos_theta_max)?;
    warp_rows(py, u, |u| v3(warp::sample_uniform_cone(u, c)))
}

/// The solid-angle density of directions `(n, 3)` uniform in the cone: 1/(2π(1 - cos θmax))
/// inside, 0 outside.
#[pyfunction]
fn uniform_cone_pdf<'py>(
    py: Python<'py>,
    w: &Bound<'py, PyAny>,
    cos_theta_max: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let c = checked_cone(cos_theta_max)?;
    pdf_rows::<3>(py, w, "w", |[_, _, z]| {
        if z >= c {
            warp::uniform_cone_pdf(c)
        } else {
            0.0
        }
    })
}

/// Barycentric coordinates `(b0, b1, b2)` uniform over a triangle: `(n, 3)`.
#[pyfunction]
fn sample_uniform_triangle<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    warp_rows(py, u, warp::sample_uniform_triangle)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(uniform_points, m)?)?;
    m.add_function(wrap_pyfunction!(sample_uniform_disk_concentric, m)?)?;
    m.add_function(wrap_pyfunction!(uniform_disk_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(sample_uniform_hemisphere, m)?)?;
    m.add_function(wrap_pyfunction!(uniform_hemisphere_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(sample_cosine_hemisphere, m)?)?;
    m.add_function(wrap_pyfunction!(cosine_hemisphere_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(sample_uniform_sphere, m)?)?;
    m.add_function(wrap_pyfunction!(uniform_sphere_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(sample_uniform_cone, m)?)?;
    m.add_function(wrap_pyfunction!(uniform_cone_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(sample_uniform_triangle, m)?)?;
    Ok(())
}
