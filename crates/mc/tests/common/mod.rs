//! Shared helpers of the toolkit's statistical tests.
#![allow(dead_code)]

use pathlab_mc::sampler::{IndependentSampler, Sampler};
use pathlab_mc::stats::{bonferroni, ChiSquareTest};

/// Family-wise significance level of the chi-square tests of this crate's suite.
pub const SUITE_ALPHA: f64 = 0.01;

/// Number of goodness-of-fit tests in this crate's suite that must *pass* (the Bonferroni
/// correction divides the level among them). Update it when adding one.
pub const SUITE_TESTS: usize = 16;

/// The per-test significance level.
pub fn alpha() -> f64 {
    bonferroni(SUITE_ALPHA, SUITE_TESTS)
}

/// Asserts that a chi-square test does not reject at the suite's corrected level.
pub fn assert_fits(name: &str, t: &ChiSquareTest) {
    eprintln!(
        "{name}: chi2 = {:.1}, dof = {}, p = {:.3}",
        t.statistic, t.dof, t.p_value
    );
    assert!(
        t.passes(alpha()),
        "{name}: chi-square rejects the pdf: statistic {:.1}, {} dof, p = {:.3e} < {:.1e} \
         ({} samples, {} impossible)",
        t.statistic,
        t.dof,
        t.p_value,
        alpha(),
        t.samples,
        t.impossible_samples
    );
}

/// Asserts that a chi-square test rejects, as it must for a deliberately wrong pdf.
pub fn assert_rejects(name: &str, t: &ChiSquareTest) {
    eprintln!(
        "{name} (wrong on purpose): chi2 = {:.1}, dof = {}, p = {:.3e}",
        t.statistic, t.dof, t.p_value
    );
    assert!(
        !t.passes(alpha()),
        "{name}: chi-square failed to reject a wrong pdf: statistic {:.1}, {} dof, p = {:.3e}",
        t.statistic,
        t.dof,
        t.p_value
    );
}

/// `n` independent draws of `f` applied to a fresh sampler state per sample (fixed seed).
pub fn draws<T>(n: u32, seed: u64, mut f: impl FnMut(&mut IndependentSampler) -> T) -> Vec<T> {
    let mut s = IndependentSampler::new(1, seed);
    (0..n)
        .map(|i| {
            s.start_pixel_sample([0, 0], i, 0);
            f(&mut s)
        })
        .collect()
}

/// (cos θ, φ) of a direction, φ in [0, 2π): the parameterisation in which a solid-angle density
/// is a density per unit area.
pub fn cos_theta_phi(w: glam::Vec3) -> [f64; 2] {
    pathlab_mc::stats::cos_theta_phi(w.as_dvec3().to_array())
}
