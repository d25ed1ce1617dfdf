//! Tests of the layered BSDFs: energy, a closed form (Mitsuba's plastic), and agreement of
//! sampling with evaluation.

use super::*;
use crate::bsdf::{NormalDistribution, Plastic};
use pathlab_mc::estimator::RunningStats;

/// A white or coloured Lambertian base under a coat of index 1.5, no medium.
fn stack(roughness: Option<f32>, max_depth: u16) -> LayerStack {
    LayerStack {
        coat: Coat {
            eta: 1.5,
            roughness: roughness.map(|a| Microfacet::new(NormalDistribution::Ggx, a)),
        },
        base: Base::Diffuse,
        medium: LayerMedium {
            thickness: f32::MIN_POSITIVE,
            albedo: Rgb::ZERO,
            g: 0.0,
        },
        max_depth,
        samples: 1,
    }
}

fn coated_diffuse(rho: Rgb, roughness: Option<f32>, max_depth: u16) -> Layered {
    Layered::new(stack(roughness, max_depth), rho)
}

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Mean of f |cos| / pdf over `n` samples from `wo`, and its standard error (green).
fn sampled_albedo(b: &Layered, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 1);
    let mut s = RunningStats::new();
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let w = b
            .sample(wo, rng.uniform_f32(), u)
            .map_or(0.0, |x| (x.f.y * x.wi.z.abs() / x.pdf) as f64);
        s.push(w);
    }
    (s.mean(), s.std_error())
}

#[test]
fn a_smooth_coat_over_white_lambertian_loses_no_energy() {
    // Nothing absorbs: every walk leaves eventually, so the albedo is one (the walks are
    // long enough at depth 200; Russian roulette keeps the estimate unbiased).
    let b = coated_diffuse(Rgb::ONE, None, 200);
    for theta in [0.0, 45.0, 80.0] {
        let (a, se) = sampled_albedo(&b, direction(theta, 0.0), 100_000, 3);
        assert!(
            (a - 1.0).abs() < 4.0 * se + 1e-3,
            "θo {theta}: albedo {a} ± {se}"
        );
    }
}

#[test]
fn a_smooth_coat_over_lambertian_is_mitsubas_nonlinear_plastic() {
    // With no medium and no thickness, the walks sum the internal reflections that the
    // plastic model sums in closed form: ρ (1 - F_i)(1 - F_o) / (π η² (1 - ρ F_dr)).
    let rho = Rgb::new(0.8, 0.5, 0.2);
    let b = coated_diffuse(rho, None, 200);
    let plastic = Plastic::new(rho, 1.5, true);
    let mut rng = Pcg32::new(9, 2);
    for theta_o in [10.0, 60.0] {
        let wo = direction(theta_o, 0.0);
        let mut ratio = [
            RunningStats::new(),
            RunningStats::new(),
            RunningStats::new(),
        ];
        for _ in 0..20_000 {
            let wi = direction(85.0 * rng.uniform_f32(), 360.0 * rng.uniform_f32());
            let (f, exact) = (b.f(wo, wi), plastic.f(wo, wi));
            for c in 0..3 {
                ratio[c].push((f[c] / exact[c]) as f64);
            }
        }
        for (c, r) in ratio.iter().enumerate() {
            assert!(
                (r.mean() - 1.0).abs() < 4.0 * r.std_error() + 2e-3,
                "θo {theta_o}, channel {c}: f / plastic = {} ± {}",
                r.mean(),
                r.std_error()
            );
        }
    }
}

#[test]
fn sampling_and_evaluation_estimate_the_same_albedo() {
    // E[f |cos| / pdf] over the walk's own samples equals ∫ f |cos| dω, estimated by
    // evaluating f at cosine-distributed directions: the walks of `sample` and of `f`
    // agree, with a rough coat, a medium and a rough conductor base.
    let (eta, k) = (Rgb::new(0.2, 0.92, 1.1), Rgb::new(3.9, 2.45, 2.14));
    let cases = [
        coated_diffuse(Rgb::new(0.7, 0.4, 0.2), Some(0.3), 100),
        Layered::new(
            LayerStack {
                medium: LayerMedium {
                    albedo: Rgb::new(0.8, 0.6, 0.3),
                    g: 0.4,
                    thickness: 0.3,
                },
                ..stack(Some(0.15), 100)
            },
            Rgb::splat(0.5),
        ),
        Layered::new(
            LayerStack {
                base: Base::Conductor(Conductor {
                    eta,
                    k,
                    specular: Rgb::ONE,
                    distribution: Some(Microfacet::new(NormalDistribution::Ggx, 0.4)),
                }),
                ..stack(Some(0.2), 100)
            },
            Rgb::ONE,
        ),
    ];
    for (i, b) in cases.iter().enumerate() {
        for theta in [20.0, 70.0] {
            let wo = direction(theta, 30.0);
            let (sampled, se_s) = sampled_albedo(b, wo, 200_000, 5 + i as u64);
            let mut rng = Pcg32::new(7, i as u64);
            let mut eval = RunningStats::new();
            for _ in 0..200_000 {
                let wi: Vec3 =
                    pathlab_mc::warp::cosine_hemisphere(rng.uniform_f32(), rng.uniform_f32());
                if wi.z <= 0.0 {
                    eval.push(0.0);
                    continue;
                }
                // f |cos| / (cos / π) = π f.
                eval.push((b.f(wo, wi).y * std::f32::consts::PI) as f64);
            }
            let z = (sampled - eval.mean()) / (se_s * se_s + eval.std_error().powi(2)).sqrt();
            assert!(
                z.abs() < 4.0,
                "case {i} θo {theta}: sampled {sampled} ± {se_s}, evaluated {} ± {}",
                eval.mean(),
                eval.std_error()
            );
            assert!(sampled <= 1.0 + 4.0 * se_s, "case {i}: albedo {sampled}");
        }
    }
}

#[test]
fn estimates_are_fixed_functions_of_their_arguments_and_both_sides_alike() {
    let b = Layered::new(
        LayerStack {
            medium: LayerMedium {
                albedo: Rgb::splat(0.5),
                thickness: 0.2,
                g: 0.0,
            },
            ..stack(Some(0.3), 10)
        },
        Rgb::splat(0.6),
    );
    // One stack interned once.
    assert!(std::ptr::eq(
        b.stack,
        Layered::new(*b.stack, Rgb::ONE).stack
    ));
    let (wo, wi) = (direction(30.0, 10.0), direction(50.0, 200.0));
    assert_eq!(b.f(wo, wi), b.f(wo, wi));
    assert_eq!(b.pdf(wo, wi), b.pdf(wo, wi));
    assert_eq!(b.f(-wo, -wi), b.f(wo, wi));
    let s = b.sample(wo, 0.7, Vec2::new(0.3, 0.6));
    assert_eq!(s, b.sample(wo, 0.7, Vec2::new(0.3, 0.6)));
    // Nothing passes through the base.
    assert_eq!(b.f(wo, -wi), Rgb::ZERO);
    assert!(b.pdf(wo, wi) > 0.0 && b.pdf(wo, -wi) > 0.0);
}
