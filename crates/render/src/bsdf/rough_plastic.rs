//! A diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`).

use super::bxdf::DirectionSample;
use super::fresnel::{fresnel_dielectric, fresnel_dielectric_real};
use super::microfacet::{Distribution, Microfacet, MicrofacetLanes, NormalDistribution};
use super::plastic::{coated_base, mean};
use super::scattering::{reflect, refract_about};
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8, W};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
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

/// A coat's [`CoatTable`] for one material (`&'static CoatTable`, `R = f32`) or each lane's
/// ([`CoatLanes`], `R = F8`).
pub trait Coat<R: Real> {
    /// T(cos θ), interpolated.
    fn transmittance_at(&self, cos: R) -> R;
    /// The coat's internal diffuse reflectance.
    fn internal_reflectance(&self) -> R;
}

impl Coat<f32> for &'static CoatTable {
    #[inline(always)]
    fn transmittance_at(&self, cos: f32) -> f32 {
        self.transmittance(cos)
    }

    #[inline(always)]
    fn internal_reflectance(&self) -> f32 {
        self.internal
    }
}

/// Eight lanes' coat tables, each read lane by lane by [`CoatTable::transmittance`].
#[derive(Clone, Copy, Debug)]
pub struct CoatLanes([&'static CoatTable; W]);

/// The table of lanes without a rough plastic (whose values are discarded).
static NO_COAT: CoatTable = CoatTable {
    transmittance: [0.0; TABLE],
    internal: 0.0,
};

impl Default for CoatLanes {
    fn default() -> Self {
        CoatLanes([&NO_COAT; W])
    }
}

impl Coat<F8> for CoatLanes {
    #[inline(always)]
    fn transmittance_at(&self, cos: F8) -> F8 {
        F8(std::array::from_fn(|i| self.0[i].transmittance(cos.0[i])))
    }

    #[inline(always)]
    fn internal_reflectance(&self) -> F8 {
        F8(std::array::from_fn(|i| self.0[i].internal))
    }
}

/// Rough plastic: microfacet reflection off the coat,
/// f_s = F(wo·wm) D(wm) G(wo, wi, wm) / (4 cos θo cos θi) × `specular`,
/// plus light that crosses the coat, scatters diffusely off the base and crosses back,
/// f_d = ρ' T(θo) T(θi) / (η² π), with ρ' = ρ / (1 - R_int) (or ρ / (1 - ρ R_int) when
/// `nonlinear`), T and R_int from the [`CoatTable`]: Mitsuba's model.
///
/// Written once for one material (the defaults: [`Rgb`], `f32`, [`Microfacet`], `bool` and
/// its table) and for eight lanes' materials ([`V8`], [`F8`], [`MicrofacetLanes`], [`M8`],
/// [`CoatLanes`]): the path tracer's lanes shade with these same functions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoughPlastic<V = Rgb, R = f32, D = Microfacet, M = bool, T = &'static CoatTable> {
    /// Diffuse reflectance of the base.
    pub diffuse: V,
    /// Scale of the coat's reflection.
    pub specular: V,
    /// Index of the coat relative to outside.
    pub eta: R,
    /// The coat's roughness.
    pub distribution: D,
    /// Whether internal reflections tint by the base colour.
    pub nonlinear: M,
    /// The coat's precomputed transmittance.
    pub table: T,
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

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_and_pdf(wo, wi).0
    }

    /// A sample: the reflection about a sampled microfacet normal, or a cosine-weighted
    /// direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        self.sample_real(wo, uc, u.x, u.y).local()
    }

    /// Density of [`RoughPlastic::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_and_pdf(wo, wi).1
    }
}

impl<V, D, T> RoughPlastic<V, V::R, D, <V::R as Real>::Mask, T>
where
    V: Vector3,
    D: Distribution<V::R>,
    T: Coat<V::R>,
{
    /// Probability of sampling the coat's reflection (Mitsuba's choice: the coat's share of
    /// light arriving from `wo`, weighted by the mean specular and diffuse reflectances), `t`
    /// the coat's transmittance towards `wo`.
    #[inline(always)]
    fn specular_probability(&self, t: V::R) -> V::R {
        let (zero, one, half) = (V::R::splat(0.0), V::R::splat(1.0), V::R::splat(0.5));
        let (s, d) = (mean(self.specular), mean(self.diffuse));
        let weight = V::R::select((s + d).gt(zero), s / (s + d), half);
        let ps = (one - t) * weight;
        let pd = t * (one - weight);
        V::R::select((ps + pd).gt(zero), ps / (ps + pd), half)
    }

    /// f(wo, wi) and its density as a sample from `wo` (zero where either direction is below
    /// the surface; without the coat's reflection where they are opposite).
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V) -> (V, V::R) {
        self.f_and_pdf_from(wo, wi, self.table.transmittance_at(wo.z()))
    }

    /// [`Self::f_and_pdf`] given `t_o`, the coat's transmittance towards `wo` (read from the
    /// table once per sample: in the lanes, one lookup per lane).
    #[inline(always)]
    fn f_and_pdf_from(&self, wo: V, wi: V, t_o: V::R) -> (V, V::R) {
        let (zero, one, four) = (V::R::splat(0.0), V::R::splat(1.0), V::R::splat(4.0));
        let m = &self.distribution;
        // The half vector, where it exists (glam's `normalize_or_zero` is not zero).
        let sum = wo + wi;
        let rcp = one / sum.dot(sum).sqrt();
        let half = rcp.is_finite() & rcp.gt(zero);
        let wm = sum.scale(rcp);
        let cos_om = wo.dot(wm);
        let spec = fresnel_dielectric_real(cos_om, self.eta) * m.d(wm) * m.g(wo, wi, wm)
            / (four * wo.z() * wi.z());
        let spec = V::select(half, self.specular.scale(spec), V::splat(Vec3::ZERO));
        let t = t_o * self.table.transmittance_at(wi.z());
        let base = coated_base(
            self.diffuse,
            self.table.internal_reflectance(),
            self.nonlinear,
        );
        let f = spec + base.scale(V::R::splat(FRAC_1_PI) * t / (self.eta * self.eta));
        let ps = self.specular_probability(t_o);
        let spec_pdf = V::R::select(
            half & cos_om.gt(zero),
            m.pdf_wm(wo, wm) / (four * cos_om),
            zero,
        );
        let pdf = ps * spec_pdf + (one - ps) * cosine_hemisphere_pdf(wi.z());
        // `z <= 0`: a NaN goes on, as it did through the early return of the one-direction
        // code this was written from.
        let none = wo.z().le(zero) | wi.z().le(zero);
        (
            V::select(none, V::splat(Vec3::ZERO), f),
            V::R::select(none, zero, pdf),
        )
    }

    /// The reflection of `wo` about a microfacet normal drawn from (`u0`, `u1`), with the
    /// probability `specular_probability`, or a cosine-weighted direction from them;
    /// `uc` chooses. It exists where `wo` and it are above the surface and its density is
    /// positive.
    #[inline(always)]
    pub fn sample_real(&self, wo: V, uc: V::R, u0: V::R, u1: V::R) -> DirectionSample<V> {
        let zero = V::R::splat(0.0);
        let t_o = self.table.transmittance_at(wo.z());
        let specular = uc.lt(self.specular_probability(t_o));
        let mut wi: V = cosine_hemisphere(u0, u1);
        if V::R::any(specular) {
            let reflected = reflect(wo, self.distribution.sample_wm(wo, u0, u1));
            wi = V::select(specular, reflected, wi);
        }
        let (f, pdf) = self.f_and_pdf_from(wo, wi, t_o);
        DirectionSample {
            wi,
            pdf,
            f,
            valid: !wo.z().le(zero) & !wi.z().le(zero) & pdf.gt(zero),
        }
    }
}

impl RoughPlastic<V8, F8, MicrofacetLanes, M8, CoatLanes> {
    /// Sets lane `i` to `p`. Every field is taken apart here: a field added to
    /// [`RoughPlastic`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, p: RoughPlastic) {
        let RoughPlastic {
            diffuse,
            specular,
            eta,
            distribution,
            nonlinear,
            table,
        } = p;
        self.diffuse.set(i, diffuse);
        self.specular.set(i, specular);
        self.eta.0[i] = eta;
        self.distribution.set_lane(i, distribution);
        self.nonlinear.set(i, nonlinear);
        self.table.0[i] = table;
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

#[cfg(test)]
mod lane_tests {
    use super::*;
    use crate::bsdf::conductor::tests::lane_kind;
    use crate::bsdf::plastic::tests::{
        assert_lane_f_pdf, assert_lane_sample, direction, LaneInputs,
    };
    use pathlab_mc::rng::Pcg32;

    /// Eight lanes of rough plastic compute, lane by lane, what one rough plastic computes,
    /// to the bit: f, pdf and the sample, linear and not, GGX and Beckmann lanes (mixed in
    /// some rounds) of several roughnesses and coat indices (each lane its own table), for
    /// directions on both sides, on the horizon, opposite and equal.
    #[test]
    fn lanes_compute_what_one_rough_plastic_computes() {
        let mut rng = Pcg32::new(13, 1);
        let (mut seen, mut valid) = (0, 0);
        for round in 0..300 {
            let case = LaneInputs::draw(&mut rng, |rng, i| {
                let alpha = [0.01, 0.1, 0.3, 0.7][(round + i) % 4];
                let eta = [1.5, 1.33, 1.9][(round + i) % 3];
                let rho = Vec3::new(rng.uniform_f32(), 0.3, rng.uniform_f32());
                let specular = Vec3::new(1.0, rng.uniform_f32(), 0.5);
                let m = Microfacet::new(lane_kind(round, i), alpha);
                let p = RoughPlastic::new(rho, specular, eta, m, i % 2 == 1);
                let (o, mut w) = (direction(rng), direction(rng));
                match round % 6 {
                    0 => w = -o,
                    1 => w = o,
                    2 => w.z = 0.0,
                    _ => {}
                }
                (p, o, w)
            });
            let mut lanes = RoughPlastic::<V8, F8, MicrofacetLanes, M8, CoatLanes>::default();
            for (i, p) in case.one.iter().enumerate() {
                lanes.set_lane(i, *p);
            }
            let (f, pdf) = lanes.f_and_pdf(case.wo, case.wi);
            let s = lanes.sample_real(case.wo, case.uc, case.u[0], case.u[1]);
            for (i, p) in case.one.iter().enumerate() {
                let (o, w, uc, u) = case.lane(i);
                let what = format!("{o} {w}");
                assert_lane_f_pdf(f, pdf, i, (p.f(o, w), p.pdf(o, w)), &what);
                if let Some(scalar) = assert_lane_sample(&s, i, p.sample(o, uc, u), &what) {
                    assert!(!scalar.delta);
                    valid += 1;
                }
                seen += 1;
            }
        }
        assert!(valid * 3 > seen, "{valid} of {seen} samples valid");
    }
}
