//! Environment-map sampling: chi-square goodness of fit of sampled directions against the
//! map's own pdf, and the light-sampling estimate of ∫ L dω against uniform sampling.

use glam::{Mat3, Vec2, Vec3};
use pathlab_mc::estimator::RunningStats;
use pathlab_mc::rng::Pcg32;
use pathlab_mc::stats::{chi2_test_2d_with_quadrature, cos_theta_phi, z_test_two_sample};
use pathlab_render::envmap::EnvironmentMap;
use std::f64::consts::TAU;

/// A 64 x 32 sky: a smooth gradient with a 3 x 3 sun 200 times brighter, rotated.
fn sky() -> EnvironmentMap {
    let (w, h) = (64, 32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let base = Vec3::new(0.2, 0.3, 0.5) * (1.0 + (y as f32 / h as f32))
                + Vec3::splat(0.05 * (x as f32 / w as f32));
            if (20..23).contains(&x) && (8..11).contains(&y) {
                base * 200.0
            } else {
                base
            }
        })
        .collect();
    EnvironmentMap::new(
        texels,
        w,
        h,
        Mat3::from_rotation_y(0.4) * Mat3::from_rotation_z(0.2),
        1.5,
    )
    .unwrap()
}

#[test]
fn environment_samples_fit_their_pdf() {
    let map = sky();
    let mut rng = Pcg32::new(1, 2);
    let samples: Vec<[f64; 2]> = (0..1_000_000)
        .map(|_| {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            match map.sample(u) {
                Some((d, _, _)) => cos_theta_phi(d.as_dvec3().to_array()),
                None => [9.0, 9.0],
            }
        })
        .collect();
    let direction = |z: f64, phi: f64| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
    };
    // The density is constant per map cell, whose edges do not line up with the bins: a fine
    // quadrature gets each bin's mass right.
    let t = chi2_test_2d_with_quadrature(
        samples,
        |z, phi| map.pdf(direction(z, phi)) as f64,
        [[-1.0, 1.0], [0.0, TAU]],
        [40, 40],
        16,
    );
    eprintln!(
        "environment map: chi2 {:.0} / {} dof, p = {:.3}",
        t.statistic, t.dof, t.p_value
    );
    assert!(t.passes(0.01), "p = {:.3e}", t.p_value);
}

#[test]
fn light_sampling_and_uniform_sampling_agree_on_the_total_radiance() {
    let map = sky();
    let n = 400_000;
    let mut rng = Pcg32::new(3, 4);
    let (mut by_map, mut uniform) = (RunningStats::new(), RunningStats::new());
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        by_map.push(map.sample(u).map_or(0.0, |(_, pdf, l)| (l.y / pdf) as f64));
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let d = pathlab_mc::warp::sample_uniform_sphere(u);
        uniform.push((map.eval(d).y / pathlab_mc::warp::uniform_sphere_pdf()) as f64);
    }
    let z = z_test_two_sample(
        by_map.mean(),
        by_map.std_error(),
        uniform.mean(),
        uniform.std_error(),
    );
    eprintln!(
        "∫ L dω: light sampling {:.4} ± {:.4}, uniform {:.4} ± {:.4} (z {:.2}); variance ratio {:.1}",
        by_map.mean(),
        by_map.std_error(),
        uniform.mean(),
        uniform.std_error(),
        z.z,
        uniform.variance() / by_map.variance()
    );
    assert!(z.within(4.0));
    // Importance sampling must help a map with a sun.
    assert!(by_map.variance() < uniform.variance());
}
