//! Perfect specular reflection.

use super::LocalSample;
use crate::desc::Rgb;
use glam::Vec3;

/// A perfect mirror: wi = (-wo.x, -wo.y, wo.z), scaled by `reflectance` (a delta lobe).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance per channel.
    pub reflectance: Rgb,
}

impl Mirror {
    /// The mirror direction, with f |cos θi| / pdf = reflectance.
    pub fn sample(&self, wo: Vec3) -> Option<LocalSample> {
        specular_reflection(wo, self.reflectance, 1.0)
    }
}

/// A delta reflection lobe chosen with probability `pdf` whose throughput f |cos| / pdf is
/// `weight / pdf`.
pub(super) fn specular_reflection(wo: Vec3, weight: Rgb, pdf: f32) -> Option<LocalSample> {
    if wo.z == 0.0 || pdf <= 0.0 {
        return None;
    }
    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
    Some(LocalSample {
        f: weight / wi.z.abs(),
        wi,
        pdf,
        delta: true,
    })
}
