//! pbrt-v4's quadrics: spheres (whole ones as spheres, parts of them tessellated), disks and
//! cylinders (tessellated), each with pbrt-v4's parameters and (u, v).

use super::params::ParamList;
use super::shapes::{AreaEmission, ObjectMesh, SEGMENTS};
use super::{Builder, GraphicsState};
use crate::Error;
use glam::{DMat3, DMat4, DVec3, Vec2};
use pathlab_render::desc::*;

/// What a `sphere` shape is.
pub(super) enum SphereExtent {
    /// The whole sphere, of this radius.
    Whole(f64),
    /// A part of it, tessellated.
    Partial(ObjectMesh),
}

/// The part of the sphere of `radius` between heights `z0 < z1` and azimuths 0 to `phi_max`
/// (radians): [`SEGMENTS`] columns over the azimuths, rows evenly spaced in θ (as many per
/// radian as the columns of a whole turn), vertices on the sphere with its normals, pbrt-v4's
/// (u, v), outward-facing triangles (those a pole makes degenerate are dropped when the scene
/// is built, as every mesh's are).
fn partial_sphere(radius: f64, z0: f64, z1: f64, phi_max: f64) -> ObjectMesh {
    let (theta0, theta1) = ((z0 / radius).acos(), (z1 / radius).acos());
    let rows = ((theta0 - theta1) / std::f64::consts::TAU * SEGMENTS as f64)
        .ceil()
        .max(1.0) as usize;
    let mut m = ObjectMesh::default();
    for i in 0..=SEGMENTS {
        let u = i as f64 / SEGMENTS as f64;
        let (sin_p, cos_p) = (u * phi_max).sin_cos();
        // From the bottom (z0) up, as the cylinder's columns run.
        for j in 0..=rows {
            let v = j as f64 / rows as f64;
            let (sin_t, cos_t) = (theta0 + v * (theta1 - theta0)).sin_cos();
            let n = DVec3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
            m.positions.push(radius * n);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u as f32, v as f32));
        }
    }
    grid_triangles(&mut m, rows as u32 + 1);
    m
}

/// The triangles of a tessellated quadric whose vertices run in [`SEGMENTS`] + 1 columns
/// (one per azimuth step) of `per_column` each: two per cell, wound as a column's first
/// vertex, the next column's, then the next column's second (the outward side of a disk's
/// annulus and of the cylinder and sphere walls).
fn grid_triangles(m: &mut ObjectMesh, per_column: u32) {
    for i in 0..SEGMENTS as u32 {
        for j in 0..per_column - 1 {
            let (a, b) = (i * per_column + j, i * per_column + j + 1);
            let (c, d) = (a + per_column, b + per_column);
            m.indices.extend([a, c, d, a, d, b]);
        }
    }
}

impl Builder {
    /// A disk (or annulus) at height `height`, normal +z, as a fan of [`SEGMENTS`].
    pub(super) fn disk(&mut self, params: &ParamList) -> Result<ObjectMesh, Error> {
        let h = self.float(params, "height", 0.0)?;
        let r = self.float(params, "radius", 1.0)?;
        let ri = self.float(params, "innerradius", 0.0)?;
        let phi_max = self
            .float(params, "phimax", 360.0)?
            .clamp(0.0, 360.0)
            .to_radians();
        if !(r > 0.0 && ri >= 0.0 && ri < r) {
            return Err(self.error(format!(
                "Shape \"disk\": need 0 <= innerradius ({ri}) < radius ({r})"
            )));
        }
        let mut m = ObjectMesh::default();
        for i in 0..=SEGMENTS {
            let phi = phi_max * i as f64 / SEGMENTS as f64;
            let (s, c) = phi.sin_cos();
            m.positions.push(DVec3::new(r * c, r * s, h));
            m.positions.push(DVec3::new(ri * c, ri * s, h));
            let u = (phi / phi_max) as f32;
            m.uvs.push(Vec2::new(u, 0.0));
            m.uvs.push(Vec2::new(u, 1.0));
        }
        // Outer then inner in each column: counter-clockwise seen from +z.
        grid_triangles(&mut m, 2);
        Ok(m)
    }

    /// A cylinder about z from `zmin` to `zmax`, normals outwards, [`SEGMENTS`] around.
    pub(super) fn cylinder(&mut self, params: &ParamList) -> Result<ObjectMesh, Error> {
        let r = self.float(params, "radius", 1.0)?;
        let z0 = self.float(params, "zmin", -1.0)?;
        let z1 = self.float(params, "zmax", 1.0)?;
        let phi_max = self
            .float(params, "phimax", 360.0)?
            .clamp(0.0, 360.0)
            .to_radians();
        if !(r > 0.0 && z1 != z0) {
            return Err(self.error("Shape \"cylinder\": need radius > 0 and zmin != zmax"));
        }
        let mut m = ObjectMesh::default();
        for i in 0..=SEGMENTS {
            let phi = phi_max * i as f64 / SEGMENTS as f64;
            let (s, c) = phi.sin_cos();
            for z in [z0.min(z1), z0.max(z1)] {
                m.positions.push(DVec3::new(r * c, r * s, z));
                m.normals.push(DVec3::new(c, s, 0.0));
            }
        }
        grid_triangles(&mut m, 2);
        Ok(m)
    }

    /// A sphere's `radius`, and its part: the whole sphere (rendered as a sphere), or the part
    /// between heights `zmin` and `zmax` up to azimuth `phimax`, as pbrt-v4 defines them
    /// (clamped to the sphere; u = φ / φmax, v from θ at zmin to θ at zmax), tessellated as
    /// the disk and cylinder are, with the sphere's normals.
    pub(super) fn sphere_extent(&mut self, params: &ParamList) -> Result<SphereExtent, Error> {
        let radius = self.float(params, "radius", 1.0)?;
        if radius.is_nan() || radius <= 0.0 {
            return Err(self.error(format!(
                "Shape \"sphere\": radius {radius} must be positive"
            )));
        }
        let zmin = self.float(params, "zmin", -radius)?;
        let zmax = self.float(params, "zmax", radius)?;
        let phimax = self.float(params, "phimax", 360.0)?;
        if [zmin, zmax, phimax].iter().any(|v| !v.is_finite()) {
            return Err(self.error("Shape \"sphere\": zmin, zmax and phimax must be finite"));
        }
        let (z0, z1) = (
            zmin.min(zmax).clamp(-radius, radius),
            zmin.max(zmax).clamp(-radius, radius),
        );
        let phi_max = phimax.clamp(0.0, 360.0).to_radians();
        if z0 <= -radius && z1 >= radius && phimax >= 360.0 {
            return Ok(SphereExtent::Whole(radius));
        }
        if z0 >= z1 || phi_max <= 0.0 {
            self.warn("Shape \"sphere\": zmin, zmax and phimax leave no surface; skipped");
            return Ok(SphereExtent::Partial(ObjectMesh::default()));
        }
        Ok(SphereExtent::Partial(partial_sphere(
            radius, z0, z1, phi_max,
        )))
    }

    /// A whole sphere of `radius` in object space, placed by `m`.
    pub(super) fn sphere(
        &mut self,
        radius: f64,
        m: DMat4,
        material: usize,
        emission: Option<&AreaEmission>,
        state: &GraphicsState,
    ) -> Result<(), Error> {
        let axes = DMat3::from_mat4(m);
        let scales = [
            axes.x_axis.length(),
            axes.y_axis.length(),
            axes.z_axis.length(),
        ];
        if (scales[0] - scales[1]).abs() > 1e-4 * scales[0]
            || (scales[0] - scales[2]).abs() > 1e-4 * scales[0]
        {
            self.warn(
                "Shape \"sphere\": a non-uniform scale is not supported; the x scale is used",
            );
        }
        if state.reverse_orientation && emission.is_some() {
            self.warn(
                "Shape \"sphere\": an emitting sphere with ReverseOrientation still emits outwards",
            );
        }
        let rot = DMat3::from_cols(
            axes.x_axis / scales[0],
            axes.y_axis / scales[1],
            axes.z_axis / scales[2],
        );
        let world_radius = radius * scales[0];
        let area = 4.0 * std::f64::consts::PI * world_radius * world_radius;
        let emission_texture = emission.and_then(|e| e.texture.clone());
        let emission = emission.map(|e| e.for_area(area));
        self.desc.spheres.push(SphereDesc {
            center: m.transform_point3(DVec3::ZERO).as_vec3(),
            radius: world_radius as f32,
            material,
            emission,
            to_object: rot.transpose().as_mat3(),
            emission_texture,
        });
        Ok(())
    }
}
