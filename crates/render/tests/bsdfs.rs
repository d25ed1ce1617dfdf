//! Statistical tests of every BSDF: chi-square goodness of fit of `sample` against `pdf`,
//! agreement of the sampled weight f |cos| / pdf with an independent estimate of the same
//! integral, directional albedo ≤ 1, exact energy conservation where the model has it, and
//! reciprocity.

use glam::{Vec2, Vec3};
use pathlab_mc::estimator::RunningStats;
use pathlab_mc::rng::Pcg32;
use pathlab_mc::stats::{
    bonferroni, chi2_test_2d, chi2_test_2d_with_quadrature, cos_theta_phi, z_test_two_sample,
};
use pathlab_render::bsdf::*;
use std::f64::consts::TAU;

mod bsdf_models;
use bsdf_models::*;

/// Samples in each goodness-of-fit test.
const N: usize = 1_000_000;
/// Bins in (cos θ, φ).
const RES: [usize; 2] = [40, 40];
/// Quadrature pieces per bin axis: microfacet pdfs have narrow peaks and, where the half
/// vector crosses the horizon, jumps inside bins.
const QUADRATURE: usize = 12;

fn uniform(rng: &mut Pcg32) -> (f32, Vec2) {
    (
        rng.uniform_f32(),
        Vec2::new(rng.uniform_f32(), rng.uniform_f32()),
    )
}

fn direction(z: f64, phi: f64) -> Vec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// The non-delta samples of `bxdf` from `wo` as (cos θ, φ); delta and failed samples map
/// outside every test domain.
fn draws(bxdf: &Bxdf, wo: Vec3, n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = Pcg32::new(seed, 7);
    (0..n)
        .map(|_| {
            let (uc, u) = uniform(&mut rng);
            match bxdf.sample(wo, uc, u) {
                Some(s) if !s.delta => cos_theta_phi(s.wi.as_dvec3().to_array()),
                _ => [9.0, 9.0],
            }
        })
        .collect()
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// The domain of a test: the box in (cos θ, φ) holding the central 99% of a pilot run's
/// samples on one side of the surface (`upper`), widened by a tenth, so that the bins sit
/// where the lobe is however narrow it is. `None` when that side receives under 1% of the
/// samples.
fn pilot_domain(bxdf: &Bxdf, wo: Vec3, upper: bool, seed: u64) -> Option<[[f64; 2]; 2]> {
    let pilot: Vec<[f64; 2]> = draws(bxdf, wo, 40_000, seed ^ 0x5eed)
        .into_iter()
        .filter(|s| s[0] <= 1.0 && (s[0] > 0.0) == upper)
        .collect();
    if pilot.len() < 400 {
        return None;
    }
    let range = |axis: usize, lo: f64, hi: f64| {
        let mut v: Vec<f64> = pilot.iter().map(|s| s[axis]).collect();
        v.sort_by(f64::total_cmp);
        let (a, b) = (quantile(&v, 0.005), quantile(&v, 0.995));
        let pad = 0.1 * (b - a).max(1e-3);
        [(a - pad).max(lo), (b + pad).min(hi)]
    };
    let z = if upper {
        range(0, 0.0, 1.0)
    } else {
        range(0, -1.0, 0.0)
    };
    let mut phi = range(1, 0.0, TAU);
    if phi[1] - phi[0] > std::f64::consts::PI {
        phi = [0.0, TAU];
    }
    Some([z, phi])
}

struct Case {
    name: String,
    bxdf: Bxdf,
    wo: Vec3,
}

fn cases() -> Vec<Case> {
    let mut v = Vec::new();
    let mut add = |name: String, bxdf: Bxdf, wo: Vec3| v.push(Case { name, bxdf, wo });
    for theta in [0.0, 60.0] {
        add(
            format!("diffuse θo {theta}"),
            diffuse(),
            wo_at(theta, false),
        );
    }
    for (theta, below) in [(30.0, false), (70.0, true)] {
        add(
            format!("diffuse transmission θo {theta} below {below}"),
            diffuse_transmission(),
            wo_at(theta, below),
        );
    }
    for (kind, label) in [
        (NormalDistribution::Ggx, "GGX"),
        (NormalDistribution::Beckmann, "Beckmann"),
    ] {
        for alpha in [0.05, 0.3, 0.8] {
            for theta in [5.0, 45.0, 85.0] {
                add(
                    format!("{label} conductor α {alpha} θo {theta}"),
                    conductor(kind, alpha),
                    wo_at(theta, false),
                );
                add(
                    format!("{label} rough glass α {alpha} θo {theta} outside"),
                    rough_glass(kind, alpha),
                    wo_at(theta, false),
                );
            }
            // From inside the glass, below and beyond the critical angle (41.8°).
            for theta in [20.0, 60.0] {
                add(
                    format!("{label} rough glass α {alpha} θo {theta} inside"),
                    rough_glass(kind, alpha),
                    wo_at(theta, true),
                );
            }
        }
    }
    for theta in [30.0, 80.0] {
        add(
            format!("plastic θo {theta}"),
            plastic(0.6, false),
            wo_at(theta, false),
        );
    }
    for (kind, label) in [
        (NormalDistribution::Ggx, "GGX"),
        (NormalDistribution::Beckmann, "Beckmann"),
    ] {
        for (ax, ay) in [(0.1, 0.4), (0.6, 0.15)] {
            for (theta, phi) in [(20.0, 30.0), (70.0, 120.0)] {
                add(
                    format!("{label} anisotropic conductor α ({ax}, {ay}) θo {theta} φo {phi}"),
                    anisotropic_conductor(kind, ax, ay),
                    wo_at_azimuth(theta, phi),
                );
                add(
                    format!("{label} anisotropic rough glass α ({ax}, {ay}) θo {theta} φo {phi}"),
                    anisotropic_rough_glass(kind, ax, ay),
                    wo_at_azimuth(theta, phi),
                );
            }
        }
        for alpha in [0.1, 0.6] {
            for theta in [10.0, 70.0] {
                add(
                    format!("{label} rough plastic α {alpha} θo {theta}"),
                    rough_plastic(kind, alpha),
                    wo_at(theta, false),
                );
            }
        }
    }
    for (thin, label) in [(false, "principled"), (true, "principled thin")] {
        for roughness in [0.3, 0.8] {
            for (theta, below) in [(15.0, false), (70.0, false), (40.0, true)] {
                add(
                    format!("{label} roughness {roughness} θo {theta} below {below}"),
                    principled(thin, roughness),
                    wo_at_azimuth(theta, 40.0)
                        * if below {
                            Vec3::new(1.0, 1.0, -1.0)
                        } else {
                            Vec3::ONE
                        },
                );
            }
        }
    }
    v
}

#[test]
fn every_bsdf_sample_fits_its_pdf() {
    let cases = cases();
    // Each case is tested on each side of the surface that receives samples.
    let tests: Vec<(usize, bool, [[f64; 2]; 2])> = cases
        .iter()
        .enumerate()
        .flat_map(|(i, c)| {
            [true, false].into_iter().filter_map(move |upper| {
                pilot_domain(&c.bxdf, c.wo, upper, i as u64).map(|d| (i, upper, d))
            })
        })
        .collect();
    let alpha = bonferroni(0.01, tests.len());
    let mut failures = Vec::new();
    for &(i, upper, domain) in &tests {
        let c = &cases[i];
        let samples = draws(&c.bxdf, c.wo, N, 1000 + i as u64);
        let t = chi2_test_2d_with_quadrature(
            samples,
            |z, phi| c.bxdf.pdf(c.wo, direction(z, phi)) as f64,
            domain,
            RES,
            QUADRATURE,
        );
        let side = if upper { "upper" } else { "lower" };
        eprintln!(
            "{} ({side}): chi2 {:.0} / {} dof, p = {:.3}",
            c.name, t.statistic, t.dof, t.p_value
        );
        if !t.passes(alpha) {
            failures.push(format!("{} ({side}): p = {:.2e}", c.name, t.p_value));
        }
    }
    assert!(
        tests.len() >= cases.len(),
        "only {} tests for {} cases",
        tests.len(),
        cases.len()
    );
    assert!(
        failures.is_empty(),
        "rejected at α = {alpha:.1e}: {failures:?}"
    );
}

#[test]
fn chi_square_harness_rejects_a_wrong_microfacet_pdf() {
    // GGX samples against a Beckmann pdf of the same roughness: must be rejected.
    let wo = wo_at(45.0, false);
    let ggx = conductor(NormalDistribution::Ggx, 0.3);
    let beckmann = conductor(NormalDistribution::Beckmann, 0.3);
    let domain = pilot_domain(&ggx, wo, true, 3).unwrap();
    let t = chi2_test_2d(
        draws(&ggx, wo, N, 3),
        |z, phi| beckmann.pdf(wo, direction(z, phi)) as f64,
        domain,
        RES,
    );
    eprintln!("GGX vs Beckmann pdf: p = {:.3e}", t.p_value);
    assert!(t.p_value < 1e-6);
}

/// (mean, standard error) of f |cos θi| / pdf over BSDF samples (delta lobes included).
fn sampled_albedo(bxdf: &Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 11);
    let mut stats = RunningStats::new();
    for _ in 0..n {
        let (uc, u) = uniform(&mut rng);
        let w = bxdf
            .sample(wo, uc, u)
            .map_or(0.0, |s| (s.f.y * s.wi.z.abs() / s.pdf) as f64);
        stats.push(w);
    }
    (stats.mean(), stats.std_error())
}

/// (mean, standard error) of ∫ f |cos θi| dωi over the sphere by uniform direction sampling:
/// an estimator that shares nothing with the BSDF's own sampling.
fn uniform_albedo(bxdf: &Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 13);
    let mut stats = RunningStats::new();
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let wi = pathlab_mc::warp::sample_uniform_sphere(u);
        let pdf = pathlab_mc::warp::uniform_sphere_pdf();
        stats.push((bxdf.f(wo, wi).y * wi.z.abs() / pdf) as f64);
    }
    (stats.mean(), stats.std_error())
}

#[test]
fn sampled_weights_agree_with_uniform_integration_and_albedo_is_at_most_one() {
    // For non-delta BSDFs wide enough for uniform sampling to resolve: E[f cos / pdf] under
    // the BSDF's sampling must equal ∫ f cos dω, which uniform sampling estimates
    // independently (this checks f and pdf against each other, the chi-square test checks
    // sample against pdf). And the directional albedo never exceeds one.
    let cases: Vec<(String, Bxdf, Vec3)> = [
        ("diffuse", diffuse()),
        (
            "GGX conductor α 0.3",
            conductor(NormalDistribution::Ggx, 0.3),
        ),
        (
            "GGX conductor α 0.8",
            conductor(NormalDistribution::Ggx, 0.8),
        ),
        (
            "Beckmann conductor α 0.3",
            conductor(NormalDistribution::Beckmann, 0.3),
        ),
        (
            "Beckmann conductor α 0.8",
            conductor(NormalDistribution::Beckmann, 0.8),
        ),
        (
            "GGX rough glass α 0.3",
            rough_glass(NormalDistribution::Ggx, 0.3),
        ),
        (
            "GGX rough glass α 0.8",
            rough_glass(NormalDistribution::Ggx, 0.8),
        ),
        (
            "Beckmann rough glass α 0.5",
            rough_glass(NormalDistribution::Beckmann, 0.5),
        ),
        (
            "GGX anisotropic conductor α (0.2, 0.6)",
            anisotropic_conductor(NormalDistribution::Ggx, 0.2, 0.6),
        ),
        (
            "Beckmann anisotropic conductor α (0.6, 0.25)",
            anisotropic_conductor(NormalDistribution::Beckmann, 0.6, 0.25),
        ),
        (
            "GGX anisotropic rough glass α (0.3, 0.7)",
            anisotropic_rough_glass(NormalDistribution::Ggx, 0.3, 0.7),
        ),
        (
            "GGX rough plastic α 0.3",
            rough_plastic(NormalDistribution::Ggx, 0.3),
        ),
        (
            "Beckmann rough plastic α 0.6",
            rough_plastic(NormalDistribution::Beckmann, 0.6),
        ),
        ("principled roughness 0.5", principled(false, 0.5)),
        ("principled thin roughness 0.5", principled(true, 0.5)),
        ("diffuse transmission", diffuse_transmission()),
    ]
    .into_iter()
    .flat_map(|(name, b)| {
        [(10.0, false), (70.0, false), (30.0, true)]
            .into_iter()
            .filter(move |&(_, below)| {
                !below
                    || matches!(
                        b,
                        Bxdf::RoughDielectric(_)
                            | Bxdf::Principled(_)
                            | Bxdf::DiffuseTransmission(_)
                    )
            })
            .map(move |(theta, below)| {
                (
                    format!("{name} θo {theta} below {below}"),
                    b,
                    wo_at(theta, below),
                )
            })
    })
    .collect();
    let n = 400_000;
    for (i, (name, bxdf, wo)) in cases.iter().enumerate() {
        let (a, se_a) = sampled_albedo(bxdf, *wo, n, 100 + i as u64);
        let (b, se_b) = uniform_albedo(bxdf, *wo, n, 200 + i as u64);
        let z = z_test_two_sample(a, se_a, b, se_b);
        eprintln!(
            "{name}: sampled {a:.5} ± {se_a:.5}, uniform {b:.5} ± {se_b:.5}, z {:.2}",
            z.z
        );
        assert!(
            z.within(4.0),
            "{name}: sampled {a} vs uniform {b} (z = {:.2})",
            z.z
        );
        // Radiance scaling by 1/η² makes transmission from outside carry less than one;
        // from inside it can exceed one (1/η'² > 1): that is radiance, not energy.
        // Mitsuba's principled material adds its sheen and clear coat on top of the base
        // layer without taking their energy from it: its albedo can exceed one by design.
        let transmits_from_inside = matches!(bxdf, Bxdf::RoughDielectric(_)) && wo.z < 0.0;
        if !transmits_from_inside && !matches!(bxdf, Bxdf::Principled(_)) {
            assert!(a <= 1.0 + 4.0 * se_a, "{name}: albedo {a} > 1");
        }
    }
}

#[test]
fn narrow_lobes_and_grazing_angles_keep_albedo_at_most_one() {
    for (name, bxdf) in [
        (
            "GGX conductor α 0.05",
            conductor(NormalDistribution::Ggx, 0.05),
        ),
        (
            "Beckmann conductor α 0.05",
            conductor(NormalDistribution::Beckmann, 0.05),
        ),
        (
            "GGX rough glass α 0.05",
            rough_glass(NormalDistribution::Ggx, 0.05),
        ),
        ("plastic", plastic(0.8, false)),
    ] {
        for theta in [0.0, 45.0, 85.0, 89.0] {
            let (a, se) = sampled_albedo(&bxdf, wo_at(theta, false), 200_000, 7);
            eprintln!("{name} θo {theta}: albedo {a:.5} ± {se:.5}");
            assert!(a <= 1.0 + 4.0 * se, "{name} θo {theta}: albedo {a} > 1");
        }
    }
}

#[test]
fn white_plastic_reflects_everything_and_coloured_plastic_has_the_stated_albedo() {
    // Linear model: albedo = s F(θo) + (1 - F(θo)) ρ exactly, s the coat's specular
    // scale; nonlinear with ρ = 1 too.
    for (rho, nonlinear, s) in [
        (1.0f32, false, 1.0f32),
        (0.5, false, 1.0),
        (1.0, true, 1.0),
        (0.5, false, 0.3),
    ] {
        for theta in [0.0f32, 50.0, 80.0] {
            let wo = wo_at(theta, false);
            let f = fresnel_dielectric(wo.z, 1.5) as f64;
            let truth = s as f64 * f + (1.0 - f) * rho as f64;
            let Bxdf::Plastic(p) = plastic(rho, nonlinear) else {
                unreachable!()
            };
            let bxdf = Bxdf::Plastic(p.with_specular(Vec3::splat(s)));
            let (a, se) = sampled_albedo(&bxdf, wo, 400_000, 9);
            let z = (a - truth) / se;
            eprintln!(
                "plastic ρ {rho} nonlinear {nonlinear} θo {theta}: {a:.5} ± {se:.5} vs {truth:.5}"
            );
            assert!(
                z.abs() <= 4.0,
                "ρ {rho} θo {theta}: {a} vs {truth} (z {z:.2})"
            );
        }
    }
}

#[test]
fn smooth_glass_conserves_energy_exactly() {
    // Without absorption, reflection + transmission carries all the energy: the throughput
    // of a transmitted sample times η'² (undoing radiance scaling) is one, as is a
    // reflected one, for every angle and side (Schlick's reflectance too).
    for fresnel in [FresnelModel::Exact, FresnelModel::Schlick] {
        let glass = Bxdf::Dielectric(SmoothDielectric {
            eta: 1.5,
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
            fresnel,
        });
        for (theta, below) in [
            (0.0, false),
            (60.0, false),
            (89.0, false),
            (30.0, true),
            (60.0, true),
        ] {
            let wo = wo_at(theta, below);
            for i in 0..1000 {
                let uc = (i as f32 + 0.5) / 1000.0;
                let s = glass.sample(wo, uc, Vec2::ZERO).unwrap();
                let etap = glass.relative_ior(wo, s.wi);
                let expected: f32 = match (s.wi.z * wo.z < 0.0, wo.z > 0.0) {
                    (false, _) => 1.0,
                    (true, true) => 1.5,
                    (true, false) => 1.0 / 1.5,
                };
                assert_eq!(etap, expected, "θo {theta}: relative index");
                let w = s.f.y * s.wi.z.abs() / s.pdf * etap * etap;
                assert!((w - 1.0).abs() < 1e-4, "{fresnel:?} θo {theta}: weight {w}");
            }
        }
    }
}

#[test]
fn diffuse_transmission_carries_reflectance_plus_transmittance_in_every_sample() {
    // Grey R = 0.3 and T = 0.5: reflection is chosen with probability 0.3 / 0.8, and each
    // sample's weight f |cos| / pdf is R / p_r = T / (1 - p_r) = R + T, on either side; a
    // sample on wo's side is a reflection, one on the other side a transmission.
    let b = Bxdf::DiffuseTransmission(DiffuseTransmission {
        reflectance: Vec3::splat(0.3),
        transmittance: Vec3::splat(0.5),
    });
    for (theta, below) in [(0.0, false), (60.0, false), (40.0, true)] {
        let wo = wo_at(theta, below);
        let mut reflected = 0;
        let n = 10_000;
        for i in 0..n {
            let uc = (i as f32 + 0.5) / n as f32;
            let u = Vec2::new((((i * 7919) % n) as f32 + 0.5) / n as f32, 0.37);
            let s = b.sample(wo, uc, u).unwrap();
            let w = s.f * s.wi.z.abs() / s.pdf;
            assert!(
                (w - Vec3::splat(0.8)).abs().max_element() < 1e-5,
                "weight {w}"
            );
            assert!((s.pdf - b.pdf(wo, s.wi)).abs() <= 1e-5 * s.pdf);
            reflected += (s.wi.z * wo.z > 0.0) as u32;
        }
        assert_eq!(reflected, 3750, "θo {theta}: reflections of {n}");
    }
    // Black on both sides: nothing but zero-valued samples, never a NaN.
    let black = Bxdf::DiffuseTransmission(DiffuseTransmission {
        reflectance: Vec3::ZERO,
        transmittance: Vec3::ZERO,
    });
    let s = black
        .sample(wo_at(30.0, false), 0.7, Vec2::new(0.2, 0.4))
        .unwrap();
    assert_eq!(s.f, Vec3::ZERO);
    assert!(s.pdf > 0.0);
}

#[test]
fn thin_glass_reflects_what_its_internal_bounces_add_up_to_and_conserves_energy() {
    // A sheet's two interfaces each reflect R = F(θ) and transmit T = 1 - R; light bounces
    // between them until it leaves. Simulating that walk estimates the sheet's reflectance,
    // which sampling the sheet must reproduce (2R / (1 + R) in closed form), and every
    // sample of a white sheet carries weight one.
    let sheet = ThinDielectric {
        eta: 1.5,
        reflectance: Vec3::ONE,
        transmittance: Vec3::ONE,
    };
    let n = 400_000;
    for (theta, below) in [(0.0, false), (50.0, false), (80.0, false), (60.0, true)] {
        let wo = wo_at(theta, below);
        let r = fresnel_dielectric(wo.z.abs(), 1.5) as f64;
        let mut rng = Pcg32::new(17, 3);
        let mut walk = RunningStats::new();
        let mut sampled = RunningStats::new();
        for _ in 0..n {
            // Reflected off the top, or in and bouncing (each interface transmitting with
            // probability T) until it leaves: at the top when it was travelling up.
            let left_on_top = (rng.uniform_f32() as f64) < r || {
                let mut going_down = true;
                while (rng.uniform_f32() as f64) < r {
                    going_down = !going_down;
                }
                !going_down
            };
            walk.push(left_on_top as u8 as f64);
            let s = Bxdf::ThinDielectric(sheet)
                .sample(wo, rng.uniform_f32(), Vec2::ZERO)
                .unwrap();
            assert!(s.delta);
            let w = s.f.y * s.wi.z.abs() / s.pdf;
            assert!((w - 1.0).abs() < 1e-5, "θo {theta}: weight {w}");
            let reflected = s.wi.z * wo.z > 0.0;
            if reflected {
                assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            } else {
                assert_eq!(s.wi, -wo);
            }
            sampled.push(reflected as u8 as f64);
        }
        let closed = 2.0 * r / (1.0 + r);
        let z = z_test_two_sample(
            walk.mean(),
            walk.std_error(),
            sampled.mean(),
            sampled.std_error(),
        );
        eprintln!(
            "thin sheet θo {theta}: walk {:.5}, sampled {:.5}, closed form {closed:.5}",
            walk.mean(),
            sampled.mean()
        );
        assert!(z.within(4.0), "θo {theta}: z = {:.2}", z.z);
        assert!((sheet.reflectance(wo.z) as f64 - closed).abs() < 1e-6);
    }
}

#[test]
fn reflection_is_reciprocal() {
    let mut rng = Pcg32::new(5, 5);
    let bxdfs = [
        diffuse(),
        conductor(NormalDistribution::Ggx, 0.2),
        conductor(NormalDistribution::Beckmann, 0.3),
        rough_glass(NormalDistribution::Ggx, 0.3),
        plastic(0.6, false),
        plastic(0.6, true),
        diffuse_transmission(),
    ];
    for bxdf in &bxdfs {
        let mut checked = 0;
        for _ in 0..2000 {
            let a = pathlab_mc::warp::sample_uniform_hemisphere(Vec2::new(
                rng.uniform_f32(),
                rng.uniform_f32(),
            ));
            let b = pathlab_mc::warp::sample_uniform_hemisphere(Vec2::new(
                rng.uniform_f32(),
                rng.uniform_f32(),
            ));
            let (fab, fba) = (bxdf.f(a, b), bxdf.f(b, a));
            let scale = fab.max_element().max(fba.max_element());
            if scale > 0.0 {
                checked += 1;
                assert!(
                    (fab - fba).abs().max_element() <= 1e-4 * scale,
                    "{bxdf:?}: f({a}, {b}) = {fab} but f({b}, {a}) = {fba}"
                );
            }
        }
        assert!(checked > 100, "{bxdf:?}: only {checked} nonzero pairs");
    }
}

#[test]
fn refraction_obeys_generalised_reciprocity_with_its_relative_index() {
    // Radiance refracted into a medium of index η_b from one of η_a is scaled by (η_b/η_a)²,
    // and a BTDF obeys f(a, b) η_b² = f(b, a) η_a² (Veach 1997, eq. 5.19): with
    // η' = `relative_ior` = η_b/η_a one way and its inverse the other,
    // f(a, b) η'(a, b) = f(b, a) η'(b, a). A wrong η' (or one given the wrong way round)
    // misses by η⁴ ≈ 5.
    let mut rng = Pcg32::new(6, 6);
    let bxdfs = [
        rough_glass(NormalDistribution::Ggx, 0.3),
        rough_glass(NormalDistribution::Beckmann, 0.5),
        principled(false, 0.4),
    ];
    for bxdf in &bxdfs {
        let mut checked = 0;
        for _ in 0..4000 {
            let mut u = || Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let a = pathlab_mc::warp::sample_uniform_hemisphere(u());
            let b = -pathlab_mc::warp::sample_uniform_hemisphere(u());
            let (r_ab, r_ba) = (bxdf.relative_ior(a, b), bxdf.relative_ior(b, a));
            assert_eq!((r_ab, r_ba), (1.5, 1.0 / 1.5), "{bxdf:?}");
            let (fab, fba) = (bxdf.f(a, b) * r_ab, bxdf.f(b, a) * r_ba);
            // Near total internal reflection at the facet, 1 - F is steep in the facet's
            // angle and both values tiny: rounding of the half vector decides them there.
            let scale = fab.max_element().max(fba.max_element());
            if scale > 1e-3 {
                checked += 1;
                assert!(
                    (fab - fba).abs().max_element() <= 1e-3 * scale,
                    "{bxdf:?}: f({a}, {b}) η' = {fab} but f({b}, {a}) η' = {fba}"
                );
            }
            // Reflection crosses nothing.
            assert_eq!(bxdf.relative_ior(a, -b), 1.0);
        }
        assert!(checked > 100, "{bxdf:?}: only {checked} nonzero pairs");
    }
    // Nothing else scales radiance: a thin sheet's transmission, diffuse transmission.
    let above = Vec3::new(0.3, 0.1, 0.9).normalize();
    let below = Vec3::new(-0.2, 0.4, -0.8).normalize();
    for bxdf in [principled(true, 0.4), diffuse_transmission()] {
        assert_eq!(bxdf.relative_ior(above, below), 1.0, "{bxdf:?}");
    }
}
