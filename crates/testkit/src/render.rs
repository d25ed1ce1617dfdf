//! Renders for tests (independent samples, so that each pixel's variance estimate is honest)
//! and the z-tests of their results.

use glam::DVec3;
use pathlab_mc::sampler::SamplerKind;
use pathlab_mc::stats::z_test_two_sample;
use pathlab_render::desc::SceneDesc;
use pathlab_render::film::Film;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings, RenderStats};
use pathlab_render::scene::Scene;

/// A value is an outlier when it is more than this many standard errors away.
pub const MAX_Z: f64 = 4.0;

/// The path tracer to `max_depth` bounces, with its other settings at their defaults.
pub fn path(max_depth: u32) -> IntegratorKind {
    IntegratorKind::Path(PathIntegrator {
        max_depth,
        ..Default::default()
    })
}

/// `scene` rendered with `spp` independent samples per pixel.
pub fn render_independent(
    scene: &Scene,
    integrator: &IntegratorKind,
    spp: u32,
    seed: u64,
) -> (Film, RenderStats) {
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    render(scene, integrator, &settings, &|_| {}, &Default::default())
}

/// The scene `desc` describes, built and rendered with independent samples.
pub fn render_desc(desc: &SceneDesc, integrator: IntegratorKind, spp: u32, seed: u64) -> Film {
    let scene = Scene::build(desc).expect("the test's scene builds");
    render_independent(&scene, &integrator, spp, seed).0
}

/// Asserts that every channel of the image mean is within [`MAX_Z`] standard errors of
/// `truth`.
pub fn assert_mean(name: &str, film: &Film, truth: DVec3) {
    let (m, se) = (film.image_mean(), film.image_mean_std_error());
    eprintln!("{name}: mean {m:.5?} ± {se:.5?}, expected {truth:?}");
    for c in 0..3 {
        assert!(
            // The second term is the single-precision rounding of the radiance computation.
            (m[c] - truth[c]).abs() <= MAX_Z * se[c] + 1e-6 * truth[c].abs(),
            "{name}: channel {c}: {} vs {} (se {})",
            m[c],
            truth[c],
            se[c]
        );
    }
}

/// Per-pixel two-sample z-tests of two independent renders of one image: at most 0.1% of
/// pixel channels beyond [`MAX_Z`] (rounded up to 1; differences within single-precision
/// rounding are none), and image means within 3 combined standard errors.
pub fn assert_same_image(name: &str, a: &Film, b: &Film) {
    let mut outliers = 0;
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let (va, vb) = (p.variance_of_mean(), q.variance_of_mean());
        for c in 0..3 {
            let (ma, mb) = (p.mean()[c], q.mean()[c]);
            let z = z_test_two_sample(ma, va[c].sqrt(), mb, vb[c].sqrt());
            // A difference within the rounding of single-precision values is none, as in
            // `assert_mean`: a pixel whose samples all take one value but for an ulp has a
            // variance of zero, against which any difference would count.
            let rounding = 1e-6 * ma.abs().max(mb.abs());
            outliers += (!z.within(MAX_Z) && (ma - mb).abs() > rounding) as usize;
        }
    }
    let allowed = (a.pixels().len() * 3) / 1000 + 1;
    assert!(
        outliers <= allowed,
        "{name}: {outliers} pixel channels beyond {MAX_Z} sigma"
    );
    assert_same_mean(name, a, b);
}

/// Asserts that two independent renders' image means agree within 3 combined standard errors
/// in every channel.
pub fn assert_same_mean(name: &str, a: &Film, b: &Film) {
    let (ma, mb) = (a.image_mean(), b.image_mean());
    let (sa, sb) = (a.image_mean_std_error(), b.image_mean_std_error());
    for c in 0..3 {
        let z = z_test_two_sample(ma[c], sa[c], mb[c], sb[c]);
        assert!(
            z.within(3.0),
            "{name}: image mean channel {c}: {} vs {} (z {})",
            ma[c],
            mb[c],
            z.z
        );
    }
}
