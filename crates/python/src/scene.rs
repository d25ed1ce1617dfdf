//! `pathlab.load` and `pathlab.Scene`: a scene description, its parameters applied, and the
//! scene built from it for rendering (built once, on first use; a new camera or resolution
//! replaces only the camera).

use crate::SceneError;
use pathlab_render::camera::Camera;
use pathlab_render::desc::SceneDesc;
use pathlab_render::limits;
use pathlab_render::scene::Scene as BuiltScene;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::Arc;

/// A scene read from a file or a built-in name.
#[pyclass(module = "pathlab")]
pub struct Scene {
    /// The file or built-in name it came from.
    source: String,
    /// The description, with the resolution and camera the attributes set.
    pub(crate) desc: SceneDesc,
    /// The built scene, once rendered; its camera is the description's as last rendered.
    built: Option<Arc<BuiltScene>>,
}

/// Load a scene: a built-in name ("cornell-box", ...) or a file pathlab reads (Mitsuba 3 XML,
/// pbrt-v4 .pbrt/.pbrt.gz, the course's COLLADA .dae, OBJ, PLY, glTF .gltf/.glb).
///
/// Keyword arguments fill a Mitsuba file's `$name` defaults, as `pathlab render -D name=value`
/// does: `load("scene.xml", spp=16, resx=128)`. The loader's warnings are given as Python
/// warnings (UserWarning). Raises SceneError naming the file, line and what was expected.
#[pyfunction]
#[pyo3(signature = (source, **params))]
fn load(
    py: Python<'_>,
    source: std::path::PathBuf,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Scene> {
    let source = source.to_string_lossy().into_owned();
    let source = source.as_str();
    let mut defines = Vec::new();
    if let Some(params) = params {
        for (name, value) in params.iter() {
            defines.push((name.extract::<String>()?, parameter_text(&value)?));
        }
    }
    let source_owned = source.to_string();
    let desc = py
        .detach(|| pathlab_scene::load_with(&source_owned, &defines))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    for w in &desc.warnings {
        warn(py, w)?;
    }
    Ok(Scene {
        source: source.to_string(),
        desc,
        built: None,
    })
}

/// A parameter's value as the text a `-D name=value` would give: booleans as `true`/`false`,
/// numbers and strings as they print, sequences of numbers as `a, b, c`.
fn parameter_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(b) = value.extract::<bool>() {
        return Ok(if b { "true" } else { "false" }.to_string());
    }
    if let Ok(seq) = value.cast::<PyTuple>() {
        let parts: PyResult<Vec<String>> = seq.iter().map(|v| parameter_text(&v)).collect();
        return Ok(parts?.join(", "));
    }
    if let Ok(list) = value.cast::<pyo3::types::PyList>() {
        let parts: PyResult<Vec<String>> = list.iter().map(|v| parameter_text(&v)).collect();
        return Ok(parts?.join(", "));
    }
    Ok(value.str()?.to_string())
}

/// A warning through Python's `warnings` module (shown once per place, filterable).
pub fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    let text = std::ffi::CString::new(message.replace('\0', " "))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    PyErr::warn(py, &category, &text, 1)
}

impl Scene {
    /// The scene built for rendering at `resolution`, with the description's camera: built
    /// the first time (GIL released), afterwards only its camera replaced when it changed.
    pub(crate) fn built_at(
        &mut self,
        py: Python<'_>,
        resolution: [u32; 2],
    ) -> PyResult<Arc<BuiltScene>> {
        let camera = Camera::new(&self.desc.camera, resolution).with_filter(self.desc.filter);
        match &mut self.built {
            Some(built) => {
                if built.camera() != &camera {
                    Arc::make_mut(built).set_camera(camera);
                }
            }
            None => {
                let desc = &self.desc;
                let mut scene = py
                    .detach(|| BuiltScene::build(desc))
                    .map_err(|e| SceneError::new_err(format!("{}: {e}", self.source)))?;
                scene.set_camera(camera);
                self.built = Some(Arc::new(scene));
            }
        }
        Ok(self.built.clone().expect("built above"))
    }
}

#[pymethods]
impl Scene {
    /// The file or built-in name the scene came from.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// The image size `(width, height)` renders use unless told otherwise.
    #[getter]
    fn get_resolution(&self) -> (u32, u32) {
        (self.desc.resolution[0], self.desc.resolution[1])
    }

    #[setter]
    fn set_resolution(&mut self, size: (i64, i64)) -> PyResult<()> {
        self.desc.resolution = checked_resolution(size)?;
        Ok(())
    }

    /// The camera: a dict of `origin`, `target`, `up` (tuples), `fov` (degrees),
    /// `lens_radius` and `focal_distance`. Assign a dict with any of these keys to change it.
    #[getter]
    fn get_camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = &self.desc.camera;
        let d = PyDict::new(py);
        let v = |v: glam::Vec3| (v.x, v.y, v.z);
        d.set_item("origin", v(c.origin))?;
        d.set_item("target", v(c.target))?;
        d.set_item("up", v(c.up))?;
        d.set_item("fov", c.fov_degrees)?;
        d.set_item("lens_radius", c.lens_radius)?;
        d.set_item("focal_distance", c.focal_distance)?;
        Ok(d)
    }

    #[setter]
    fn set_camera(&mut self, changes: &Bound<'_, PyDict>) -> PyResult<()> {
        let mut c = self.desc.camera;
        for (key, value) in changes.iter() {
            let key: String = key.extract()?;
            let vector = |value: &Bound<'_, PyAny>| -> PyResult<glam::Vec3> {
                let (x, y, z): (f32, f32, f32) = value.extract().map_err(|_| {
                    PyValueError::new_err(format!("camera['{key}']: expected (x, y, z)"))
                })?;
                finite(&[x, y, z], &key)?;
                Ok(glam::Vec3::new(x, y, z))
            };
            match key.as_str() {
                "origin" => c.origin = vector(&value)?,
                "target" => c.target = vector(&value)?,
                "up" => c.up = vector(&value)?,
                "fov" => {
                    c.fov_degrees = within(&key, value.extract()?, limits::fov_degrees)?;
                    c.focal_pixels = None;
                }
                "lens_radius" => c.lens_radius = within(&key, value.extract()?, limits::lens_radius)?,
                "focal_distance" => {
                    c.focal_distance = within(&key, value.extract()?, limits::focal_distance)?
                }
                other => {
                    return Err(PyValueError::new_err(format!(
                        "camera['{other}']: unknown key (expected origin, target, up, fov, lens_radius or focal_distance)"
                    )))
                }
            }
        }
        if (c.target - c.origin).length_squared() == 0.0 {
            return Err(PyValueError::new_err(
                "camera: origin and target are the same point",
            ));
        }
        self.desc.camera = c;
        Ok(())
    }

    /// The samples per pixel the scene file asks for, if it does.
    #[getter]
    fn spp(&self) -> Option<u32> {
        self.desc.hints.spp
    }

    /// The loader's warnings (also given as Python warnings when the scene was loaded).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.desc.warnings.clone()
    }

    /// What the scene holds: counts of meshes, triangles, spheres; materials and lights by
    /// kind; the camera; the bounds of its shapes (`None` when empty).
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let info = pathlab_scene::info::summarize(&self.desc);
        let d = PyDict::new(py);
        d.set_item("source", &self.source)?;
        d.set_item("meshes", info.meshes)?;
        d.set_item("triangles", info.triangles)?;
        d.set_item("spheres", info.spheres)?;
        d.set_item("sdf_grids", info.sdf_grids)?;
        d.set_item("materials", info.materials)?;
        d.set_item("lights", info.lights)?;
        d.set_item("camera", self.get_camera(py)?)?;
        d.set_item("resolution", self.get_resolution())?;
        let v = |v: glam::Vec3| (v.x, v.y, v.z);
        d.set_item("bounds", info.bounds.map(|(lo, hi)| (v(lo), v(hi))))?;
        d.set_item("warnings", info.warnings)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let info = pathlab_scene::info::summarize(&self.desc);
        let [w, h] = self.desc.resolution;
        format!(
            "Scene('{}': {} triangles, {} spheres, {} lights, {w}x{h})",
            self.source,
            info.triangles,
            info.spheres,
            info.lights.values().sum::<usize>()
        )
    }
}

/// A `(width, height)` of 1 to 16384 pixels each.
pub fn checked_resolution((w, h): (i64, i64)) -> PyResult<[u32; 2]> {
    let side = |n: i64| u32::try_from(n).unwrap_or(0);
    limits::resolution([side(w), side(h)])
        .map_err(|e| PyValueError::new_err(format!("resolution ({w}, {h}): {e}")))
}

/// A camera value by its rule in [`limits`], or a `ValueError` naming its key.
fn within(key: &str, value: f32, rule: fn(f32) -> Result<f32, limits::Expected>) -> PyResult<f32> {
    rule(value).map_err(|e| PyValueError::new_err(format!("camera['{key}'] {value}: {e}")))
}

fn finite(v: &[f32], key: &str) -> PyResult<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "camera['{key}']: every coordinate must be finite"
        )))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    Ok(())
}
