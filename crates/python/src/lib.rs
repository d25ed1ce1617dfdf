//! # pathlab in Python
//!
//! The extension module `pathlab._pathlab`, which the Python package `pathlab`
//! (`python/pathlab/__init__.py`) re-exports. It wraps the libraries, not the command line:
//! - [`scene`]: `load(path_or_builtin, **params)` and the `Scene` it returns;
//! - [`render`]: `render(scene, ...)` to a float32 numpy array (or a dict of AOVs), with the
//!   GIL released and Ctrl-C stopping the render;
//! - [`images`]: `read` and `write` of EXR and PNG files, and PNG bytes for notebooks;
//! - [`sampling`]: the samplers' points and the warps with their pdfs, vectorised;
//! - [`distributions`]: exponential, piecewise-constant 1D and 2D, and alias tables;
//! - [`estimate`]: `integrate` of a Python function over a box and `chi2_test` of samples
//!   against a pdf.
//!
//! Errors are Python exceptions with the command line's one-line messages: `SceneError` for a
//! scene that cannot be read or built, `ValueError` for a bad argument, `OSError` for a file
//! that cannot be read or written.

use pyo3::prelude::*;

mod arrays;
mod distributions;
mod estimate;
mod images;
mod render;
mod sampling;
mod scene;

pyo3::create_exception!(
    pathlab,
    SceneError,
    pyo3::exceptions::PyException,
    "A scene could not be read or built: the message names the file, the line and what was expected."
);

/// The extension module.
#[pymodule]
fn _pathlab(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    scene::register(m)?;
    render::register(m)?;
    images::register(m)?;
    sampling::register(m)?;
    distributions::register(m)?;
    estimate::register(m)?;
    Ok(())
}
