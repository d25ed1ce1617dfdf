//! numpy arrays in and out: any array-like of numbers becomes `f64` rows of a fixed width;
//! results go back as arrays numpy owns, built from a `Vec` without a copy.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `obj` as a read-only float64 array: itself if it is one, else `numpy.asarray(obj, float64)`.
pub fn f64_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        return Ok(a.readonly());
    }
    let np = PyModule::import(obj.py(), "numpy")?;
    let converted = np.call_method1("asarray", (obj, "float64")).map_err(|e| {
        PyValueError::new_err(format!("{what}: expected an array of numbers ({e})"))
    })?;
    let array = converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected an array of numbers")))?;
    Ok(array.readonly())
}

/// The rows of an `(n, K)` array (or one `(K,)` row) as `[f64; K]`.
pub fn rows<const K: usize>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; K]>> {
    let a = f64_array(obj, what)?;
    let view = a.as_array();
    let shape = view.shape().to_vec();
    let ok = match shape.as_slice() {
        [_, k] => *k == K,
        [k] => *k == K,
        _ => false,
    };
    if !ok {
        return Err(PyValueError::new_err(format!(
            "{what}: expected an array of shape (n, {K}), got {shape:?}"
        )));
    }
    let flat: Vec<f64> = view.iter().copied().collect();
    Ok(flat
        .chunks_exact(K)
        .map(|c| std::array::from_fn(|i| c[i]))
        .collect())
}

/// The values of a 1D array (or a scalar, as one value).
pub fn values(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let a = f64_array(obj, what)?;
    let view = a.as_array();
    if view.ndim() > 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a number or an array of shape (n,), got {:?}",
            view.shape()
        )));
    }
    Ok(view.iter().copied().collect())
}

/// `(n, K)` rows as a new array.
pub fn rows_out<'py, const K: usize>(
    py: Python<'py>,
    rows: Vec<[f64; K]>,
) -> Bound<'py, PyArray2<f64>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    Array2::from_shape_vec((n, K), flat)
        .expect("n rows of K values fill an (n, K) array")
        .into_pyarray(py)
}

/// Values as a new 1D array.
pub fn values_out<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// A count that must be at least 1 and fit in 32 bits, or a `ValueError` naming it.
pub fn positive_u32(value: i64, what: &str) -> PyResult<u32> {
    if value < 1 || value > u32::MAX as i64 {
        return Err(PyValueError::new_err(format!(
            "{what} {value}: must be a whole number from 1 to {}",
            u32::MAX
        )));
    }
    Ok(value as u32)
}

/// A `String` error (the libraries' parse errors) as a `ValueError`.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}
