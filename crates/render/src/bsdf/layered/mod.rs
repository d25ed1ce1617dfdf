//! pbrt-v4's layered BSDFs, `coateddiffuse` and `coatedconductor`: a dielectric coat (smooth
//! or rough) over a diffuse or conductor base, with an optional scattering medium of albedo
//! `albedo` and Henyey–Greenstein asymmetry `g` filling a layer of optical `thickness` between
//! them. Both sides alike (pbrt-v4's two-sided layers).
//!
//! Nothing is precomputed: light's walk between the interfaces is simulated, as in pbrt-v4.
//! - `f` averages `samples` random walks from `wo`, each entering through the coat, bouncing
//!   off the base and inside the coat (up to `max_depth` events, then Russian roulette), and
//!   at each bounce connecting to a direction refracted in from `wi` (next-event estimation
//!   combined with the walk's own directions by the power heuristic). An unbiased estimate of
//!   the layered BSDF's value.
//! - `sample` follows one walk from `wo` until it leaves through the coat: an unbiased
//!   estimate of f |cos| / pdf along its exit direction.
//! - `pdf` is an estimate too (the coat's reflection, and reflection off the base through the
//!   coat twice), mixed with the uniform sphere density as pbrt-v4 mixes it: it serves MIS.
//!
//! The random numbers of `f` and `pdf` come from a generator seeded by the directions (and of
//! `sample`'s walk by its own uniform numbers), so each is a fixed function of its arguments:
//! the same image for any thread count, and a `pdf` that light sampling and BSDF sampling agree
//! on. [`Layered::sample`] returns that `pdf` with f scaled to keep the walk's f / pdf, so
//! that the path tracer's MIS weights use one density for both strategies.

use super::microfacet::Microfacet;
use super::phase::HenyeyGreenstein;
use super::scattering::relative_eta;
use super::{Conductor, Diffuse, Lobes, LocalSample, RoughDielectric, SmoothDielectric};
use crate::desc::Rgb;
use crate::integrator::power_heuristic;
use glam::{Vec2, Vec3};
use pathlab_mc::rng::{hash_words, Pcg32};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// The dielectric coat on top.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    /// Index of refraction of the coat relative to the outside.
    pub eta: f32,
    /// Its microfacet roughness (`None`: smooth).
    pub roughness: Option<Microfacet>,
}

/// What lies under the coat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Base {
    /// Lambertian, of the albedo [`Layered::reflectance`] gives.
    Diffuse,
    /// A smooth or rough conductor.
    Conductor(Conductor),
}

/// A coat over a base with a medium between them (see the module's description): interned
/// ([`LayerStack::interned`]) so that a [`Layered`] holds a reference to it. What may vary
/// over a surface (the diffuse base's albedo, the roughnesses, the medium) the [`Layered`]
/// holds itself, starting from the stack's values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerStack {
    /// The top interface.
    pub coat: Coat,
    /// The bottom interface.
    pub base: Base,
    /// The medium between them (where a material's is textured, each [`Layered`] holds its
    /// own).
    pub medium: LayerMedium,
    /// Most scattering events a walk follows.
    pub max_depth: u16,
    /// Walks averaged by each `f` and `pdf` estimate.
    pub samples: u16,
}

impl LayerStack {
    /// The one shared copy of this stack (stacks are few: one per coated material of the
    /// scenes loaded, kept for the life of the program).
    pub fn interned(self) -> &'static LayerStack {
        static STACKS: OnceLock<Mutex<HashMap<Vec<u32>, &'static LayerStack>>> = OnceLock::new();
        let bits = |c: Rgb| [c.x, c.y, c.z].map(f32::to_bits);
        let mut key = vec![
            self.coat.eta.to_bits(),
            self.medium.thickness.to_bits(),
            self.medium.g.to_bits(),
            self.max_depth as u32,
            self.samples as u32,
        ];
        key.extend(bits(self.medium.albedo));
        let facets = |m: Option<Microfacet>| match m {
            None => [0, 0, 0],
            Some(m) => [1 + m.kind as u32, m.alpha.to_bits(), m.alpha_y.to_bits()],
        };
        key.extend(facets(self.coat.roughness));
        if let Base::Conductor(c) = self.base {
            key.extend(bits(c.eta));
            key.extend(bits(c.k));
            key.extend(bits(c.specular));
            key.extend(facets(c.distribution));
        }
        let mut stacks = STACKS
            .get_or_init(Default::default)
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        stacks
            .entry(key)
            .or_insert_with(|| Box::leak(Box::new(self)))
    }
}

/// A layered BSDF: a [`LayerStack`] and what may vary over the surface: a diffuse base's
/// albedo, the coat's and a conductor base's roughness, and the layer's medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layered {
    /// Coat, base and medium.
    pub stack: &'static LayerStack,
    /// Albedo of a diffuse base (unused over a conductor).
    pub reflectance: Rgb,
    /// The coat's microfacet roughness here (`None`: smooth); the stack's own unless the
    /// material's roughness is textured.
    pub coat_roughness: Option<Microfacet>,
    /// A conductor base's roughness here, as `coat_roughness` (unused over a diffuse base).
    pub base_roughness: Option<Microfacet>,
    /// The layer's medium here: the stack's own unless the material's is textured.
    pub medium: LayerMedium,
}

/// The medium between coat and base, as it may vary over the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerMedium {
    /// Optical thickness of the layer (in units of the medium's mean free path).
    pub thickness: f32,
    /// Single-scattering albedo (zero: no medium, only absorption-free travel).
    pub albedo: Rgb,
    /// Henyey–Greenstein asymmetry.
    pub g: f32,
}

impl LayerMedium {
    /// The medium of these parameters, kept in range: a thickness of at least the smallest
    /// positive number, an albedo in [0, 1] and an asymmetry in [-0.99, 0.99].
    pub fn new(thickness: f32, albedo: Rgb, g: f32) -> Self {
        LayerMedium {
            thickness: thickness.max(f32::MIN_POSITIVE),
            albedo: albedo.clamp(Rgb::ZERO, Rgb::ONE),
            g: g.clamp(-0.99, 0.99),
        }
    }
}

/// Whether a walk carries radiance (from the camera) or importance (from a light): refraction
/// scales radiance by 1/η'² and importance not at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Radiance,
    Importance,
}

/// One sampled event at an interface.
#[derive(Clone, Copy, Debug)]
struct Event {
    f: Rgb,
    wi: Vec3,
    pdf: f32,
    reflection: bool,
}

/// The interface a walk meets.
#[derive(Clone, Copy)]
enum Interface {
    Top(Coat),
    Diffuse(Diffuse),
    Conductor(Conductor),
}

/// η'² undone on a transmission from `wo` to `wi` (the radiance scaling of refraction, which
/// importance does not have).
fn adjoint(mode: Mode, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    if mode == Mode::Radiance {
        return 1.0;
    }
    let etap = relative_eta(wo, wi, eta);
    etap * etap
}

impl Coat {
    fn smooth(&self) -> Option<SmoothDielectric> {
        (self.roughness.is_none() || self.eta == 1.0).then_some(SmoothDielectric {
            eta: self.eta,
            reflectance: Rgb::ONE,
            transmittance: Rgb::ONE,
            fresnel: super::FresnelModel::Exact,
        })
    }

    fn rough(&self) -> Option<RoughDielectric> {
        match (self.roughness, self.eta == 1.0) {
            (Some(distribution), false) => Some(RoughDielectric {
                eta: self.eta,
                distribution,
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
            }),
            _ => None,
        }
    }
}

impl Interface {
    fn specular(self) -> bool {
        match self {
            Interface::Top(c) => c.smooth().is_some(),
            Interface::Diffuse(_) => false,
            Interface::Conductor(c) => c.distribution.is_none(),
        }
    }

    fn f(self, wo: Vec3, wi: Vec3, mode: Mode) -> Rgb {
        match self {
            Interface::Top(c) => match c.rough() {
                Some(r) => r.f(wo, wi) * adjoint(mode, wo, wi, c.eta),
                None => Rgb::ZERO,
            },
            Interface::Diffuse(d) => d.f(wo, wi),
            Interface::Conductor(c) => c.f(wo, wi),
        }
    }

    fn pdf(self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        match self {
            Interface::Top(c) => c.rough().map_or(0.0, |r| r.pdf_lobes(wo, wi, lobes)),
            _ if lobes == Lobes::Transmission => 0.0,
            Interface::Diffuse(d) => d.pdf(wo, wi),
            Interface::Conductor(c) => c.pdf(wo, wi),
        }
    }

    fn sample(self, wo: Vec3, uc: f32, u: Vec2, mode: Mode, lobes: Lobes) -> Option<Event> {
        let s = match self {
            Interface::Top(c) => {
                let s = match (c.smooth(), c.rough()) {
                    (Some(smooth), _) => smooth.sample_lobes(wo, uc, lobes),
                    (None, Some(rough)) => rough.sample_lobes(wo, uc, u, lobes),
                    (None, None) => None,
                }?;
                LocalSample {
                    f: s.f * adjoint(mode, wo, s.wi, c.eta),
                    ..s
                }
            }
            _ if lobes == Lobes::Transmission => return None,
            Interface::Diffuse(d) => d.sample(wo, u)?,
            Interface::Conductor(c) => c.sample(wo, u)?,
        };
        (s.pdf > 0.0 && s.wi.z != 0.0 && s.f.max_element() > 0.0).then_some(Event {
            f: s.f,
            wi: s.wi,
            pdf: s.pdf,
            reflection: s.wi.z * wo.z > 0.0,
        })
    }
}

/// The density with which refracting in from `wi` (the other strategy of the walk's
/// connections) produces the inner direction `w` that a walk follows towards the coat: the
/// density of `-w` sampled from `wi`. (pbrt-v4 weighs with the density of `wi` sampled from
/// `-w` instead, which for a rough coat differs and leaves the two weights summing to other
/// than one: a bias this evaluation does not have.)
fn refracted_pdf(top: Interface, wi: Vec3, w: Vec3) -> f32 {
    top.pdf(wi, -w, Lobes::Transmission)
}

/// Transmittance through a layer of optical depth `dz` along `w`.
fn tr(dz: f32, w: Vec3) -> f32 {
    if dz.abs() <= f32::MIN_POSITIVE {
        1.0
    } else {
        (-(dz / w.z).abs()).exp()
    }
}

/// A generator seeded by two directions (and a salt): the same numbers for the same query.
fn rng_for(a: Vec3, b: Vec3, salt: u64) -> Pcg32 {
    let words = |v: Vec3| [v.x, v.y, v.z].map(|c| c.to_bits() as u64);
    let [ax, ay, az] = words(a);
    let [bx, by, bz] = words(b);
    Pcg32::new(
        hash_words(&[ax, ay, az, salt]),
        hash_words(&[bx, by, bz, salt]),
    )
}

/// A uniform number in [0, 1).
fn next(rng: &mut Pcg32) -> f32 {
    rng.uniform_f32().min(1.0 - f32::EPSILON)
}

impl Layered {
    /// A layered BSDF of `stack` (interned here) and base albedo `reflectance`.
    pub fn new(stack: LayerStack, reflectance: Rgb) -> Self {
        Layered {
            coat_roughness: stack.coat.roughness,
            base_roughness: match stack.base {
                Base::Conductor(c) => c.distribution,
                Base::Diffuse => None,
            },
            medium: stack.medium,
            stack: stack.interned(),
            reflectance,
        }
    }

    fn top(&self) -> Interface {
        Interface::Top(Coat {
            eta: self.stack.coat.eta,
            roughness: self.coat_roughness,
        })
    }

    fn bottom(&self) -> Interface {
        match &self.stack.base {
            Base::Diffuse => Interface::Diffuse(Diffuse {
                reflectance: self.reflectance,
            }),
            Base::Conductor(c) => Interface::Conductor(Conductor {
                distribution: self.base_roughness,
                ..*c
            }),
        }
    }

    fn has_medium(&self) -> bool {
        self.medium.albedo.max_element() > 0.0
    }

    fn phase(&self) -> HenyeyGreenstein {
        HenyeyGreenstein { g: self.medium.g }
    }

    /// f(wo, wi): the coat's reflection plus the mean of `samples` random walks' estimates.
    pub fn f(&self, mut wo: Vec3, mut wi: Vec3) -> Rgb {
        if wo.z < 0.0 {
            (wo, wi) = (-wo, -wi);
        }
        // The base transmits nothing: light leaves on wo's side only.
        if wo.z * wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let n = self.stack.samples.max(1) as f32;
        let mut f = self.top().f(wo, wi, Mode::Radiance) * n;
        let mut rng = rng_for(wo, wi, 1);
        for _ in 0..self.stack.samples.max(1) {
            f += self.walk_estimate(wo, wi, &mut rng);
        }
        f / n
    }

    /// One random walk's estimate of the light from `wi` leaving along `wo` after entering the
    /// layer (pbrt-v4's `LayeredBxDF::f` loop, for the coat as entrance and exit).
    fn walk_estimate(&self, wo: Vec3, wi: Vec3, rng: &mut Pcg32) -> Rgb {
        let (top, bottom) = (self.top(), self.bottom());
        // Fixed for the material: asked once, not at every event.
        let (top_specular, bottom_specular) = (top.specular(), bottom.specular());
        let thickness = self.medium.thickness;
        let exit_z = thickness;
        let mut r = || next(rng);
        let mut f = Rgb::ZERO;
        // Into the layer along wo, and the virtual light's way in along wi.
        let (uc, u) = (r(), Vec2::new(r(), r()));
        let Some(wos) = top.sample(wo, uc, u, Mode::Radiance, Lobes::Transmission) else {
            return f;
        };
        let (uc, u) = (r(), Vec2::new(r(), r()));
        let Some(wis) = top.sample(wi, uc, u, Mode::Importance, Lobes::Transmission) else {
            return f;
        };
        let mut beta = wos.f * wos.wi.z.abs() / wos.pdf;
        let mut z = thickness;
        let mut w = wos.wi;
        let phase = self.phase();
        for depth in 0..self.stack.max_depth {
            if depth > 3 && beta.max_element() < 0.25 {
                let q = (1.0 - beta.max_element()).max(0.0);
                if r() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            if !self.has_medium() {
                z = if z == thickness { 0.0 } else { thickness };
                beta *= tr(thickness, w);
            } else {
                let dz = -(1.0 - r()).ln() * w.z.abs();
                let zp = if w.z > 0.0 { z + dz } else { z - dz };
                if zp == z {
                    continue;
                }
                if 0.0 < zp && zp < thickness {
                    // Scattered inside: connect to wis, then walk on by the phase function.
                    let wt = if top_specular {
                        1.0
                    } else {
                        power_heuristic(1, wis.pdf, 1, phase.p(-w, -wis.wi))
                    };
                    f += beta
                        * self.medium.albedo
                        * phase.p(-w, -wis.wi)
                        * wt
                        * tr(zp - exit_z, wis.wi)
                        * wis.f
                        / wis.pdf;
                    let ps = phase.sample(-w, Vec2::new(r(), r()));
                    if ps.p <= 0.0 || ps.wi.z == 0.0 {
                        continue;
                    }
                    beta *= self.medium.albedo; // p / pdf = 1
                    w = ps.wi;
                    z = zp;
                    if (z < exit_z && w.z > 0.0 || z > exit_z && w.z < 0.0) && !top_specular {
                        let f_exit = top.f(-w, wi, Mode::Radiance);
                        if f_exit.max_element() > 0.0 {
                            let wt = power_heuristic(1, ps.p, 1, refracted_pdf(top, wi, w));
                            f += beta * tr(zp - exit_z, ps.wi) * f_exit * wt;
                        }
                    }
                    continue;
                }
                z = zp.clamp(0.0, thickness);
            }
            if z == exit_z {
                // Reflected back down by the coat.
                let (uc, u) = (r(), Vec2::new(r(), r()));
                let Some(bs) = top.sample(-w, uc, u, Mode::Radiance, Lobes::Reflection) else {
                    break;
                };
                beta *= bs.f * bs.wi.z.abs() / bs.pdf;
                w = bs.wi;
            } else {
                // At the base: connect to wis, then reflect.
                if !bottom_specular {
                    let wt = if top_specular {
                        1.0
                    } else {
                        power_heuristic(1, wis.pdf, 1, bottom.pdf(-w, -wis.wi, Lobes::All))
                    };
                    f += beta
                        * bottom.f(-w, -wis.wi, Mode::Radiance)
                        * wis.wi.z.abs()
                        * wt
                        * tr(thickness, wis.wi)
                        * wis.f
                        / wis.pdf;
                }
                let (uc, u) = (r(), Vec2::new(r(), r()));
                let Some(bs) = bottom.sample(-w, uc, u, Mode::Radiance, Lobes::Reflection) else {
                    break;
                };
                beta *= bs.f * bs.wi.z.abs() / bs.pdf;
                w = bs.wi;
                if !top_specular {
                    let f_exit = top.f(-w, wi, Mode::Radiance);
                    if f_exit.max_element() > 0.0 {
                        let wt = if bottom_specular {
                            1.0
                        } else {
                            power_heuristic(1, bs.pdf, 1, refracted_pdf(top, wi, w))
                        };
                        f += beta * tr(thickness, bs.wi) * f_exit * wt;
                    }
                }
            }
        }
        f
    }

    /// A direction from `wo`: the coat's reflection, or a walk through the layers until it
    /// leaves through the coat. The returned pdf is [`Layered::pdf`] and f keeps the walk's
    /// f / pdf (see the module's description).
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        let flip = wo.z < 0.0;
        let wo_up = if flip { -wo } else { wo };
        let (f, wi, pdf, delta) = self.walk(wo_up, uc, u)?;
        let wi = if flip { -wi } else { wi };
        if delta {
            return Some(LocalSample {
                f,
                wi,
                pdf,
                delta: true,
            });
        }
        let estimate = self.pdf(wo, wi);
        (estimate > 0.0 && pdf > 0.0).then(|| LocalSample {
            f: f * (estimate / pdf),
            wi,
            pdf: estimate,
            delta: false,
        })
    }

    /// One walk from `wo` (above): (f, the exit direction, the walk's density, whether it is
    /// the coat's specular reflection).
    fn walk(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<(Rgb, Vec3, f32, bool)> {
        let (top, bottom) = (self.top(), self.bottom());
        let entry = top.sample(wo, uc, u, Mode::Radiance, Lobes::All)?;
        if entry.reflection {
            return Some((entry.f, entry.wi, entry.pdf, top.specular()));
        }
        let mut rng = rng_for(wo, Vec3::new(uc, u.x, u.y), 3);
        let mut r = || next(&mut rng);
        let mut f = entry.f * entry.wi.z.abs();
        let mut pdf = entry.pdf;
        let mut w = entry.wi;
        let thickness = self.medium.thickness;
        let mut z = thickness;
        let phase = self.phase();
        for depth in 0..self.stack.max_depth {
            let rr_beta = f.max_element() / pdf;
            if depth > 3 && rr_beta < 0.25 {
                let q = (1.0 - rr_beta).max(0.0);
                if r() < q {
                    return None;
                }
                pdf *= 1.0 - q;
            }
            if w.z == 0.0 {
                return None;
            }
            if self.has_medium() {
                let dz = -(1.0 - r()).ln() * w.z.abs();
                let zp = if w.z > 0.0 { z + dz } else { z - dz };
                if zp == z {
                    return None;
                }
                if 0.0 < zp && zp < thickness {
                    let ps = phase.sample(-w, Vec2::new(r(), r()));
                    if ps.p <= 0.0 || ps.wi.z == 0.0 {
                        return None;
                    }
                    f *= self.medium.albedo * ps.p;
                    pdf *= ps.p;
                    w = ps.wi;
                    z = zp;
                    continue;
                }
                z = zp.clamp(0.0, thickness);
            } else {
                z = if z == thickness { 0.0 } else { thickness };
                f *= tr(thickness, w);
            }
            let interface = if z == 0.0 { bottom } else { top };
            let (uc, u) = (r(), Vec2::new(r(), r()));
            let bs = interface.sample(-w, uc, u, Mode::Radiance, Lobes::All)?;
            f *= bs.f;
            pdf *= bs.pdf;
            w = bs.wi;
            if !bs.reflection {
                // Out through the coat.
                return Some((f, w, pdf, false));
            }
            f *= bs.wi.z.abs();
        }
        None
    }

    /// An estimate of the density of [`Layered::sample`]: the coat's reflection and
    /// transmission-reflection-transmission through the base, averaged over `samples` draws,
    /// mixed 9 : 1 with the uniform sphere density (pbrt-v4's estimate).
    pub fn pdf(&self, mut wo: Vec3, mut wi: Vec3) -> f32 {
        if wo.z < 0.0 {
            (wo, wi) = (-wo, -wi);
        }
        let (top, bottom) = (self.top(), self.bottom());
        // Fixed for the material: asked once, not at every event.
        let (top_specular, bottom_specular) = (top.specular(), bottom.specular());
        let n = self.stack.samples.max(1);
        let mut sum = 0.0;
        if wo.z * wi.z > 0.0 {
            sum += n as f32 * top.pdf(wo, wi, Lobes::Reflection);
            let mut rng = rng_for(wi, wo, 2);
            let mut r = || next(&mut rng);
            for _ in 0..n {
                let wos = top.sample(
                    wo,
                    r(),
                    Vec2::new(r(), r()),
                    Mode::Radiance,
                    Lobes::Transmission,
                );
                let wis = top.sample(
                    wi,
                    r(),
                    Vec2::new(r(), r()),
                    Mode::Importance,
                    Lobes::Transmission,
                );
                let (Some(wos), Some(wis)) = (wos, wis) else {
                    continue;
                };
                if top_specular {
                    sum += bottom.pdf(-wos.wi, -wis.wi, Lobes::All);
                    continue;
                }
                let Some(rs) = bottom.sample(
                    -wos.wi,
                    r(),
                    Vec2::new(r(), r()),
                    Mode::Radiance,
                    Lobes::All,
                ) else {
                    continue;
                };
                if bottom_specular {
                    sum += top.pdf(-rs.wi, wi, Lobes::All);
                } else {
                    let r_pdf = bottom.pdf(-wos.wi, -wis.wi, Lobes::All);
                    sum += power_heuristic(1, wis.pdf, 1, r_pdf) * r_pdf;
                    let t_pdf = top.pdf(-rs.wi, wi, Lobes::All);
                    sum += power_heuristic(1, rs.pdf, 1, t_pdf) * t_pdf;
                }
            }
        }
        let uniform = 1.0 / (4.0 * std::f32::consts::PI);
        0.1 * uniform + 0.9 * sum / n as f32
    }
}

#[cfg(test)]
mod tests;
