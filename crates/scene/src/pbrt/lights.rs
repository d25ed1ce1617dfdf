//! pbrt-v4's lights: `point`, `spot`, `distant`, `infinite` (a constant radiance, or an image
//! in pbrt-v4's equal-area octahedral mapping when square and lat-long otherwise), `goniometric`
//! and `projection` warned about; `scale` and `power` as pbrt-v4 defines them.

use super::params::ParamList;
use super::spectra::Use;
use super::Builder;
use crate::Error;
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use pathlab_render::desc::*;

impl Builder {
    /// The current transform into pathlab's world.
    pub(crate) fn to_world(&self) -> DMat4 {
        self.world_fix * self.gs.ctm
    }

    /// A light's `scale`, times what `power`-like parameters ask for (`per_unit`: the
    /// factor from the spectrum's unit to the requested quantity).
    fn light_scale(&mut self, params: &ParamList, power_name: &str, k: f64) -> Result<f32, Error> {
        let mut scale = self.emission_scale(params)? as f64;
        let power = self.float(params, power_name, -1.0)?;
        if power > 0.0 {
            scale *= power / k;
        }
        Ok(scale as f32)
    }

    /// A light's `scale` (default 1): an error naming its line unless it is a number >= 0.
    pub(crate) fn emission_scale(&self, params: &ParamList) -> Result<f32, Error> {
        let scale = self.float(params, "scale", 1.0)?;
        self.check_non_negative(params, "scale", scale, "a light's scale")?;
        Ok(scale as f32)
    }

    /// An image infinite light as pathlab's latitude-longitude map: pbrt-v4's equal-area
    /// octahedral mapping for square images (pbrt-v3's latitude-longitude, z up, otherwise),
    /// resampled bilinearly onto a map in the world's frame. `m` is the light's transform;
    /// `illuminance` (when positive) sets the irradiance the upper hemisphere of the light's
    /// frame gives a surface facing up, as pbrt-v4 does.
    fn image_light(
        &mut self,
        path: &std::path::Path,
        m: DMat4,
        scale: f32,
        illuminance: f64,
    ) -> Result<EnvironmentMapDesc, Error> {
        let (w, h, texels) = crate::texture::read_image(path, true)?;
        let (w, h) = (w as usize, h as usize);
        let square = w == h;
        if !square {
            self.warn(format!(
                "infinite \"{}\": not square, so read as pbrt-v3's latitude-longitude map (pbrt-v4 reads only square equal-area maps)",
                path.display()
            ));
        }
        let light_from_world = glam::DMat3::from_mat4(m).inverse();
        let out_w = (2 * w).clamp(8, 4096);
        let out_h = (w + 1).clamp(5, 2049);
        let lookup = |uv: Vec2| -> Rgb {
            // Pixel centres at (i + ½) / w; row 0 at the top, as pbrt's images.
            let x = (uv.x * w as f32 - 0.5).clamp(0.0, (w - 1) as f32);
            let y = (uv.y * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
            let (x0, y0) = (x as usize, y as usize);
            let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
            let (fx, fy) = (x - x0 as f32, y - y0 as f32);
            let at = |i: usize, j: usize| texels[j * w + i];
            (at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx) * (1.0 - fy)
                + (at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx) * fy
        };
        let mut out = Vec::with_capacity(out_w * out_h);
        let mut upper = 0.0f64;
        for j in 0..out_h {
            for i in 0..out_w {
                let d = pathlab_render::envmap::EnvironmentMap::grid_direction(i, j, out_w, out_h);
                let wl = (light_from_world * d.as_dvec3()).normalize_or_zero();
                let uv = if square {
                    equal_area_sphere_to_square(wl)
                } else {
                    let phi = wl.y.atan2(wl.x);
                    let phi = if phi < 0.0 {
                        phi + std::f64::consts::TAU
                    } else {
                        phi
                    };
                    Vec2::new(
                        (phi / std::f64::consts::TAU) as f32,
                        (wl.z.clamp(-1.0, 1.0).acos() / std::f64::consts::PI) as f32,
                    )
                };
                let l = lookup(uv);
                let l = if l.is_finite() {
                    l.max(Rgb::ZERO)
                } else {
                    Rgb::ZERO
                };
                if wl.z > 0.0 {
                    let sin_t = (std::f64::consts::PI * j as f64 / (out_h - 1) as f64).sin();
                    let lum = pathlab_render::color::luminance_f64(l.as_dvec3());
                    upper += lum * wl.z * sin_t;
                }
                out.push(l);
            }
        }
        let d_omega =
            std::f64::consts::TAU / out_w as f64 * std::f64::consts::PI / (out_h - 1) as f64;
        let mut scale = scale;
        if illuminance > 0.0 {
            let e = upper * d_omega;
            if e > 0.0 {
                scale *= (illuminance / e) as f32;
            }
        }
        Ok(EnvironmentMapDesc {
            source: path.display().to_string(),
            width: out_w,
            height: out_h,
            texels: std::sync::Arc::new(out),
            to_world: Mat3::IDENTITY,
            scale,
        })
    }

    /// `LightSource`.
    pub(crate) fn light(&mut self, kind: &str, params: ParamList) -> Result<(), Error> {
        let m = self.to_world();
        let point = |name: &str, default: DVec3, b: &Self| -> Result<DVec3, Error> {
            match params.get(name) {
                None => Ok(default),
                Some(p) => match p.numbers() {
                    Some([x, y, z]) => Ok(DVec3::new(*x, *y, *z)),
                    _ => Err(b.error(format!(
                        "\"{} {name}\" (line {}): expected a point",
                        p.ty, p.line
                    ))),
                },
            }
        };
        match kind {
            "point" => {
                let i = self
                    .spectrum(&params, "I", Use::Illuminant)?
                    .unwrap_or(Vec3::ONE);
                let scale = self.light_scale(&params, "power", 4.0 * std::f64::consts::PI)?;
                let from = point("from", DVec3::ZERO, self)?;
                self.desc.point_lights.push(PointLightDesc {
                    position: m.transform_point3(from).as_vec3(),
                    intensity: i * scale,
                    attenuation: INVERSE_SQUARE,
                });
            }
            "spot" => {
                let i = self
                    .spectrum(&params, "I", Use::Illuminant)?
                    .unwrap_or(Vec3::ONE);
                let cone = self.float(&params, "coneangle", 30.0)?;
                let delta = self.float(&params, "conedelta", 5.0)?;
                let (cos_end, cos_start) =
                    (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                let k =
                    2.0 * std::f64::consts::PI * ((1.0 - cos_start) + (cos_start - cos_end) / 2.0);
                let scale = self.light_scale(&params, "power", k)?;
                let from = point("from", DVec3::ZERO, self)?;
                let to = point("to", DVec3::Z, self)?;
                let z = m
                    .transform_vector3(to - from)
                    .as_vec3()
                    .normalize_or(Vec3::Z);
                let (x, y) = z.any_orthonormal_pair();
                self.desc.projectors.push(ProjectorDesc {
                    position: m.transform_point3(from).as_vec3(),
                    frame: Mat3::from_cols(x, y, z),
                    texture: TextureDesc::value(1.0),
                    kind: ProjectorKind::Spot {
                        intensity: i * scale,
                        cutoff: cone.to_radians() as f32,
                        beam_width: (cone - delta).max(0.0).to_radians() as f32,
                        falloff: SpotFalloff::SmoothStepInCosine,
                    },
                });
            }
            "distant" => {
                let l = self
                    .spectrum(&params, "L", Use::Illuminant)?
                    .unwrap_or(Vec3::ONE);
                let scale = self.light_scale(&params, "illuminance", 1.0)?;
                let from = point("from", DVec3::ZERO, self)?;
                let to = point("to", DVec3::Z, self)?;
                let d = m.transform_vector3(to - from).as_vec3();
                if d.length_squared() == 0.0 {
                    return Err(self.error("distant: from and to are the same point"));
                }
                self.desc.directional_lights.push(DirectionalLightDesc {
                    direction: d.normalize(),
                    irradiance: l * scale,
                });
            }
            "infinite" => {
                if let Some(file) = self.string(&params, "filename")? {
                    if params.has("L") {
                        return Err(
                            self.error("infinite: give either \"L\" or \"filename\", not both")
                        );
                    }
                    if params.has("portal") {
                        params.get("portal");
                        self.warn(
                            "infinite: portals are not supported; the light is sampled without one",
                        );
                    }
                    let scale = self.emission_scale(&params)?;
                    let illuminance = self.float(&params, "illuminance", -1.0)?;
                    let path = self.resolve(&file);
                    match self.image_light(&path, m, scale, illuminance) {
                        Ok(map) => {
                            if self.desc.environment_map.is_some() {
                                self.warn("infinite: a second image light replaces the first");
                            }
                            self.desc.environment_map = Some(map);
                        }
                        Err(e) => self.warn(format!(
                            "infinite: {e}; the scene is rendered without this light"
                        )),
                    }
                } else {
                    let l = self
                        .spectrum(&params, "L", Use::Illuminant)?
                        .unwrap_or(Vec3::ONE);
                    let scale = self.light_scale(&params, "illuminance", std::f64::consts::PI)?;
                    let e = self.desc.environment.unwrap_or(Vec3::ZERO);
                    self.desc.environment = Some(e + l * scale);
                }
            }
            other => {
                for p in &params.params {
                    p.used.set(true);
                }
                self.warn(format!("LightSource \"{other}\": not supported; skipped"));
            }
        }
        self.warn_unused(&format!("LightSource \"{kind}\""), &params);
        Ok(())
    }
}

/// pbrt-v4's equal-area octahedral mapping (Clarberg's) of a unit direction to [0, 1]², the
/// square's y growing down the image.
pub(crate) fn equal_area_sphere_to_square(d: DVec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * 2.0 / std::f64::consts::PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    u = u.copysign(d.x);
    v = v.copysign(d.y);
    Vec2::new((0.5 * (u + 1.0)) as f32, (0.5 * (v + 1.0)) as f32)
}

/// The inverse of [`equal_area_sphere_to_square`].
#[cfg(test)]
pub(crate) fn equal_area_square_to_sphere(p: Vec2) -> DVec3 {
    let (u, v) = (2.0 * p.x as f64 - 1.0, 2.0 * p.y as f64 - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed = 1.0 - (up + vp);
    let d = signed.abs();
    let r = 1.0 - d;
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * std::f64::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed);
    let cos_phi = phi.cos().copysign(u);
    let sin_phi = phi.sin().copysign(v);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    DVec3::new(cos_phi * s, sin_phi * s, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equal_area_mapping_round_trips_and_keeps_area() {
        // Round trip over a grid of the square.
        for i in 0..50 {
            for j in 0..50 {
                let p = Vec2::new((i as f32 + 0.5) / 50.0, (j as f32 + 0.5) / 50.0);
                let d = equal_area_square_to_sphere(p);
                assert!((d.length() - 1.0).abs() < 1e-9, "{d}");
                let q = equal_area_sphere_to_square(d);
                assert!((q - p).length() < 1e-5, "{p} -> {d} -> {q}");
            }
        }
        // Equal area: uniform points of the square give uniform directions, so each octant
        // of the sphere holds an eighth of them and E[z] = 0, E[z²] = 1/3.
        let n = 200;
        let (mut z1, mut z2) = (0.0, 0.0);
        let mut octants = [0usize; 8];
        for i in 0..n {
            for j in 0..n {
                let d = equal_area_square_to_sphere(Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    (j as f32 + 0.5) / n as f32,
                ));
                z1 += d.z;
                z2 += d.z * d.z;
                octants
                    [(d.x > 0.0) as usize + 2 * (d.y > 0.0) as usize + 4 * (d.z > 0.0) as usize] +=
                    1;
            }
        }
        let m = (n * n) as f64;
        assert!((z1 / m).abs() < 1e-3 && (z2 / m - 1.0 / 3.0).abs() < 1e-3);
        // Each octant is a triangle of the square: the grid's points fill each to within the
        // points on its edges.
        let eighth = (n * n / 8) as f64;
        assert!(
            octants
                .iter()
                .all(|&o| (o as f64 - eighth).abs() < 2.0 * n as f64),
            "{octants:?}"
        );
    }
}
