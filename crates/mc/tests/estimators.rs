//! The Monte Carlo estimator against known integrals, with tolerances from its standard error.

mod common;

use glam::Vec3;
use pathlab_mc::estimator::{integrate, integrate_parallel, RunningStats};
use pathlab_mc::sampler::{IndependentSampler, Sampler, SamplerKind};
use pathlab_mc::stats::{f_test_variance_ratio, z_test};
use pathlab_mc::warp::*;
use statrs::function::erf::erf;
use std::f64::consts::PI;

/// |estimate - truth| ≤ 4 standard errors.
const MAX_Z: f64 = 4.0;

#[test]
fn cosine_over_hemisphere_is_pi_with_uniform_sampling() {
    let mut s = IndependentSampler::new(1, 1);
    let est = integrate(
        |w: &Vec3| w.z as f64,
        &mut s,
        |s| {
            (
                sample_uniform_hemisphere(s.next_2d()),
                uniform_hemisphere_pdf() as f64,
            )
        },
        200_000,
    );
    let z = z_test(est.mean, est.std_error, PI);
    assert!(z.within(MAX_Z), "{est:?}, z = {}", z.z);
    assert!(est.ci95_half_width() > 0.0);
}

#[test]
fn cosine_over_hemisphere_has_zero_variance_with_cosine_sampling() {
    // f/p = cos θ / (cos θ / π) = π for every sample: importance sampling proportional to f.
    let mut s = IndependentSampler::new(1, 2);
    let est = integrate(
        |w: &Vec3| w.z as f64,
        &mut s,
        |s| {
            let w = sample_cosine_hemisphere(s.next_2d());
            (w, cosine_hemisphere_pdf(w.z) as f64)
        },
        10_000,
    );
    assert!(
        (est.mean - PI).abs() < 1e-5 && est.std_error < 1e-5,
        "{est:?}"
    );
}

/// The 2D Gaussian exp(-(x² + y²)/2) over [-2, 2]², sampled uniformly (pdf 1/16): the
/// estimator is 16/N Σ f(x_i, y_i).
fn gaussian_2d(x: f64, y: f64) -> f64 {
    (-(x * x + y * y) / 2.0).exp()
}

fn gaussian_2d_truth() -> f64 {
    let one = (2.0 * PI).sqrt() * erf(2.0 / 2f64.sqrt());
    one * one
}

fn gaussian_estimate(kind: SamplerKind, n: u32, seed: u64) -> pathlab_mc::estimator::Estimate {
    let mut s = kind.build(n, seed);
    integrate(
        |p: &[f64; 2]| gaussian_2d(p[0], p[1]),
        &mut s,
        |s| {
            let u = s.next_2d();
            (
                [-2.0 + 4.0 * u.x as f64, -2.0 + 4.0 * u.y as f64],
                1.0 / 16.0,
            )
        },
        n,
    )
}

#[test]
fn gaussian_over_square_matches_erf() {
    let est = gaussian_estimate(SamplerKind::Independent, 200_000, 3);
    let z = z_test(est.mean, est.std_error, gaussian_2d_truth());
    assert!(z.within(MAX_Z), "{est:?}, truth {}", gaussian_2d_truth());
}

#[test]
fn ten_dimensional_product_integral() {
    // ∏_{i=1}^{10} (π/2) sin(π x_i) over [0, 1]^10 = 1.
    let mut s = IndependentSampler::new(1, 4);
    let est = integrate(
        |x: &[f64; 10]| x.iter().map(|&xi| PI / 2.0 * (PI * xi).sin()).product(),
        &mut s,
        |s| {
            let mut x = [0.0; 10];
            x.iter_mut().for_each(|xi| *xi = s.next_1d() as f64);
            (x, 1.0)
        },
        400_000,
    );
    let z = z_test(est.mean, est.std_error, 1.0);
    assert!(z.within(MAX_Z), "{est:?}");
    // The variance is known too: ∏ E[g²] - 1 = (π²/8)^10 - 1.
    let var = (PI * PI / 8.0).powi(10) - 1.0;
    assert!(
        (est.variance - var).abs() < 0.25 * var,
        "variance {} vs {var}",
        est.variance
    );
}

#[test]
fn low_discrepancy_beats_independent_on_a_smooth_integrand() {
    // Mean squared error over independent replications (seeds), around the known truth.
    let (reps, n) = (40u64, 4096u32);
    let truth = gaussian_2d_truth();
    let mse = |kind: SamplerKind| -> f64 {
        (0..reps)
            .map(|r| (gaussian_estimate(kind, n, 1000 + r).mean - truth).powi(2))
            .sum::<f64>()
            / reps as f64
    };
    let independent = mse(SamplerKind::Independent);
    for kind in [SamplerKind::Stratified, SamplerKind::Sobol] {
        let other = mse(kind);
        let p = f_test_variance_ratio(independent, reps, other, reps);
        eprintln!(
            "{kind:?}: MSE {other:.3e} vs independent {independent:.3e} (ratio {:.1}), p = {p:.2e}",
            independent / other
        );
        assert!(
            p < 1e-4,
            "{kind:?}: MSE {other:.3e} vs independent {independent:.3e}, F-test p = {p:.2e}"
        );
    }
    // Every replication is unbiased: the replicated Sobol estimates' mean agrees with the truth.
    let mut stats = RunningStats::new();
    (0..reps).for_each(|r| stats.push(gaussian_estimate(SamplerKind::Sobol, n, 5000 + r).mean));
    assert!(z_test(stats.mean(), stats.std_error(), truth).within(MAX_Z));
}

#[test]
fn parallel_estimate_is_independent_of_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            integrate_parallel(
                |w: &Vec3| w.z as f64,
                &IndependentSampler::new(1, 9),
                |s| {
                    (
                        sample_uniform_sphere(s.next_2d()),
                        uniform_sphere_pdf() as f64,
                    )
                },
                100_000,
            )
        })
    };
    let (one, two, three) = (run(1), run(2), run(3));
    assert_eq!(one, two);
    assert_eq!(one, three);
    // ∫ cos θ over the whole sphere is 0.
    assert!(
        z_test(one.mean, one.std_error, 0.0).within(MAX_Z),
        "{one:?}"
    );
    // And it agrees with the sequential estimator up to rounding of the merge.
    let mut s = IndependentSampler::new(1, 9);
    let seq = integrate(
        |w: &Vec3| w.z as f64,
        &mut s,
        |s| {
            (
                sample_uniform_sphere(s.next_2d()),
                uniform_sphere_pdf() as f64,
            )
        },
        100_000,
    );
    assert!((seq.mean - one.mean).abs() < 1e-12 && seq.n == one.n);
}
