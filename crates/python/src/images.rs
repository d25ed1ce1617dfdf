//! `pathlab.read` and `pathlab.write`: images as float32 arrays of linear values, in OpenEXR
//! (exact) or 8-bit PNG (sRGB), and `png_bytes` for a notebook to show an array.

use crate::arrays::f64_array;
use numpy::ndarray::Array3;
use numpy::IntoPyArray;
use pathlab_render::color::Rgb;
use pathlab_render::image_io::{encode_rgb8, read_rgb, write_exr, write_rgb8, ToneMap};
use pathlab_render::limits;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

/// Read an image (OpenEXR, PNG, JPEG, Radiance HDR, BMP) as a float32 array (H, W, 3) of
/// linear values; 8-bit formats are decoded from sRGB. Raises OSError naming the file.
#[pyfunction]
fn read<'py>(py: Python<'py>, path: std::path::PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, pixels) = py
        .detach(|| read_rgb(&path, true))
        .map_err(|e| PyOSError::new_err(e.to_string()))?;
    let data: Vec<f32> = pixels.iter().flat_map(|p| p.to_array()).collect();
    Ok(Array3::from_shape_vec((h as usize, w as usize, 3), data)
        .expect("one RGB triple per pixel")
        .into_pyarray(py)
        .into_any())
}

/// An `(H, W, 3)` or `(H, W)` array (grey) as RGB pixels, with its width and height.
fn pixels(array: &Bound<'_, PyAny>) -> PyResult<(u32, u32, Vec<Rgb>)> {
    let a = f64_array(array, "image")?;
    let v = a.as_array();
    let shape = v.shape().to_vec();
    let (h, w, channels) = match shape.as_slice() {
        [h, w, 3] => (*h, *w, 3),
        [h, w] => (*h, *w, 1),
        _ => {
            return Err(PyValueError::new_err(format!(
                "image: expected an array of shape (height, width, 3) or (height, width), got {shape:?}"
            )))
        }
    };
    if h == 0 || w == 0 || h > 65536 || w > 65536 {
        return Err(PyValueError::new_err(format!(
            "image: {w}x{h} pixels; width and height must be between 1 and 65536"
        )));
    }
    let flat: Vec<f32> = v.iter().map(|&x| x as f32).collect();
    let px = if channels == 3 {
        flat.chunks_exact(3)
            .map(|c| Rgb::new(c[0], c[1], c[2]))
            .collect()
    } else {
        flat.iter().map(|&g| Rgb::splat(g)).collect()
    };
    Ok((w as u32, h as u32, px))
}

/// How linear values become 8-bit ones: 2^`exposure`, then the tone map `tonemap` names
/// (`"srgb"` or `"cs184"`, as `pathlab render --tonemap`), checked.
fn encoding(exposure: f32, tonemap: &str) -> PyResult<(f32, ToneMap)> {
    limits::exposure(exposure)
        .map_err(|e| PyValueError::new_err(format!("exposure {exposure}: {e}")))?;
    let tonemap = tonemap
        .parse::<ToneMap>()
        .map_err(|e| PyValueError::new_err(format!("tonemap: {e}")))?;
    Ok((exposure, tonemap))
}

/// Write an image of linear values, shape (H, W, 3) or (H, W): OpenEXR (float32, exact) for a
/// `.exr` path; for `.png`, 8-bit values after scaling by 2^exposure, by the tone map
/// `tonemap` names: "srgb" (clamp, the sRGB curve) or "cs184" (the course's renderer: times
/// √2, gamma 2.2, clamp).
#[pyfunction]
#[pyo3(signature = (path, image, exposure=0.0, tonemap="srgb"))]
fn write(
    py: Python<'_>,
    path: std::path::PathBuf,
    image: &Bound<'_, PyAny>,
    exposure: f32,
    tonemap: &str,
) -> PyResult<()> {
    let (exposure, tonemap) = encoding(exposure, tonemap)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let exr = match ext.as_deref() {
        Some("exr") => true,
        Some("png") => false,
        _ => {
            return Err(PyValueError::new_err(format!(
                "{}: unknown image format (expected .exr or .png)",
                path.display()
            )))
        }
    };
    let (w, h, px) = pixels(image)?;
    py.detach(|| {
        if exr {
            write_exr(&path, w, h, &px, &[])
        } else {
            write_rgb8(&path, w, h, &encode_rgb8(&px, exposure, tonemap))
        }
    })
    .map_err(|e| PyOSError::new_err(e.to_string()))
}

/// The image (linear values, (H, W, 3) or (H, W)) as the bytes of an 8-bit PNG file, after
/// scaling by 2^exposure and the tone map `tonemap` names (as [`write`]): what a notebook
/// shows.
#[pyfunction]
#[pyo3(signature = (image, exposure=0.0, tonemap="srgb"))]
fn png_bytes<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    exposure: f32,
    tonemap: &str,
) -> PyResult<Bound<'py, PyBytes>> {
    let (exposure, tonemap) = encoding(exposure, tonemap)?;
    let (w, h, px) = pixels(image)?;
    let bytes = encode_rgb8(&px, exposure, tonemap);
    let mut out = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(
        &mut out,
        &bytes,
        w,
        h,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| PyValueError::new_err(format!("cannot encode the PNG: {e}")))?;
    Ok(PyBytes::new(py, out.get_ref()))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(png_bytes, m)?)?;
    Ok(())
}
