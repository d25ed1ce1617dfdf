//! A diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`).

use super::fresnel::fresnel_dielectric;
use super::microfacet::{Microfacet, NormalDistribution};
use super::scattering::{reflect, refract_about};
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use std::collections::HashMap;
use std::f32::consts::FRAC_1_PI;
use std::sync::{Mutex, OnceLock};

/// Entries of the coat's transmittance table over cos θ in [0, 1].
const TABLE: usize = 64;

/// What light keeps crossing a rough dielectric coat, precomputed once per (distribution, α,
/// η): `transmittance[i]` = T(μᵢ), the part of light arriving at cos θ = μᵢ = i / 63 that
/// the coat's microfacets refract into it (T = 1 - R minus what masking loses), and
/// `internal` = 2 ∫ R_int(μ) μ dμ, the share of diffuse light from the base that the coat
/// reflects back inside (R_int its directional albedo from inside).
#[derive(Debug, PartialEq)]
pub struct CoatTable {
    transmittance: [f32; TABLE],
    internal: f32,
}

/// The directional albedo of microfacet reflection off a dielectric of relative index `eta`
/// for light arriving at cos θ = `mu`: ∫ D_wi(m) F(wi·m) G1(wo, m) dm over the visible
/// normals (by Gauss–Legendre quadrature over the distribution's sampling of them).
pub fn rough_reflectance(
    distribution: &Microfacet,
    mu: f32,
    eta: f32,
    rule: &(Vec<f64>, Vec<f64>),
) -> f64 {
    visible_normal_integral(distribution, mu, rule, |wi, m, cos_im| {
        let wo = reflect(wi, m);
        (wo.z > 0.0).then(|| fresnel_dielectric(cos_im, eta) * distribution.g1(wo, m))
    })
}

/// The directional transmittance of a rough dielectric interface of relative index `eta` for
/// light arriving at cos θ = `mu`: ∫ D_wi(m) (1 - F(wi·m)) G1(wt, m) dm, wt the refraction of
/// wi through the facet m (by quadrature, as [`rough_reflectance`]).
pub fn rough_transmittance(
    distribution: &Microfacet,
    mu: f32,
    eta: f32,
    rule: &(Vec<f64>, Vec<f64>),
) -> f64 {
    visible_normal_integral(distribution, mu, rule, |wi, m, cos_im| {
        let (wt, _) = refract_about(wi, m, eta)?;
        (wt.z * wi.z < 0.0)
            .then(|| (1.0 - fresnel_dielectric(cos_im, eta)) * distribution.g1(wt, m))
    })
}

/// ∫ D_wi(m) g(m) dm over the normals visible from the direction at cos θ = `mu`, by the
/// Gauss–Legendre `rule` (nodes, weights on [-1, 1]) in both dimensions of the distribution's
/// own sampling of normals. `g(wi, m, wi·m)` is the rest of the integrand, `None` where it
/// vanishes; it is asked only where wi·m > 0.
fn visible_normal_integral(
    distribution: &Microfacet,
    mu: f32,
    rule: &(Vec<f64>, Vec<f64>),
    g: impl Fn(Vec3, Vec3, f32) -> Option<f32>,
) -> f64 {
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (nodes, weights) = rule;
    let mut sum = 0.0f64;
    for (i, &xi) in nodes.iter().enumerate() {
        for (j, &xj) in nodes.iter().enumerate() {
            let u = Vec2::new((0.5 * xi + 0.5) as f32, (0.5 * xj + 0.5) as f32);
            let m = distribution.sample_wm(wi, u);
            let cos_im = wi.dot(m);
            if cos_im <= 0.0 {
                continue;
            }
            let Some(rest) = g(wi, m, cos_im) else {
                continue;
            };
            // The sampled normals' density against the visible normals' D_wi.
            let correction = match distribution.kind {
                NormalDistribution::Ggx => 1.0,
                NormalDistribution::Beckmann => distribution.g1(wi, m) * cos_im / (mu * m.z),
            };
            sum += weights[i] * weights[j] * (rest * correction) as f64;
        }
    }
    0.25 * sum
}

impl CoatTable {
    /// The table for a coat of `distribution` and relative index `eta`, computed on first use
    /// and kept for the life of the program (shared by every material with the same
    /// parameters; a few hundred bytes each).
    pub fn get(distribution: Microfacet, eta: f32) -> &'static CoatTable {
        type Key = (bool, u32, u32);
        static TABLES: OnceLock<Mutex<HashMap<Key, &'static CoatTable>>> = OnceLock::new();
        let key = (
            distribution.kind == NormalDistribution::Ggx,
            distribution.alpha.to_bits(),
            eta.to_bits(),
        );
        let tables = TABLES.get_or_init(|| Mutex::new(HashMap::new()));
        let mut tables = match tables.lock() {
            Ok(t) => t,
            Err(poisoned) => poisoned.into_inner(),
        };
        tables.entry(key).or_insert_with(|| {
            // Leaked on purpose: the table lives as long as the program, so that BSDFs
            // (plain copyable values) can refer to it.
            Box::leak(Box::new(CoatTable::compute(distribution, eta)))
        })
    }

    fn compute(distribution: Microfacet, eta: f32) -> CoatTable {
        let rule = pathlab_mc::quadrature::gauss_legendre(96);
        let mus: Vec<f32> = (0..TABLE)
            .map(|i| (i as f32 / (TABLE - 1) as f32).max(1e-6))
            .collect();
        let mut transmittance = [0.0; TABLE];
        for (t, &mu) in transmittance.iter_mut().zip(&mus) {
            *t = rough_transmittance(&distribution, mu, eta, &rule) as f32;
        }
        let internal = 2.0
            * mus
                .iter()
                .map(|&mu| rough_reflectance(&distribution, mu, 1.0 / eta, &rule) * mu as f64)
                .sum::<f64>()
            / TABLE as f64;
        CoatTable {
            transmittance,
            internal: internal as f32,
        }
    }

    /// T(cos θ), interpolated.
    #[inline]
    pub fn transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (TABLE - 1) as f32;
        let i = (x as usize).min(TABLE - 2);
        let w = x - i as f32;
        (1.0 - w) * self.transmittance[i] + w * self.transmittance[i + 1]
    }

    /// The coat's internal diffuse reflectance.
    pub fn internal(&self) -> f32 {
        self.internal
    }
}

/// Rough plastic: microfacet reflection off the coat,
/// f_s = F(wo·wm) D(wm) G(wo, wi, wm) / (4 cos θo cos θi) × `specular`,
/// plus light that crosses the coat, scatters diffusely off the base and crosses back,
/// f_d = ρ' T(θo) T(θi) / (η² π), with ρ' = ρ / (1 - R_int) (or ρ / (1 - ρ R_int) when
/// `nonlinear`), T and R_int from the [`CoatTable`]: Mitsuba's model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// Diffuse reflectance of the base.
    pub diffuse: Rgb,
    /// Scale of the coat's reflection.
    pub specular: Rgb,
    /// Index of the coat relative to outside.
    pub eta: f32,
    /// The coat's roughness.
    pub distribution: Microfacet,
    /// Whether internal reflections tint by the base colour.
    pub nonlinear: bool,
    /// The coat's precomputed transmittance.
    pub table: &'static CoatTable,
}

impl RoughPlastic {
    /// Rough plastic with base `diffuse`, coat reflection scale `specular`, coat index `eta`
    /// and roughness `distribution`.
    pub fn new(
        diffuse: Rgb,
        specular: Rgb,
        eta: f32,
        distribution: Microfacet,
        nonlinear: bool,
    ) -> Self {
        RoughPlastic {
            diffuse,
            specular,
            eta,
            distribution,
            nonlinear,
            table: CoatTable::get(distribution, eta),
        }
    }

    fn base(&self) -> Rgb {
        let r = self.table.internal;
        if self.nonlinear {
            self.diffuse / (Rgb::ONE - self.diffuse * r)
        } else {
            self.diffuse / (1.0 - r)
        }
    }

    /// Probability of sampling the coat's reflection (Mitsuba's choice: the coat's share of
    /// light arriving from `wo`, weighted by the mean specular and diffuse reflectances).
    fn specular_probability(&self, cos_o: f32) -> f32 {
        let s = (self.specular.x + self.specular.y + self.specular.z) / 3.0;
        let d = (self.diffuse.x + self.diffuse.y + self.diffuse.z) / 3.0;
        let weight = if s + d > 0.0 { s / (s + d) } else { 0.5 };
        let t = self.table.transmittance(cos_o);
        let ps = (1.0 - t) * weight;
        let pd = t * (1.0 - weight);
        if ps + pd > 0.0 {
            ps / (ps + pd)
        } else {
            0.5
        }
    }

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let m = &self.distribution;
        let mut f = Rgb::ZERO;
        let wm = (wo + wi).normalize_or_zero();
        if wm != Vec3::ZERO {
            let spec = fresnel_dielectric(wo.dot(wm), self.eta) * m.d(wm) * m.g(wo, wi, wm)
                / (4.0 * wo.z * wi.z);
            f += self.specular * spec;
        }
        let t = self.table.transmittance(wo.z) * self.table.transmittance(wi.z);
        f + self.base() * (FRAC_1_PI * t / (self.eta * self.eta))
    }

    /// A sample: the reflection about a sampled microfacet normal, or a cosine-weighted
    /// direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.specular_probability(wo.z) {
            reflect(wo, self.distribution.sample_wm(wo, u))
        } else {
            sample_cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        LocalSample::evaluated(wi, self.pdf(wo, wi), || self.f(wo, wi))
    }

    /// Density of [`RoughPlastic::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability(wo.z);
        let wm = (wo + wi).normalize_or_zero();
        let cos_om = wo.dot(wm);
        let spec = if wm != Vec3::ZERO && cos_om > 0.0 {
            self.distribution.pdf_wm(wo, wm) / (4.0 * cos_om)
        } else {
            0.0
        };
        ps * spec + (1.0 - ps) * cosine_hemisphere_pdf(wi.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_smooth_coat_reflects_what_fresnel_says() {
        // Nearly smooth: the rough albedo approaches the smooth Fresnel reflectance.
        let rule = pathlab_mc::quadrature::gauss_legendre(96);
        for kind in [NormalDistribution::Beckmann, NormalDistribution::Ggx] {
            let m = Microfacet::new(kind, 0.01);
            // Near grazing even α = 0.01 masks a little (about 0.6% at μ = 0.2).
            for (mu, tol) in [(0.2f32, 1e-2), (0.5, 2e-3), (0.9, 2e-3)] {
                let r = rough_reflectance(&m, mu, 1.5, &rule);
                let f = fresnel_dielectric(mu, 1.5) as f64;
                assert!(
                    (r - f).abs() < tol * f.max(0.05),
                    "{kind:?} μ {mu}: {r} vs {f}"
                );
                let t = rough_transmittance(&m, mu, 1.5, &rule);
                assert!(
                    (t - (1.0 - f)).abs() < 3e-3,
                    "{kind:?} μ {mu}: {t} vs {}",
                    1.0 - f
                );
                // Rough, masking takes a share, more at grazing angles: R + T < 1 (above 0.9
                // at normal incidence, 0.5 at μ = 0.2).
                let rough = Microfacet::new(kind, 0.8);
                let (r, t) = (
                    rough_reflectance(&rough, mu, 1.5, &rule),
                    rough_transmittance(&rough, mu, 1.5, &rule),
                );
                let floor = if mu > 0.8 { 0.9 } else { 0.5 };
                assert!(r + t < 1.0 && r + t > floor, "{kind:?} μ {mu}: R {r} T {t}");
            }
        }
        // The same integral by the two distributions' different sampling, on a rough coat,
        // and the internal reflectance near the smooth one (about 0.6 for η = 1.5).
        let (b, g) = (
            CoatTable::get(Microfacet::new(NormalDistribution::Beckmann, 0.01), 1.5),
            CoatTable::get(Microfacet::new(NormalDistribution::Ggx, 0.01), 1.5),
        );
        assert!(
            (b.internal - g.internal).abs() < 5e-3,
            "{} vs {}",
            b.internal,
            g.internal
        );
        let smooth = super::super::fresnel::fresnel_diffuse_reflectance(1.0 / 1.5);
        assert!(
            (b.internal - smooth).abs() < 0.02,
            "{} vs {smooth}",
            b.internal
        );
        assert!(std::ptr::eq(
            b,
            CoatTable::get(Microfacet::new(NormalDistribution::Beckmann, 0.01), 1.5)
        ));
    }
}
