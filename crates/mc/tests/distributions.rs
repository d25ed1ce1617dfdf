//! Chi-square goodness-of-fit of the inversion-method distributions and the alias table.

mod common;

use common::{assert_fits, assert_rejects, draws};
use glam::Vec2;
use pathlab_mc::distribution::*;
use pathlab_mc::rng::Pcg32;
use pathlab_mc::sampler::Sampler;
use pathlab_mc::stats::{chi2_test_1d, chi2_test_2d, chi2_test_discrete};
use std::f64::consts::PI;

const N: u32 = 1_000_000;

/// Positive weights with some exact zeros, from a fixed seed.
fn weights(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = Pcg32::new(seed, 17);
    (0..n)
        .map(|i| {
            if i % 5 == 3 {
                0.0
            } else {
                0.05 + rng.uniform_f32() * 4.0
            }
        })
        .collect()
}

#[test]
fn exponential_fits_its_pdf() {
    let e = Exponential::new(1.5).unwrap();
    let xs = draws(N, 11, |s| e.sample(s.next_1d() as f64));
    // [0, 8]: the mass beyond (e^-12) forms the outside cell.
    let t = chi2_test_1d(xs, |x| e.pdf(x), [0.0, 8.0], 80);
    assert_fits("exponential", &t);
    // The wrong rate is rejected.
    let xs = draws(N, 12, |s| e.sample(s.next_1d() as f64));
    let wrong = Exponential::new(1.52).unwrap();
    assert_rejects(
        "exponential vs wrong rate",
        &chi2_test_1d(xs, |x| wrong.pdf(x), [0.0, 8.0], 80),
    );
}

#[test]
fn exponential_inverts_its_cdf() {
    let e = Exponential::new(1.0).unwrap();
    assert!((e.sample(0.75) - 4f64.ln()).abs() < 1e-12);
    for i in 0..1000 {
        let u = i as f64 / 1000.0;
        assert!((e.invert_sample(e.sample(u)) - u).abs() < 1e-12);
    }
    assert!(Exponential::new(0.0).is_err());
    assert!(Exponential::new(f64::NAN).is_err());
}

#[test]
fn piecewise_1d_fits_its_pdf() {
    // Pieces 0.25 wide and bins 0.125 wide: their edges are exact in f32 and f64 alike, so the
    // test's binning and the distribution agree on which piece a point at an edge is in.
    let f = weights(20, 1);
    let d = PiecewiseConstant1D::new(&f, -2.0, 3.0).unwrap();
    let xs = draws(N, 13, |s| d.sample(s.next_1d()).x as f64);
    let t = chi2_test_1d(xs, |x| d.pdf(x as f32) as f64, [-2.0, 3.0], 20 * 2);
    assert_fits("piecewise-constant 1D", &t);
}

#[test]
fn piecewise_1d_sample_agrees_with_pdf_and_inverse() {
    let f = weights(24, 2);
    let d = PiecewiseConstant1D::new(&f, -2.0, 3.0).unwrap();
    let mut rng = Pcg32::new(3, 3);
    for _ in 0..10_000 {
        let u = rng.uniform_f32();
        let s = d.sample(u);
        assert!(s.pdf > 0.0, "sampled a zero-density piece");
        assert_eq!(s.pdf, d.pdf(s.x));
        assert!((d.invert_sample(s.x) - u).abs() < 1e-5);
    }
    let int: f32 = f.iter().sum::<f32>() * 5.0 / 24.0;
    assert!((d.integral() - int).abs() < 1e-4 * int);
}

#[test]
fn piecewise_1d_discrete_fits_its_pmf() {
    let f = weights(30, 4);
    let d = PiecewiseConstant1D::new(&f, 0.0, 1.0).unwrap();
    let mut counts = vec![0u64; f.len()];
    for s in draws(N, 14, |s| d.sample_discrete(s.next_1d())) {
        counts[s.index] += 1;
        assert!(s.pmf > 0.0 && (0.0..1.0).contains(&s.u_remapped));
    }
    let pmf: Vec<f64> = (0..f.len()).map(|i| d.discrete_pmf(i) as f64).collect();
    assert_fits(
        "piecewise-constant discrete",
        &chi2_test_discrete(&counts, &pmf),
    );
}

#[test]
fn piecewise_all_zero_is_uniform() {
    let d = PiecewiseConstant1D::new(&[0.0; 4], 0.0, 2.0).unwrap();
    let xs = draws(100_000, 15, |s| d.sample(s.next_1d()).x as f64);
    assert_fits(
        "all-zero piecewise (uniform)",
        &chi2_test_1d(xs, |x| d.pdf(x as f32) as f64, [0.0, 2.0], 20),
    );
}

#[test]
fn piecewise_rejects_bad_input() {
    assert!(PiecewiseConstant1D::new(&[], 0.0, 1.0).is_err());
    assert!(PiecewiseConstant1D::new(&[1.0, -1.0], 0.0, 1.0).is_err());
    assert!(PiecewiseConstant1D::new(&[1.0, f32::NAN], 0.0, 1.0).is_err());
    assert!(PiecewiseConstant1D::new(&[1.0], 1.0, 1.0).is_err());
    assert!(PiecewiseConstant2D::new(&[1.0; 5], 2, 3, Vec2::ZERO, Vec2::ONE).is_err());
    assert!(AliasTable::new(&[0.0, 0.0]).is_err());
    assert!(AliasTable::new(&[]).is_err());
    assert!(AliasTable::new(&[1.0, f64::INFINITY]).is_err());
}

#[test]
fn piecewise_2d_fits_its_pdf() {
    let (nu, nv) = (16, 8);
    let mut f = weights(nu * nv, 5);
    // An all-zero row, as an environment map's black band would give.
    f[3 * nu..4 * nu].iter_mut().for_each(|v| *v = 0.0);
    let (min, max) = (Vec2::new(0.0, 0.0), Vec2::new(2.0 * PI as f32, PI as f32));
    let d = PiecewiseConstant2D::new(&f, nu, nv, min, max).unwrap();
    let pts = draws(N, 16, |s| {
        let (p, pdf) = d.sample(s.next_2d());
        assert!(pdf > 0.0 && (pdf - d.pdf(p)).abs() <= 1e-6 * pdf);
        [p.x as f64, p.y as f64]
    });
    let t = chi2_test_2d(
        pts,
        |x, y| d.pdf(Vec2::new(x as f32, y as f32)) as f64,
        [[0.0, 2.0 * PI], [0.0, PI]],
        [nu * 2, nv * 2],
    );
    assert_fits("piecewise-constant 2D", &t);
}

#[test]
fn piecewise_alias_2d_fits_its_pdf() {
    let (nu, nv) = (16, 8);
    let mut f = weights(nu * nv, 5);
    f[3 * nu..4 * nu].iter_mut().for_each(|v| *v = 0.0);
    let d = PiecewiseConstantAlias2D::new(&f, nu, nv).unwrap();
    let pts = draws(N, 16, |s| {
        let (p, pdf) = d.sample(s.next_2d());
        assert_eq!(pdf, d.pdf(p));
        [p.x as f64, p.y as f64]
    });
    let pdf = |x: f64, y: f64| d.pdf(Vec2::new(x as f32, y as f32)) as f64;
    // Bins of a quarter of a cell: the points must also be uniform within their cells.
    let t = chi2_test_2d(pts.clone(), pdf, [[0.0, 1.0], [0.0, 1.0]], [nu * 2, nv * 2]);
    assert_fits("piecewise-constant alias 2D", &t);
    // The same density as the marginal-conditional distribution of the same values.
    let cdf = PiecewiseConstant2D::new(&f, nu, nv, Vec2::ZERO, Vec2::ONE).unwrap();
    for (i, j) in (0..nu * 2).flat_map(|i| (0..nv * 2).map(move |j| (i, j))) {
        let p = Vec2::new(
            (i as f32 + 0.5) / (nu * 2) as f32,
            (j as f32 + 0.5) / (nv * 2) as f32,
        );
        assert!((d.pdf(p) - cdf.pdf(p)).abs() <= 1e-6 * cdf.pdf(p), "{p:?}");
    }
    // One cell's probability moved to its neighbour is rejected.
    let wrong = |x: f64, y: f64| {
        let (c, r) = ((x * nu as f64) as usize, (y * nv as f64) as usize);
        let shift = match (c, r) {
            (0, 0) => -0.5,
            (1, 0) => 0.5,
            _ => 0.0,
        };
        pdf(x, y) * (1.0 + shift * (f[0] + f[1]) as f64 / (2.0 * f[c + r * nu].max(1e-9) as f64))
    };
    let t = chi2_test_2d(pts, wrong, [[0.0, 1.0], [0.0, 1.0]], [nu * 2, nv * 2]);
    assert_rejects("piecewise-constant alias 2D vs wrong pdf", &t);
}

#[test]
fn piecewise_2d_inverts() {
    let f = weights(12 * 6, 6);
    let d = PiecewiseConstant2D::new(&f, 12, 6, Vec2::ZERO, Vec2::new(3.0, 2.0)).unwrap();
    let mut rng = Pcg32::new(9, 9);
    for _ in 0..5_000 {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let (p, _) = d.sample(u);
        assert!((d.invert_sample(p) - u).abs().max_element() < 1e-4, "{u:?}");
    }
}

#[test]
fn alias_table_fits_its_pmf() {
    let w: Vec<f64> = weights(50, 7).iter().map(|&x| x as f64).collect();
    let t = AliasTable::new(&w).unwrap();
    let total: f64 = w.iter().sum();
    let mut counts = vec![0u64; w.len()];
    for s in draws(N, 17, |s| t.sample(s.next_1d())) {
        counts[s.index] += 1;
        assert!((s.pmf - w[s.index] / total).abs() < 1e-12);
        assert!((0.0..1.0).contains(&s.u_remapped));
    }
    let pmf: Vec<f64> = (0..w.len()).map(|i| t.pmf(i)).collect();
    assert_fits("alias table", &chi2_test_discrete(&counts, &pmf));
    // A pmf with one outcome's probability moved to its neighbour is rejected.
    let mut wrong = pmf.clone();
    wrong[0] += 0.005;
    wrong[1] -= 0.005;
    assert_rejects("alias vs wrong pmf", &chi2_test_discrete(&counts, &wrong));
}

#[test]
fn alias_choose_draws_what_sample_draws() {
    // `choose` is `sample` without the remapped number: the same index and probability for
    // every u, so the chi-square test of `sample` covers it.
    let w: Vec<f64> = weights(50, 9).iter().map(|&x| x as f64).collect();
    let t = AliasTable::new(&w).unwrap();
    let edges = [0.0, 0.5, 1.0f32.next_down()];
    let us = draws(20_000, 19, |s| s.next_1d());
    for u in us.into_iter().chain(edges) {
        let s = t.sample(u);
        assert_eq!(t.choose(u), (s.index, s.pmf), "u = {u}");
    }
}

#[test]
fn alias_remapped_u_is_uniform() {
    // The remapped number must itself be uniform, so it can drive a second decision.
    let w = [1.0, 2.0, 3.0, 0.5];
    let t = AliasTable::new(&w).unwrap();
    let us = draws(N / 4, 18, |s| t.sample(s.next_1d()).u_remapped as f64);
    assert_fits(
        "alias remapped u",
        &chi2_test_1d(us, |_| 1.0, [0.0, 1.0], 50),
    );
}
