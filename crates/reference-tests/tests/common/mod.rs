//! What the reference tests of the Cornell box share: Mitsuba 3's reference images (mean and
//! standard error), renders of the box, and the pixel, block and image-mean comparisons.
#![allow(dead_code)]

use pathlab_mc::sampler::SamplerKind;
use pathlab_render::film::Film;
use pathlab_render::integrator::IntegratorKind;
use pathlab_render::render::{render, RenderSettings, RenderStats};
use pathlab_render::scene::Scene;
use std::path::PathBuf;

#[allow(unused_imports)] // each test file uses a part
pub use pathlab_testkit::reference::*;
#[allow(unused_imports)] // each test file uses a part
pub use pathlab_testkit::render::{path, MAX_Z};

pub fn reference(mitsuba_depth: &str) -> Reference {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cornell-box");
    let r = Reference::read(&dir, mitsuba_depth);
    assert_eq!(r.mean.len(), 256 * 256);
    r
}

pub fn render_cornell(integrator: IntegratorKind, spp: u32, seed: u64) -> Film {
    render_cornell_window(integrator, spp, seed, None)
}

pub fn render_cornell_window(
    integrator: IntegratorKind,
    spp: u32,
    seed: u64,
    crop: Option<[u32; 4]>,
) -> Film {
    let desc = pathlab_scene::builtin::cornell_box().unwrap();
    let scene = Scene::build(&desc).unwrap();
    let settings = RenderSettings {
        crop,
        ..RenderSettings::new(spp, seed, SamplerKind::Independent)
    };
    render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0
}

/// Renders `scene` by path tracing to `max_depth` with `spp` independent samples per pixel.
pub fn render_independent(
    scene: &Scene,
    max_depth: u32,
    spp: u32,
    seed: u64,
) -> (Film, RenderStats) {
    pathlab_testkit::render::render_independent(scene, &path(max_depth), spp, seed)
}

/// Renders a reference folder's scene.xml at -m inf and loads its reference.
pub fn render_reference_scene(folder: &str, spp: u32, seed: u64) -> (Film, Reference) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(folder);
    let desc = pathlab_scene::mitsuba::load(&dir.join("scene.xml")).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let scene = Scene::build(&desc).unwrap();
    let film = render_independent(&scene, u32::MAX, spp, seed).0;
    (film, Reference::read(&dir, "inf"))
}

/// Two seeds of an adaptive render of the Cornell box at -m inf with batches of 32, tolerance
/// 0.05 and a cap of 512 (the course's settings), merged: (film, mean spp of the estimate,
/// mean pilot spp).
pub fn adaptive_two_seeds(rule: pathlab_render::render::AdaptiveRule) -> (Film, f64, f64) {
    use pathlab_render::render::Adaptive;
    let desc = pathlab_scene::builtin::cornell_box().unwrap();
    let scene = Scene::build(&desc).unwrap();
    let mut merged: Option<Film> = None;
    let (mut samples, mut pilot) = (0u64, 0u64);
    for seed in [61, 62] {
        let mut settings = RenderSettings::new(512, seed, SamplerKind::Independent);
        settings.adaptive = Some(Adaptive {
            rule,
            ..Adaptive::DEFAULT
        });
        let (film, stats) = render(
            &scene,
            &path(u32::MAX),
            &settings,
            &|_| {},
            &Default::default(),
        );
        samples += stats.samples;
        pilot += stats.pilot_samples;
        match merged.as_mut() {
            None => merged = Some(film),
            Some(m) => {
                for (a, b) in m.pixels_mut().iter_mut().zip(film.pixels()) {
                    a.merge(b);
                }
            }
        }
    }
    let film = merged.unwrap();
    let per_pixel = 2.0 * film.pixels().len() as f64;
    (film, samples as f64 / per_pixel, pilot as f64 / per_pixel)
}
