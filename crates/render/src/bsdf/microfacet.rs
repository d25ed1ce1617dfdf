//! Microfacet distributions (Beckmann and GGX / Trowbridge–Reitz), isotropic or anisotropic,
//! with Smith's masking, in the local shading frame (z = macro normal, x the tangent along
//! which `alpha_x` applies).
//!
//! Conventions, shared with Mitsuba 3 so that renders can be compared with its references:
//! `alpha` is the distribution's roughness as given (no remapping); masking-shadowing is the
//! separable Smith form G(wo, wi, wm) = G1(wo, wm) G1(wi, wm) with the exact Λ of each
//! distribution; GGX samples the distribution of visible normals (Heitz 2018), Beckmann the
//! distribution of normals D(wm) cos θm.
//!
//! The pieces that the path tracer's lanes use (GGX's D and Λ of one roughness, the
//! density and sampling of its visible normals, Beckmann's D, Λ and sampling of one
//! roughness, Smith's G1) are written once over [`Real`] (see [`pathlab_mc::simd::lanes`]):
//! [`Microfacet`] calls their `f32` instance, and [`IsotropicMicrofacet`] is the same
//! distribution, GGX or Beckmann in each lane, for one direction or for eight lanes.
//! Beckmann's exponentials, logarithms, error function and the sine and cosine of its
//! sampled azimuth have no lane form here: the lanes compute them one lane at a time with
//! the one-direction functions, in the Beckmann lanes only ([`Real::map2_where`]).

use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8, W};
use pathlab_mc::warp::uniform_disk_concentric;
use std::f32::consts::{PI, TAU};

/// Which distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalDistribution {
    /// Beckmann–Spizzichino: a Gaussian distribution of slopes.
    Beckmann,
    /// GGX (Trowbridge–Reitz): longer tails.
    Ggx,
}

/// A microfacet distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// The distribution.
    pub kind: NormalDistribution,
    /// Roughness α (> 0); along the local x axis when anisotropic.
    pub alpha: f32,
    /// Roughness along the local y axis (equal to `alpha` when isotropic).
    pub alpha_y: f32,
}

/// The error function (Abramowitz and Stegun 7.1.26, absolute error below 1.5e-7).
pub fn erf(x: f32) -> f32 {
    let (sign, x) = if x < 0.0 {
        (-1.0, -x as f64)
    } else {
        (1.0, x as f64)
    };
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    sign * (1.0 - poly * (-x * x).exp()) as f32
}

/// tan²θ of a local direction (infinite or NaN at the horizon).
#[inline(always)]
fn tan2_theta<R: Real>(w: R::V3) -> R {
    let cos2 = w.z() * w.z();
    (R::splat(1.0) - cos2).max(R::splat(0.0)) / cos2
}

/// A distribution of microfacet normals as the microfacet models use it, for one direction
/// (`R = f32`: [`Microfacet`], every kind) or for lanes ([`IsotropicMicrofacet`]).
pub trait Distribution<R: Real> {
    /// The density of normals D(wm).
    fn d(&self, wm: R::V3) -> R;
    /// Smith's Λ(w).
    fn lambda(&self, w: R::V3) -> R;
    /// Density per solid angle of [`Distribution::sample_wm`] producing `wm`.
    fn pdf_wm(&self, wo: R::V3, wm: R::V3) -> R;
    /// A microfacet normal for light leaving towards `wo`, from (`u0`, `u1`).
    fn sample_wm(&self, wo: R::V3, u0: R, u1: R) -> R::V3;
    /// Masking-shadowing G1(wo, wm) G1(wi, wm).
    #[inline(always)]
    fn g(&self, wo: R::V3, wi: R::V3, wm: R::V3) -> R {
        smith_g1(wo, wm, self.lambda(wo)) * smith_g1(wi, wm, self.lambda(wi))
    }
}

/// Smith's masking 1 / (1 + Λ(w)) of a facet with normal `wm` seen from `w`, where Λ(w) is
/// `lambda`: zero when the facet faces away from `w` or `w` is on the other side of the macro
/// surface than the facet sees.
#[inline(always)]
fn smith_g1<R: Real>(w: R::V3, wm: R::V3, lambda: R) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    R::select((w.dot(wm) * w.z()).le(zero), zero, one / (one + lambda))
}

/// GGX's D(wm) of roughness `alpha` in every direction.
#[inline(always)]
fn ggx_d_isotropic<R: Real>(alpha: R, wm: R::V3) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let a2 = alpha * alpha;
    let cos2 = wm.z() * wm.z();
    let t = cos2 * (a2 - one) + one;
    R::select(wm.z().le(zero), zero, a2 / (R::splat(PI) * t * t))
}

/// GGX's Λ(w), `alpha` the roughness seen along the azimuth of `w`: infinite at the horizon,
/// zero along the normal.
#[inline(always)]
fn ggx_lambda<R: Real>(alpha: R, w: R::V3) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let tan2 = tan2_theta::<R>(w);
    let lambda = R::splat(0.5) * (R::splat(-1.0) + (one + alpha * alpha * tan2).sqrt());
    R::select(
        !tan2.is_finite(),
        R::splat(f32::INFINITY),
        R::select(tan2.equals(zero), zero, lambda),
    )
}

/// Beckmann's D(wm) of roughness `alpha` in every direction, of a normal whose cos θ is
/// `cos_m` (zero below the surface).
#[inline]
fn beckmann_d(alpha: f32, cos_m: f32) -> f32 {
    if cos_m <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let cos2 = cos_m * cos_m;
    let tan2 = (1.0 - cos2).max(0.0) / cos2;
    (-tan2 / a2).exp() / (PI * a2 * cos2 * cos2)
}

/// Beckmann's Λ of a direction with tan²θ `tan2`, `alpha` the roughness seen along its
/// azimuth: infinite at the horizon, zero along the normal and where it is below 10⁻¹⁵
/// (a ≥ 6).
#[inline]
fn beckmann_lambda(alpha: f32, tan2: f32) -> f32 {
    if !tan2.is_finite() {
        return f32::INFINITY;
    }
    if tan2 == 0.0 {
        return 0.0;
    }
    let a = 1.0 / (alpha * tan2.sqrt());
    if a >= 6.0 {
        return 0.0;
    }
    0.5 * (erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt())
}

/// A normal from Beckmann's D(wm) cos θm of roughness `alpha` in every direction:
/// tan²θ = -α² ln(1 - u0), φ = 2π u1 (in the lanes `lanes`; the others' are meaningless).
#[inline(always)]
fn sample_beckmann<R: Real>(alpha: R, u0: R, u1: R, lanes: R::Mask) -> R::V3 {
    let cos = alpha.map2_where(u0, lanes, |alpha, u| {
        let tan2 = -alpha * alpha * (1.0 - u).max(f32::MIN_POSITIVE).ln();
        1.0 / (1.0 + tan2).sqrt()
    });
    let sin = (R::splat(1.0) - cos * cos).max(R::splat(0.0)).sqrt();
    let phi = R::splat(TAU) * u1;
    R::V3::new(
        sin * phi.map_where(lanes, f32::cos),
        sin * phi.map_where(lanes, f32::sin),
        cos,
    )
}

/// The density of visible normals D_wo(wm) = G1(wo) max(0, wo·wm) D(wm) / cos θo, with wo
/// taken on the upper side (zero for wo on the horizon).
#[inline(always)]
fn visible_normal_pdf<R: Real, M: Distribution<R>>(m: &M, wo: R::V3, wm: R::V3) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let up = <R::V3 as Vector3>::select(wo.z().lt(zero), -wo, wo);
    let cos_om = up.dot(wm);
    let pdf = m.d(wm) * cos_om / ((one + m.lambda(up)) * up.z());
    R::select(wo.z().equals(zero) | cos_om.le(zero), zero, pdf)
}

/// Heitz's sampling of GGX visible normals (roughness `ax` along x, `ay` along y): a point on
/// the projected hemisphere of the stretched configuration, warped back.
#[inline(always)]
fn sample_visible_ggx<R: Real>(ax: R, ay: R, wo: R::V3, u0: R, u1: R) -> R::V3 {
    type V<R> = <R as Real>::V3;
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let wh = V::<R>::new(ax * wo.x(), ay * wo.y(), wo.z()).normalize();
    let wh = V::<R>::select(wh.z().lt(zero), -wh, wh);
    let t1 = V::<R>::select(
        wh.z().lt(R::splat(0.99999)),
        V::<R>::splat(Vec3::Z).cross(wh).normalize(),
        V::<R>::splat(Vec3::X),
    );
    let t2 = wh.cross(t1);
    let (px, py) = uniform_disk_concentric(u0, u1);
    // Squeeze the disk onto the visible part of the projected hemisphere.
    let h = (one - px * px).max(zero).sqrt();
    let s = R::splat(0.5) * (one + wh.z());
    let py = (one - s) * h + s * py;
    let pz = (one - (px * px + py * py)).max(zero).sqrt();
    let nh = t1.scale(px) + t2.scale(py) + wh.scale(pz);
    V::<R>::new(ax * nh.x(), ay * nh.y(), nh.z().max(R::splat(1e-6))).normalize()
}

/// GGX of one roughness in every direction, for one direction (`R = f32`) or for lanes: the
/// GGX half of [`IsotropicMicrofacet`], the same functions as [`Microfacet`]'s for such a
/// distribution, to the bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct IsotropicGgx<R> {
    /// Roughness α.
    alpha: R,
}

impl<R: Real> Distribution<R> for IsotropicGgx<R> {
    #[inline(always)]
    fn d(&self, wm: R::V3) -> R {
        ggx_d_isotropic(self.alpha, wm)
    }

    #[inline(always)]
    fn lambda(&self, w: R::V3) -> R {
        ggx_lambda(self.alpha, w)
    }

    #[inline(always)]
    fn pdf_wm(&self, wo: R::V3, wm: R::V3) -> R {
        visible_normal_pdf(self, wo, wm)
    }

    #[inline(always)]
    fn sample_wm(&self, wo: R::V3, u0: R, u1: R) -> R::V3 {
        sample_visible_ggx(self.alpha, self.alpha, wo, u0, u1)
    }
}

/// cos²θ of a normal `wm` and the slope term of anisotropic D, for roughness `ax` along x
/// and `ay` along y: e = tan²θ (cos²φ / αx² + sin²φ / αy²) = (x²/αx² + y²/αy²) / z². Both
/// distributions' anisotropic D are written on it.
#[inline(always)]
fn anisotropic_slope_term<R: Real>(ax: R, ay: R, wm: R::V3) -> (R, R) {
    let cos2 = wm.z() * wm.z();
    let e = (wm.x() * wm.x() / (ax * ax) + wm.y() * wm.y() / (ay * ay)) / cos2;
    (cos2, e)
}

/// GGX's D(wm) of roughness `ax` along x and `ay` along y:
/// 1 / (π αx αy cos⁴θ (1 + e)²), e the slope term ([`anisotropic_slope_term`]; zero below
/// the surface).
#[inline(always)]
fn ggx_d_anisotropic<R: Real>(ax: R, ay: R, wm: R::V3) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let (cos2, e) = anisotropic_slope_term(ax, ay, wm);
    let t = one + e;
    let d = one / (R::splat(PI) * ax * ay * cos2 * cos2 * t * t);
    R::select(wm.z().le(zero), zero, d)
}

/// The roughness of (`ax`, `ay`) seen along the azimuth of `w`: sqrt(cos²φ αx² + sin²φ αy²)
/// (`ax` along the normal).
#[inline(always)]
fn projected_alpha<R: Real>(ax: R, ay: R, w: R::V3) -> R {
    let r2 = w.x() * w.x() + w.y() * w.y();
    let alpha = ((w.x() * w.x() * ax * ax + w.y() * w.y() * ay * ay) / r2).sqrt();
    R::select(r2.equals(R::splat(0.0)), ax, alpha)
}

/// Anisotropic GGX, for one direction (`R = f32`, what [`Microfacet`] computes for such a
/// distribution) or for lanes ([`MicrofacetLanes`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct AnisotropicGgx<R> {
    /// Roughness along x.
    ax: R,
    /// Roughness along y.
    ay: R,
}

impl<R: Real> Distribution<R> for AnisotropicGgx<R> {
    #[inline(always)]
    fn d(&self, wm: R::V3) -> R {
        ggx_d_anisotropic(self.ax, self.ay, wm)
    }

    #[inline(always)]
    fn lambda(&self, w: R::V3) -> R {
        ggx_lambda(projected_alpha(self.ax, self.ay, w), w)
    }

    #[inline(always)]
    fn pdf_wm(&self, wo: R::V3, wm: R::V3) -> R {
        visible_normal_pdf(self, wo, wm)
    }

    #[inline(always)]
    fn sample_wm(&self, wo: R::V3, u0: R, u1: R) -> R::V3 {
        sample_visible_ggx(self.ax, self.ay, wo, u0, u1)
    }
}

/// GGX or Beckmann (`beckmann`) of one roughness in every direction, for one direction
/// (`R = f32`) or for lanes, each lane its own kind: the same functions as [`Microfacet`]'s
/// for such a distribution, to the bit. Lanes compute Beckmann's functions only where some
/// lane is Beckmann.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IsotropicMicrofacet<R: Real> {
    /// Roughness α.
    pub alpha: R,
    /// Whether the distribution is Beckmann's (GGX's where not).
    pub beckmann: R::Mask,
}

impl<R: Real> IsotropicMicrofacet<R> {
    /// The lanes' GGX.
    #[inline(always)]
    fn ggx(&self) -> IsotropicGgx<R> {
        IsotropicGgx { alpha: self.alpha }
    }

    /// Beckmann's D(wm) in the Beckmann lanes (zero in the others).
    #[inline(always)]
    fn beckmann_d(&self, wm: R::V3) -> R {
        self.alpha.map2_where(wm.z(), self.beckmann, beckmann_d)
    }

    /// `beckmann()` in the Beckmann lanes, `ggx` in the others (Beckmann's functions
    /// skipped where no lane is Beckmann). GGX's value comes computed, not as a closure: the
    /// compiler left such closures out of line, their operands passed through memory.
    #[inline(always)]
    fn either<T>(
        &self,
        beckmann: impl FnOnce() -> T,
        ggx: T,
        select: impl FnOnce(R::Mask, T, T) -> T,
    ) -> T {
        if R::any(self.beckmann) {
            select(self.beckmann, beckmann(), ggx)
        } else {
            ggx
        }
    }
}

impl<R: Real> Distribution<R> for IsotropicMicrofacet<R> {
    #[inline(always)]
    fn d(&self, wm: R::V3) -> R {
        self.either(|| self.beckmann_d(wm), self.ggx().d(wm), R::select)
    }

    #[inline(always)]
    fn lambda(&self, w: R::V3) -> R {
        self.either(
            || {
                self.alpha
                    .map2_where(tan2_theta::<R>(w), self.beckmann, beckmann_lambda)
            },
            self.ggx().lambda(w),
            R::select,
        )
    }

    #[inline(always)]
    fn pdf_wm(&self, wo: R::V3, wm: R::V3) -> R {
        self.either(
            || self.beckmann_d(wm) * wm.z().max(R::splat(0.0)),
            self.ggx().pdf_wm(wo, wm),
            R::select,
        )
    }

    #[inline(always)]
    fn sample_wm(&self, wo: R::V3, u0: R, u1: R) -> R::V3 {
        self.either(
            || sample_beckmann(self.alpha, u0, u1, self.beckmann),
            self.ggx().sample_wm(wo, u0, u1),
            <R::V3 as Vector3>::select,
        )
    }
}

impl Distribution<f32> for Microfacet {
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        Microfacet::d(self, wm)
    }

    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        Microfacet::lambda(self, w)
    }

    #[inline]
    fn pdf_wm(&self, wo: Vec3, wm: Vec3) -> f32 {
        Microfacet::pdf_wm(self, wo, wm)
    }

    #[inline]
    fn sample_wm(&self, wo: Vec3, u0: f32, u1: f32) -> Vec3 {
        Microfacet::sample_wm(self, wo, Vec2::new(u0, u1))
    }
}

/// Eight lanes' distributions, any [`Microfacet`] in each: the lanes of one roughness in every
/// direction and anisotropic GGX in SIMD registers ([`IsotropicMicrofacet`],
/// `AnisotropicGgx`, the functions [`Microfacet`] calls too), anisotropic Beckmann by each
/// lane's own [`Microfacet`], one lane at a time (its exponential, tangent and arctangent
/// have no lane form here), written over what the SIMD functions computed there. Every lane
/// gets what its [`Microfacet`] computes, to the bit.
#[derive(Clone, Copy, Debug)]
pub struct MicrofacetLanes {
    /// The lanes' roughness (along x) and kind (GGX in anisotropic Beckmann lanes, so that
    /// the SIMD functions, whose results they discard, compute on a roughness they have).
    isotropic: IsotropicMicrofacet<F8>,
    /// Lanes of anisotropic GGX, and their roughness along y.
    ggx_anisotropic: M8,
    alpha_y: F8,
    /// Lanes of anisotropic Beckmann.
    anisotropic: M8,
    /// Each anisotropic lane's distribution.
    each: [Microfacet; W],
}

impl Default for MicrofacetLanes {
    fn default() -> Self {
        MicrofacetLanes {
            isotropic: IsotropicMicrofacet::default(),
            ggx_anisotropic: M8::default(),
            alpha_y: F8::default(),
            anisotropic: M8::default(),
            each: [Microfacet::new(NormalDistribution::Ggx, 1.0); W],
        }
    }
}

impl MicrofacetLanes {
    /// Sets lane `i` to `m`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, m: Microfacet) {
        let iso = match m.as_isotropic() {
            Some(iso) => iso,
            None => {
                self.each[i] = m;
                self.alpha_y.0[i] = m.alpha_y;
                // GGX there, whatever the lane's kind: anisotropic Beckmann's functions go one
                // lane at a time, and the isotropic results would be written over.
                IsotropicMicrofacet {
                    alpha: m.alpha,
                    beckmann: false,
                }
            }
        };
        // Every field taken apart: a field added to `IsotropicMicrofacet` fails to compile
        // until its lanes are set too.
        let IsotropicMicrofacet { alpha, beckmann } = iso;
        let ggx = m.kind == NormalDistribution::Ggx;
        self.ggx_anisotropic.set(i, !m.is_isotropic() && ggx);
        self.anisotropic.set(i, !m.is_isotropic() && !ggx);
        self.isotropic.alpha.0[i] = alpha;
        self.isotropic.beckmann.set(i, beckmann);
    }

    /// Computes the functions that go one lane at a time (Beckmann's, anisotropic
    /// distributions') only in the lanes `lanes`: the others' results are not wanted.
    #[inline(always)]
    pub fn only_in(&mut self, lanes: M8) {
        self.isotropic.beckmann = self.isotropic.beckmann & lanes;
        self.ggx_anisotropic = self.ggx_anisotropic & lanes;
        self.anisotropic = self.anisotropic & lanes;
    }

    /// The isotropic lanes' `simd` result, with anisotropic GGX's `ggx` in its lanes (computed
    /// only where some lane has it).
    #[inline(always)]
    fn with_ggx<T>(
        &self,
        simd: T,
        ggx: impl FnOnce(AnisotropicGgx<F8>) -> T,
        select: impl FnOnce(M8, T, T) -> T,
    ) -> T {
        if self.ggx_anisotropic.any() {
            let d = AnisotropicGgx {
                ax: self.isotropic.alpha,
                ay: self.alpha_y,
            };
            select(self.ggx_anisotropic, ggx(d), simd)
        } else {
            simd
        }
    }

    /// `simd`, its anisotropic lanes written over by `one` of their distribution and lane.
    #[inline(always)]
    fn with_anisotropic<T>(&self, mut simd: T, one: impl Fn(&mut T, usize, &Microfacet)) -> T {
        if self.anisotropic.any() {
            self.overwrite_anisotropic(&mut simd, one);
        }
        simd
    }

    /// [`MicrofacetLanes::with_anisotropic`]'s loop over the lanes, out of line: inlined, it
    /// would make the SIMD functions around it too large to be inlined themselves.
    #[inline(never)]
    fn overwrite_anisotropic<T>(&self, simd: &mut T, one: impl Fn(&mut T, usize, &Microfacet)) {
        for (i, m) in self.each.iter().enumerate() {
            if self.anisotropic.get(i) {
                one(simd, i, m);
            }
        }
    }
}

impl Distribution<F8> for MicrofacetLanes {
    #[inline(always)]
    fn d(&self, wm: V8) -> F8 {
        let simd = self.with_ggx(self.isotropic.d(wm), |g| g.d(wm), M8::select);
        self.with_anisotropic(simd, |r, i, m| r.0[i] = m.d(wm.get(i)))
    }

    #[inline(always)]
    fn lambda(&self, w: V8) -> F8 {
        let simd = self.with_ggx(self.isotropic.lambda(w), |g| g.lambda(w), M8::select);
        self.with_anisotropic(simd, |r, i, m| r.0[i] = m.lambda(w.get(i)))
    }

    #[inline(always)]
    fn pdf_wm(&self, wo: V8, wm: V8) -> F8 {
        let iso = self.isotropic.pdf_wm(wo, wm);
        let simd = self.with_ggx(iso, |g| g.pdf_wm(wo, wm), M8::select);
        self.with_anisotropic(simd, |r, i, m| r.0[i] = m.pdf_wm(wo.get(i), wm.get(i)))
    }

    #[inline(always)]
    fn sample_wm(&self, wo: V8, u0: F8, u1: F8) -> V8 {
        let iso = self.isotropic.sample_wm(wo, u0, u1);
        let simd = self.with_ggx(iso, |g| g.sample_wm(wo, u0, u1), M8::select3);
        self.with_anisotropic(simd, |r, i, m| {
            r.set(i, m.sample_wm(wo.get(i), Vec2::new(u0.0[i], u1.0[i])))
        })
    }
}

impl Microfacet {
    /// A distribution; roughness is clamped to at least 1e-4 (below that the model is a
    /// mirror and should be drawn as one).
    pub fn new(kind: NormalDistribution, alpha: f32) -> Self {
        let alpha = alpha.max(1e-4);
        Microfacet {
            kind,
            alpha,
            alpha_y: alpha,
        }
    }

    /// An anisotropic distribution: roughness `alpha_x` along the local x axis, `alpha_y`
    /// along y (each clamped to at least 1e-4).
    pub fn anisotropic(kind: NormalDistribution, alpha_x: f32, alpha_y: f32) -> Self {
        Microfacet {
            kind,
            alpha: alpha_x.max(1e-4),
            alpha_y: alpha_y.max(1e-4),
        }
    }

    /// The anisotropic distribution of roughness (`alpha_x`, `alpha_y`), or `None` where both
    /// are at most 1e-4 (the models' smooth limit): a surface drawn as its smooth limit.
    pub fn unless_smooth(kind: NormalDistribution, alpha_x: f32, alpha_y: f32) -> Option<Self> {
        (alpha_x.max(alpha_y) > super::bxdf::SMOOTH_ALPHA)
            .then(|| Microfacet::anisotropic(kind, alpha_x, alpha_y))
    }

    /// This distribution as [`IsotropicMicrofacet`], where it has one roughness.
    #[inline]
    pub fn as_isotropic(&self) -> Option<IsotropicMicrofacet<f32>> {
        self.is_isotropic().then_some(IsotropicMicrofacet {
            alpha: self.alpha,
            beckmann: self.kind == NormalDistribution::Beckmann,
        })
    }

    /// Whether both roughnesses are the same.
    #[inline]
    pub fn is_isotropic(&self) -> bool {
        self.alpha == self.alpha_y
    }

    /// The roughness seen along the azimuth of `w`: sqrt(cos²φ αx² + sin²φ αy²).
    #[inline]
    fn projected_alpha(&self, w: Vec3) -> f32 {
        if self.is_isotropic() {
            return self.alpha;
        }
        projected_alpha(self.alpha, self.alpha_y, w)
    }

    /// The density of microfacet normals D(wm), normalised so that ∫ D(wm) cos θm dωm = 1.
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        if !self.is_isotropic() {
            let (ax, ay) = (self.alpha, self.alpha_y);
            if self.kind == NormalDistribution::Ggx {
                return ggx_d_anisotropic(ax, ay, wm);
            }
            let (cos2, e) = anisotropic_slope_term::<f32>(ax, ay, wm);
            return (-e).exp() / (PI * ax * ay * cos2 * cos2);
        }
        match self.kind {
            NormalDistribution::Beckmann => beckmann_d(self.alpha, wm.z),
            NormalDistribution::Ggx => ggx_d_isotropic(self.alpha, wm),
        }
    }

    /// Smith's Λ(w): the masked projected area per visible projected area.
    pub fn lambda(&self, w: Vec3) -> f32 {
        let alpha = self.projected_alpha(w);
        if self.kind == NormalDistribution::Ggx {
            return ggx_lambda(alpha, w);
        }
        beckmann_lambda(alpha, tan2_theta::<f32>(w))
    }

    /// Smith's masking of a facet with normal `wm` seen from `w` (zero when the facet faces
    /// away from `w` or `w` is on the other side of the macro surface than the facet sees).
    pub fn g1(&self, w: Vec3, wm: Vec3) -> f32 {
        smith_g1(w, wm, self.lambda(w))
    }

    /// Masking-shadowing G1(wo, wm) G1(wi, wm).
    pub fn g(&self, wo: Vec3, wi: Vec3, wm: Vec3) -> f32 {
        Distribution::g(self, wo, wi, wm)
    }

    /// Samples a microfacet normal (upper hemisphere) for light leaving towards `wo`: a
    /// visible normal for GGX, a normal from D(wm) cos θm for Beckmann.
    pub fn sample_wm(&self, wo: Vec3, u: Vec2) -> Vec3 {
        match self.kind {
            NormalDistribution::Ggx => sample_visible_ggx(self.alpha, self.alpha_y, wo, u.x, u.y),
            NormalDistribution::Beckmann if !self.is_isotropic() => {
                // D(wm) cos θm for elliptical slopes: the azimuth from the ellipse, then
                // tan²θ = -ln(1 - u) / (cos²φ/αx² + sin²φ/αy²).
                let (ax, ay) = (self.alpha, self.alpha_y);
                let mut phi = (ay / ax * (TAU * u.y + 0.5 * PI).tan()).atan();
                if u.y > 0.5 {
                    phi += PI;
                }
                let (sin_phi, cos_phi) = phi.sin_cos();
                let a2 = 1.0 / (cos_phi * cos_phi / (ax * ax) + sin_phi * sin_phi / (ay * ay));
                let tan2 = -a2 * (1.0 - u.x).max(f32::MIN_POSITIVE).ln();
                let cos = 1.0 / (1.0 + tan2).sqrt();
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                Vec3::new(sin * cos_phi, sin * sin_phi, cos)
            }
            NormalDistribution::Beckmann => sample_beckmann(self.alpha, u.x, u.y, true),
        }
    }

    /// Density per solid angle of [`Microfacet::sample_wm`] producing `wm`.
    pub fn pdf_wm(&self, wo: Vec3, wm: Vec3) -> f32 {
        match self.kind {
            NormalDistribution::Ggx => visible_normal_pdf(self, wo, wm),
            NormalDistribution::Beckmann => self.d(wm) * wm.z.max(0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_known_values() {
        for &(x, e) in &[
            (0.0f32, 0.0f32),
            (0.5, 0.520_499_9),
            (1.0, 0.842_700_8),
            (2.0, 0.995_322_3),
            (-1.0, -0.842_700_8),
        ] {
            assert!((erf(x) - e).abs() < 3e-7, "erf({x}) = {} vs {e}", erf(x));
        }
    }

    /// ∫ D(wm) cos θm dωm = 1 and ∫ D_wo(wm) dωm = 1 (midpoint rule in (cos θ, φ)).
    #[test]
    fn distributions_are_normalised() {
        for kind in [NormalDistribution::Beckmann, NormalDistribution::Ggx] {
            for &(alpha, alpha_y) in &[
                (0.1f32, 0.1f32),
                (0.3, 0.3),
                (0.8, 0.8),
                (0.2, 0.5),
                (0.6, 0.15),
            ] {
                let m = Microfacet::anisotropic(kind, alpha, alpha_y);
                let wo = Vec3::new(0.6, 0.0, 0.8);
                let (nz, nphi) = (4000, 64);
                let (mut proj, mut vis) = (0.0f64, 0.0f64);
                for i in 0..nz {
                    // Concentrate points near the pole, where narrow lobes live: z = 1 - s².
                    let s = (i as f64 + 0.5) / nz as f64;
                    let z = 1.0 - s * s;
                    let dz = 2.0 * s / nz as f64;
                    for j in 0..nphi {
                        let phi = (j as f64 + 0.5) / nphi as f64 * std::f64::consts::TAU;
                        let r = (1.0 - z * z).sqrt();
                        let wm =
                            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                        let dw = dz * std::f64::consts::TAU / nphi as f64;
                        proj += (m.d(wm) * wm.z) as f64 * dw;
                        vis += m.pdf_wm(wo, wm) as f64 * dw;
                    }
                }
                assert!(
                    (proj - 1.0).abs() < 2e-3,
                    "{kind:?} α {alpha}: ∫D cos = {proj}"
                );
                if kind == NormalDistribution::Ggx {
                    assert!((vis - 1.0).abs() < 2e-3, "α {alpha}: ∫D_wo = {vis}");
                }
            }
        }
    }
}
