//! Chi-square goodness-of-fit of every warp against its own pdf, and the same harness
//! rejecting deliberately wrong pdfs.

mod common;

use common::{assert_fits, assert_rejects, cos_theta_phi, draws};
use glam::{Vec2, Vec3};
use pathlab_mc::sampler::Sampler;
use pathlab_mc::stats::chi2_test_2d;
use pathlab_mc::warp::*;
use std::f64::consts::{PI, TAU};

const N: u32 = 1_000_000;
const RES: [usize; 2] = [40, 40];

/// Chi-square test of a direction warp against a solid-angle pdf over `cos θ in [z0, 1]`.
fn test_directions(
    warp: impl Fn(Vec2) -> Vec3,
    pdf: impl Fn(Vec3) -> f32,
    z0: f64,
    seed: u64,
) -> pathlab_mc::stats::ChiSquareTest {
    let samples = draws(N, seed, |s| cos_theta_phi(warp(s.next_2d())));
    chi2_test_2d(
        samples,
        |z, phi| {
            let r = (1.0 - z * z).max(0.0).sqrt();
            pdf(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            )) as f64
        },
        [[z0, 1.0], [0.0, TAU]],
        RES,
    )
}

#[test]
fn uniform_hemisphere_fits_its_pdf() {
    let t = test_directions(
        sample_uniform_hemisphere,
        |_| uniform_hemisphere_pdf(),
        0.0,
        1,
    );
    assert_fits("uniform hemisphere", &t);
}

#[test]
fn cosine_hemisphere_fits_its_pdf() {
    let t = test_directions(
        sample_cosine_hemisphere,
        |w| cosine_hemisphere_pdf(w.z),
        0.0,
        2,
    );
    assert_fits("cosine hemisphere", &t);
}

#[test]
fn uniform_sphere_fits_its_pdf() {
    let t = test_directions(sample_uniform_sphere, |_| uniform_sphere_pdf(), -1.0, 3);
    assert_fits("uniform sphere", &t);
}

#[test]
fn uniform_cone_fits_its_pdf() {
    let cos_max = 0.83f32;
    let t = test_directions(
        |u| sample_uniform_cone(u, cos_max),
        |w| {
            if w.z >= cos_max {
                uniform_cone_pdf(cos_max)
            } else {
                0.0
            }
        },
        cos_max as f64,
        4,
    );
    assert_fits("uniform cone", &t);
}

#[test]
fn concentric_disk_fits_its_pdf() {
    // Tested in polar coordinates (r, φ), where the area density becomes r · pdf(p).
    let samples = draws(N, 5, |s| {
        let p = sample_uniform_disk_concentric(s.next_2d());
        [
            p.length() as f64,
            pathlab_mc::stats::azimuth(p.y as f64, p.x as f64),
        ]
    });
    let t = chi2_test_2d(
        samples,
        |r, phi| {
            let p = Vec2::new((r * phi.cos()) as f32, (r * phi.sin()) as f32);
            r * uniform_disk_pdf(p) as f64
        },
        [[0.0, 1.0], [0.0, TAU]],
        RES,
    );
    assert_fits("concentric disk", &t);
}

#[test]
fn uniform_triangle_fits_its_pdf() {
    // Barycentrics (b0, b1) fill a triangle of area 1/2 with density 2 = pdf(area 1/2).
    // Tested in (b0, t = b1 / (1 - b0)) on the unit square, where the density is 2 (1 - b0).
    let samples = draws(N, 6, |s| {
        let b = sample_uniform_triangle(s.next_2d());
        let t = if b[0] < 1.0 { b[1] / (1.0 - b[0]) } else { 0.0 };
        [b[0] as f64, t as f64]
    });
    let t = chi2_test_2d(
        samples,
        |b0, _| uniform_triangle_pdf(0.5) as f64 * (1.0 - b0),
        [[0.0, 1.0], [0.0, 1.0]],
        RES,
    );
    assert_fits("uniform triangle", &t);
}

#[test]
fn wrong_pdfs_are_rejected() {
    // Uniform samples against the cosine pdf, and the other way round.
    let t = test_directions(
        sample_uniform_hemisphere,
        |w| cosine_hemisphere_pdf(w.z),
        0.0,
        7,
    );
    assert_rejects("uniform samples vs cosine pdf", &t);
    let t = test_directions(
        sample_cosine_hemisphere,
        |_| uniform_hemisphere_pdf(),
        0.0,
        8,
    );
    assert_rejects("cosine samples vs uniform pdf", &t);
    // A pdf that is right in shape but integrates to 1.02 (mass missing from the samples).
    let t = test_directions(
        sample_cosine_hemisphere,
        |w| 1.02 * cosine_hemisphere_pdf(w.z),
        0.0,
        9,
    );
    assert_rejects("cosine pdf scaled by 1.02", &t);
    // Samples where the pdf is zero: hemisphere samples against the lower hemisphere only.
    let samples = draws(10_000, 10, |s| {
        cos_theta_phi(sample_uniform_hemisphere(s.next_2d()))
    });
    let t = chi2_test_2d(
        samples,
        |z, _| if z < 0.0 { 1.0 / TAU } else { 0.0 },
        [[-1.0, 1.0], [0.0, TAU]],
        RES,
    );
    assert_rejects("upper-hemisphere samples vs lower-hemisphere pdf", &t);
    assert!(t.impossible_samples > 0);
}

#[test]
fn pdfs_integrate_to_one() {
    // Deterministic midpoint quadrature over (cos θ, φ); the smooth densities converge fast.
    let m = 400;
    let mut hemi = 0.0;
    let mut cosine = 0.0;
    for i in 0..m {
        let z = (i as f64 + 0.5) / m as f64;
        hemi += uniform_hemisphere_pdf() as f64 * TAU / m as f64;
        cosine += cosine_hemisphere_pdf(z as f32) as f64 * TAU / m as f64;
    }
    assert!((hemi - 1.0).abs() < 1e-6 && (cosine - 1.0).abs() < 1e-6);
    assert!((uniform_sphere_pdf() as f64 * 4.0 * PI - 1.0).abs() < 1e-6);
    assert!((uniform_disk_pdf(Vec2::ZERO) as f64 * PI - 1.0).abs() < 1e-6);
    let cos_max = 0.3f32;
    assert!((uniform_cone_pdf(cos_max) as f64 * TAU * (1.0 - cos_max as f64) - 1.0).abs() < 1e-6);
}
