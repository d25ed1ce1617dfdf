//! Scattered directions: mirror reflection and refraction by Snell's law, about the local
//! frame's normal (z) or a facet's normal. (Their weights are [`super::fresnel`]'s.)

use glam::Vec3;
use pathlab_mc::simd::lanes::{Real, Vector3};

/// Mirror reflection of `w` about the unit normal `n` (one direction, or lanes).
#[inline(always)]
pub fn reflect<V: Vector3>(w: V, n: V) -> V {
    n.scale(V::R::splat(2.0) * w.dot(n)) - w
}

/// Refraction of `w` (pointing away from the interface) through a facet with unit normal `n`
/// and relative index `eta` = n_below / n_above. `None` under total internal reflection;
/// otherwise the refracted direction and the relative index η' along the path.
pub fn refract_about(w: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (wt, etap, ok) = refract_about_real(w, n, eta);
    ok.then_some((wt, etap))
}

/// [`refract_about`] written once for one direction and for lanes: the refracted direction,
/// η', and where it exists (not total internal reflection).
#[inline(always)]
pub fn refract_about_real<V: Vector3>(w: V, n: V, eta: V::R) -> (V, V::R, <V::R as Real>::Mask) {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let cos = w.dot(n);
    // From below: the index seen from there, and the normal on w's side.
    let below = cos.lt(zero);
    let etap = V::R::select(below, one / eta, eta);
    let cos_i = V::R::select(below, -cos, cos);
    let n = V::select(below, -n, n);
    let sin2_t = (one - cos_i * cos_i).max(zero) / (etap * etap);
    let cos_t = (one - sin2_t).sqrt();
    let wt = (-w).div_by(etap) + n.scale(cos_i / etap - cos_t);
    (wt.normalize(), etap, !one.le(sin2_t))
}

/// The relative index η' of a pair of directions (local frame) across an interface of
/// relative index `eta` (inside / outside): η from outside in, 1/η from inside out, one when
/// both lie on the same side (or either on the interface). For one pair or lanes.
#[inline(always)]
pub fn relative_eta<V: Vector3>(wo: V, wi: V, eta: V::R) -> V::R {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    V::R::select(
        zero.le(wo.z() * wi.z()),
        one,
        V::R::select(wo.z().gt(zero), eta, one / eta),
    )
}

/// Refracts `wo` (local frame, z = normal) through an interface of relative index `eta`
/// (inside / outside); `None` under total internal reflection. Returns wi and the relative
/// index η' along the path (η for entering, 1/η for leaving).
pub fn refract(wo: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (wi, etap, ok) = refract_real(wo, eta);
    ok.then_some((wi, etap))
}

/// [`refract`] written once for one direction and for lanes: wi, η', and where it exists
/// (not total internal reflection).
#[inline(always)]
pub fn refract_real<V: Vector3>(wo: V, eta: V::R) -> (V, V::R, <V::R as Real>::Mask) {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let above = wo.z().gt(zero);
    let cos_o = V::R::select(above, wo.z(), -wo.z());
    let etap = V::R::select(above, eta, one / eta);
    let sign = V::R::select(above, one, -one);
    let sin2_t = (one - cos_o * cos_o).max(zero) / (etap * etap);
    let cos_t = (one - sin2_t).sqrt();
    let wi = V::new(-wo.x() / etap, -wo.y() / etap, -sign * cos_t);
    (wi.normalize(), etap, !one.le(sin2_t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_obeys_snell() {
        for &(theta, eta) in &[(0.3f32, 1.5f32), (1.2, 1.33), (0.7, 1.0 / 1.5)] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            match refract(wo, eta) {
                Some((wi, etap)) => {
                    assert!(wi.z < 0.0);
                    let sin_t = (wi.x * wi.x + wi.y * wi.y).sqrt();
                    assert!((theta.sin() - etap * sin_t).abs() < 1e-5, "{theta} {eta}");
                    // Back through the interface returns the original direction.
                    let (back, _) = refract(wi, eta).unwrap();
                    assert!((back - wo).length() < 1e-4);
                }
                None => assert!(theta.sin() / eta > 1.0),
            }
        }
    }

    #[test]
    fn refraction_about_a_facet_obeys_snell() {
        let n = Vec3::new(0.3, 0.1, 1.0).normalize();
        let w = Vec3::new(-0.2, 0.5, 0.8).normalize();
        let (t, etap) = refract_about(w, n, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        let sin_i = w.cross(n).length();
        let sin_t = t.cross(n).length();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(t.dot(n) < 0.0);
        let (back, _) = refract_about(t, n, 1.5).unwrap();
        assert!((back - w).length() < 1e-5);
        assert!((reflect(w, n).dot(n) - w.dot(n)).abs() < 1e-6);
    }
}
