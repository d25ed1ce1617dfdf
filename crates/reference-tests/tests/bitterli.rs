//! Bitterli's pbrt-v4 scenes (`tests/data/bitterli`) against the reference images he rendered
//! with Tungsten: rendered at a quarter of the reference's resolution with a box filter (the
//! reference is averaged over 4 x 4 blocks, which is a box filter at that size), the image mean
//! within 3% per channel and the mean over pixels of (ours - ref)² / (ref² + 0.01) below 0.02.

use glam::DVec3;
use pathlab_render::image_io::read_exr_rgb;
use pathlab_render::scene::Scene;
use pathlab_testkit::render::{path, render_independent};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/bitterli")
        .join(name)
}

/// Renders a Bitterli scene at a quarter of its resolution and compares it with Tungsten's
/// reference reduced the same way: (image mean ratio per channel, relative MSE).
fn against_tungsten(scene: &str, spp: u32) -> (DVec3, f64) {
    let mut desc =
        pathlab_scene::load(data(scene).join("scene-v4.pbrt").to_str().unwrap()).unwrap();
    let (w, h, reference) = read_exr_rgb(&data(scene).join("tungsten-quarter.exr")).unwrap();
    desc.resolution = [w, h];
    // Averaging 4 x 4 blocks of the reference is a box filter at this resolution.
    desc.filter = pathlab_render::desc::PixelFilter::Box;
    let built = Scene::build(&desc).unwrap();
    let integrator = path(desc.hints.max_depth.unwrap_or(u32::MAX));
    let film = render_independent(&built, &integrator, spp, 7).0;
    let ours = film.mean_image();
    let mean =
        |img: &[glam::Vec3]| img.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / img.len() as f64;
    let ratio = mean(&ours) / mean(&reference);
    let rel = ours
        .iter()
        .zip(&reference)
        .map(|(a, b)| {
            let (a, b) = (a.as_dvec3(), b.as_dvec3());
            ((a - b) * (a - b) / (b * b + DVec3::splat(0.01))).element_sum() / 3.0
        })
        .sum::<f64>()
        / ours.len() as f64;
    eprintln!("{scene} at {w}x{h}, {spp} spp: image mean / Tungsten's {ratio:.4}, relative MSE {rel:.4}; warnings {:?}", desc.warnings);
    (ratio, rel)
}

#[test]
fn bitterli_cornell_box_matches_tungsten() {
    let desc =
        pathlab_scene::load(data("cornell-box").join("scene-v4.pbrt").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let (ratio, rel) = against_tungsten("cornell-box", 128);
    assert!((ratio - DVec3::ONE).abs().max_element() < 0.03, "{ratio}");
    assert!(rel < 0.02, "relative MSE {rel}");
}

#[test]
#[ignore = "open: the plates reflect 2.5 times the light they do in Tungsten's render (see issue 16's note)"]
fn bitterli_veach_mis_matches_tungsten() {
    let (ratio, rel) = against_tungsten("veach-mis", 256);
    assert!((ratio - DVec3::ONE).abs().max_element() < 0.03, "{ratio}");
    assert!(rel < 0.02, "relative MSE {rel}");
}

#[test]
#[ignore = "open: unidirectional paths reach its light through the lamp's glossy shade too rarely for the noise to fall below the bound in a minute"]
fn bitterli_veach_bidir_matches_tungsten() {
    let (ratio, rel) = against_tungsten("veach-bidir", 256);
    assert!((ratio - DVec3::ONE).abs().max_element() < 0.03, "{ratio}");
    assert!(rel < 0.02, "relative MSE {rel}");
}
