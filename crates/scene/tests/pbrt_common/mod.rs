//! Helpers of the pbrt-v4 tests: scenes written from text, and rendered.

use pathlab_mc::sampler::SamplerKind;
use pathlab_render::film::Film;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use pathlab_scene::Error;
use std::path::PathBuf;

/// Writes `files` (name, text) to a scratch folder and loads the first.
pub fn load_text(
    tag: &str,
    files: &[(&str, &str)],
) -> Result<pathlab_render::desc::SceneDesc, Error> {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("pbrt")
        .join(tag);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    pathlab_scene::load(dir.join(files[0].0).to_str().unwrap())
}

pub fn render_film(desc: &pathlab_render::desc::SceneDesc, spp: u32, seed: u64) -> Film {
    let scene = Scene::build(desc).unwrap();
    let integrator = IntegratorKind::Path(PathIntegrator {
        max_depth: desc.hints.max_depth.unwrap_or(u32::MAX),
        ..Default::default()
    });
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0
}

/// A furnace: a camera looking at the origin under a uniform sky of radiance 1, with paths as
/// long as they need; the scene's shapes follow.
// Used by the materials' tests; `pbrt.rs` includes this module without it.
#[allow(dead_code)]
pub const FURNACE: &str = r#"LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
Integrator "path" "integer maxdepth" [ 1000 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
"#;
