//! `pathlab.render`: a scene rendered to a float32 numpy array of linear radiance, on the
//! libraries' render loop (the same one `pathlab render` runs), with the GIL released.
//!
//! The render runs on a thread of its own; the calling thread waits without the GIL and every
//! 20 ms takes it back to let Python handle signals. A Ctrl-C (or any exception a signal
//! handler raises) cancels the render, which stops within a sample per thread, and the
//! exception is raised.

use crate::arrays::{positive_u32, value_error};
use crate::scene::{checked_resolution, Scene};
use numpy::ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::desc::RenderHints;
use pathlab_render::film::Film;
use pathlab_render::integrator::{
    DirectStrategy, IntegratorChoice, IntegratorKind, IntegratorName, PathLighting,
};
use pathlab_render::render::{render as render_scene, RenderSettings, RenderStats};
use pathlab_render::scene::Scene as BuiltScene;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// An extra output of `render(..., aovs=...)`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Aov {
    /// Each pixel's variance of its mean (its squared standard error), per channel.
    Variance,
    /// Each pixel's sample count.
    Samples,
    /// The light that arrives after exactly this many bounces (a render of its own).
    Bounce(u32),
}

impl Aov {
    fn parse(s: &str) -> PyResult<Aov> {
        match s {
            "variance" => Ok(Aov::Variance),
            "samples" => Ok(Aov::Samples),
            _ => s
                .strip_prefix("bounce:")
                .and_then(|k| k.parse().ok())
                .map(Aov::Bounce)
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "aovs: unknown output '{s}' (expected variance, samples or bounce:K with K = 0, 1, 2, ...)"
                    ))
                }),
        }
    }
}

/// The arguments of `render`, checked.
struct Request {
    settings: RenderSettings,
    /// What was asked of the integrator, with the file's hints it is completed by.
    choice: IntegratorChoice,
    hints: RenderHints,
    integrator: IntegratorKind,
    resolution: [u32; 2],
    threads: usize,
    aovs: Vec<(String, Aov)>,
}

/// The estimator's names as `render` takes them: the integrator, the direct-lighting
/// strategy and the path tracer's lighting.
struct Names<'a> {
    integrator: Option<&'a str>,
    direct: Option<&'a str>,
    lighting: Option<&'a str>,
}

#[allow(clippy::too_many_arguments)]
fn request(
    scene: &Scene,
    spp: Option<i64>,
    seed: u64,
    max_depth: Option<i64>,
    names: Names<'_>,
    sampler: Option<&str>,
    resolution: Option<(i64, i64)>,
    threads: i64,
    aovs: Vec<String>,
) -> PyResult<Request> {
    let hints = &scene.desc.hints;
    let spp = match spp {
        Some(n) => positive_u32(n, "spp")?,
        None => hints.spp_or_default(),
    };
    let max_depth = match max_depth {
        Some(d) if d < 0 => {
            return Err(PyValueError::new_err(format!(
                "max_depth {d}: must be 0 or more bounces (None: unbounded)"
            )))
        }
        Some(d) => Some(d.min(u32::MAX as i64 - 1) as u32),
        None => None,
    };
    let name = names
        .integrator
        .map(|s| s.parse::<IntegratorName>())
        .transpose()
        .map_err(value_error)?;
    let direct = names
        .direct
        .map(|s| s.parse::<DirectStrategy>())
        .transpose()
        .map_err(value_error)?;
    let lighting = names
        .lighting
        .map(|s| s.parse::<PathLighting>())
        .transpose()
        .map_err(value_error)?;
    if direct.is_some() && name != Some(IntegratorName::Direct) {
        return Err(PyValueError::new_err(
            "direct: a direct-lighting strategy needs integrator=\"direct\"",
        ));
    }
    let choice = IntegratorChoice {
        name,
        max_depth,
        direct,
        lighting: lighting.unwrap_or_default(),
        ..Default::default()
    };
    let (name, integrator) = choice.integrator(hints);
    if lighting.is_some() && name != IntegratorName::Path {
        return Err(PyValueError::new_err(format!(
            "lighting: the path tracer's way of finding light; this render uses integrator=\"{}\"",
            name.name()
        )));
    }
    let sampler = match sampler {
        Some(s) => s.parse::<SamplerKind>().map_err(value_error)?,
        None => hints.sampler_or_default(false),
    };
    let resolution = match resolution {
        Some(r) => checked_resolution(r)?,
        None => scene.desc.resolution,
    };
    if threads < 0 {
        return Err(PyValueError::new_err(format!(
            "threads {threads}: must be 0 (every core) or more"
        )));
    }
    let mut checked = Vec::new();
    for a in aovs {
        let aov = Aov::parse(&a)?;
        if let Aov::Bounce(k) = aov {
            if name != IntegratorName::Path {
                return Err(PyValueError::new_err(format!(
                    "aovs: '{a}' needs the path tracer (integrator=\"path\")"
                )));
            }
            if k > choice.max_depth(hints) {
                return Err(PyValueError::new_err(format!(
                    "aovs: '{a}' is beyond the largest bounce {}: it would be black",
                    choice.max_depth(hints)
                )));
            }
        }
        checked.push((a, aov));
    }
    let mut settings = RenderSettings::new(spp, seed, sampler);
    // The file's crop window, at the size the image has.
    settings.crop = hints.crop.and_then(|c| c.window_for(resolution));
    Ok(Request {
        settings,
        choice,
        hints: *hints,
        integrator,
        resolution,
        threads: threads as usize,
        aovs: checked,
    })
}

/// Render a scene to a float32 array (H, W, 3) of linear radiance, or with `aovs` a dict of
/// arrays; see `pathlab.render` for the arguments.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, seed=0, max_depth=None, integrator=None, direct=None, sampler=None, resolution=None, threads=0, aovs=Vec::new(), lighting=None))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    spp: Option<i64>,
    seed: u64,
    max_depth: Option<i64>,
    integrator: Option<&str>,
    direct: Option<&str>,
    sampler: Option<&str>,
    resolution: Option<(i64, i64)>,
    threads: i64,
    aovs: Vec<String>,
    lighting: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let names = Names {
        integrator,
        direct,
        lighting,
    };
    let req = {
        let s = scene.borrow();
        request(
            &s, spp, seed, max_depth, names, sampler, resolution, threads, aovs,
        )?
    };
    let built = scene.borrow_mut().built_at(py, req.resolution)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(req.threads)
        .build()
        .map_err(|e| PyValueError::new_err(format!("cannot start the worker threads: {e}")))?;
    let (film, _stats) = interruptible(py, &pool, &built, &req.integrator, &req.settings)?;
    let image = mean_image(py, &film);
    if req.aovs.is_empty() {
        return Ok(image.into_any());
    }
    let out = PyDict::new(py);
    out.set_item("image", image)?;
    for (key, aov) in &req.aovs {
        match *aov {
            Aov::Variance => out.set_item(key, variance_image(py, &film))?,
            Aov::Samples => out.set_item(key, sample_counts(py, &film))?,
            Aov::Bounce(k) => {
                let only = IntegratorChoice {
                    only_bounce: Some(k),
                    ..req.choice
                };
                let (_, only) = only.integrator(&req.hints);
                let (bounce, _) = interruptible(py, &pool, &built, &only, &req.settings)?;
                out.set_item(key, mean_image(py, &bounce))?;
            }
        }
    }
    Ok(out.into_any())
}

/// Renders on `pool` from another thread while this one waits without the GIL, taking it back
/// every 20 ms to run Python's signal handlers; an exception from one cancels the render and
/// is returned once the render has stopped.
fn interruptible(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    scene: &BuiltScene,
    integrator: &IntegratorKind,
    settings: &RenderSettings,
) -> PyResult<(Film, RenderStats)> {
    let cancel = AtomicBool::new(false);
    let done = AtomicBool::new(false);
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let out = pool.install(|| render_scene(scene, integrator, settings, &|_| {}, &cancel));
            done.store(true, Ordering::Release);
            out
        });
        let mut interrupted = None;
        loop {
            let finished = py.detach(|| {
                for _ in 0..4 {
                    if done.load(Ordering::Acquire) {
                        return true;
                    }
                    std::thread::sleep(Duration::from_millis(5));
                }
                done.load(Ordering::Acquire)
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                interrupted = Some(e);
                break;
            }
        }
        let result = py.detach(|| worker.join());
        match (interrupted, result) {
            (Some(e), _) => Err(e),
            (None, Ok(out)) => Ok(out),
            (None, Err(_)) => Err(pyo3::exceptions::PyRuntimeError::new_err(
                "the render thread panicked",
            )),
        }
    })
}

/// The film's mean radiance as an `(H, W, 3)` float32 array, written once into the buffer
/// numpy then owns.
pub fn mean_image<'py>(py: Python<'py>, film: &Film) -> Bound<'py, PyAny> {
    rgb_image(py, film, Film::pixel_value)
}

/// Each pixel's variance of its mean, `(H, W, 3)`.
fn variance_image<'py>(py: Python<'py>, film: &Film) -> Bound<'py, PyAny> {
    rgb_image(py, film, |f, i| f.pixels()[i].variance_of_mean())
}

/// `(H, W, 3)` float32 of a statistic of each pixel (by its index).
fn rgb_image<'py>(
    py: Python<'py>,
    film: &Film,
    statistic: impl Fn(&Film, usize) -> glam::DVec3,
) -> Bound<'py, PyAny> {
    let (w, h) = (film.width() as usize, film.height() as usize);
    let mut data = Vec::with_capacity(w * h * 3);
    for i in 0..film.pixels().len() {
        let v = statistic(film, i);
        data.extend([v.x as f32, v.y as f32, v.z as f32]);
    }
    Array3::from_shape_vec((h, w, 3), data)
        .expect("one RGB triple per pixel")
        .into_pyarray(py)
        .into_any()
}

fn sample_counts<'py>(py: Python<'py>, film: &Film) -> Bound<'py, PyAny> {
    let (w, h) = (film.width() as usize, film.height() as usize);
    Array2::from_shape_vec((h, w), film.sample_counts())
        .expect("one count per pixel")
        .into_pyarray(py)
        .into_any()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(render, m)?)?;
    Ok(())
}
