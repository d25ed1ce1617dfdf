//! Perfect specular reflection, written once for one direction and for eight lanes.

use super::bxdf::DirectionSample;
use super::LocalSample;
use crate::desc::Rgb;
use glam::Vec3;
use pathlab_mc::simd::lanes::{Real, Vector3, V8};

/// A perfect mirror: wi = (-wo.x, -wo.y, wo.z), scaled by `reflectance` (a delta lobe). `V` is
/// the colour type: [`Rgb`], or [`V8`] for eight lanes' materials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mirror<V = Rgb> {
    /// Reflectance per channel.
    pub reflectance: V,
}

impl Mirror {
    /// The mirror direction, with f |cos θi| / pdf = reflectance.
    pub fn sample(&self, wo: Vec3) -> Option<LocalSample> {
        self.sample_real(wo).delta()
    }
}

impl<V: Vector3> Mirror<V> {
    /// [`Mirror::sample`] for one direction or lanes.
    #[inline(always)]
    pub fn sample_real(&self, wo: V) -> DirectionSample<V> {
        specular_reflection_real(wo, self.reflectance, V::R::splat(1.0))
    }
}

impl Mirror<V8> {
    /// Sets lane `i` to `m`. Every field is taken apart here: a field added to [`Mirror`]
    /// fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, m: Mirror) {
        let Mirror { reflectance } = m;
        self.reflectance.set(i, reflectance);
    }
}

/// A delta reflection lobe chosen with probability `pdf` whose throughput f |cos| / pdf is
/// `weight / pdf`, for one direction or lanes: it exists where `wo` is off the surface and
/// `pdf` is positive.
#[inline(always)]
pub(super) fn specular_reflection_real<V: Vector3>(
    wo: V,
    weight: V,
    pdf: V::R,
) -> DirectionSample<V> {
    let zero = V::R::splat(0.0);
    let wi = V::new(-wo.x(), -wo.y(), wo.z());
    DirectionSample {
        wi,
        pdf,
        f: weight.div_by(wi.z().abs()),
        valid: !wo.z().equals(zero) & !pdf.le(zero),
    }
}
