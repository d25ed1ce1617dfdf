//! pbrt-v4's scene-wide options (camera, film, sampler, pixel filter, integrator) and its
//! lights.

use super::materials::Use;
use super::params::ParamList;
use super::Builder;
use crate::Error;
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use pathlab_render::desc::*;
use pathlab_render::mc::sampler::SamplerKind;

/// What comes before `WorldBegin`.
#[derive(Default)]
pub(crate) struct Options {
    /// The camera's type, parameters and camera-from-world transform.
    camera: Option<(String, ParamList, DMat4, usize)>,
    /// The film's parameters.
    film: Option<(String, ParamList, usize)>,
}

impl Options {
    /// pbrt's world to pathlab's: mirrored in x when the camera's transform keeps
    /// orientation (pbrt's camera space is left-handed), else the identity.
    pub(crate) fn world_fix(&self) -> DMat4 {
        let camera_from_world = self
            .camera
            .as_ref()
            .map_or(DMat4::IDENTITY, |(_, _, m, _)| *m);
        if camera_from_world.inverse().determinant() > 0.0 {
            DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))
        } else {
            DMat4::IDENTITY
        }
    }
}

impl Builder {
    /// `Camera`, `Film`, `Sampler`, `PixelFilter`, `Integrator`, `Accelerator`.
    pub(crate) fn options_directive(
        &mut self,
        directive: &str,
        kind: String,
        params: ParamList,
        ctm: DMat4,
    ) -> Result<(), Error> {
        match directive {
            "Camera" => {
                if ctm.determinant().abs() < 1e-12 {
                    return Err(self.error("Camera: its transform is singular"));
                }
                self.options.camera = Some((kind, params, ctm, self.line));
            }
            "Film" => self.options.film = Some((kind, params, self.line)),
            "Sampler" => {
                let n = self.float(&params, "pixelsamples", 16.0)?;
                if !(1.0..=u32::MAX as f64).contains(&n) {
                    return Err(self.error(format!(
                        "Sampler: pixelsamples {n} must be a positive count"
                    )));
                }
                self.desc.hints.spp = Some(n as u32);
                self.desc.hints.sampler = Some(match kind.as_str() {
                    "independent" => SamplerKind::Independent,
                    "stratified" => SamplerKind::Stratified,
                    _ => SamplerKind::Sobol,
                });
                for p in ["seed", "randomization", "jitter", "xsamples", "ysamples"] {
                    params.get(p);
                }
                self.warn_unused(&format!("Sampler \"{kind}\""), &params);
            }
            "PixelFilter" => {
                let filter = match kind.as_str() {
                    "box" => {
                        let r = self.float(&params, "xradius", 0.5)?;
                        self.float(&params, "yradius", r)?;
                        if (r - 0.5).abs() > 1e-6 {
                            self.warn(format!(
                                "PixelFilter \"box\": radius {r} is read as 0.5 (the pixel)"
                            ));
                        }
                        PixelFilter::Box
                    }
                    "triangle" => {
                        let r = self.float(&params, "xradius", 2.0)?;
                        let ry = self.float(&params, "yradius", r)?;
                        if (r - ry).abs() > 1e-6 {
                            self.warn("PixelFilter \"triangle\": different x and y radii; the x radius is used");
                        }
                        PixelFilter::Tent { radius: r as f32 }
                    }
                    "gaussian" => {
                        let sigma = self.float(&params, "sigma", 0.5)?;
                        self.float(&params, "xradius", 1.5)?;
                        self.float(&params, "yradius", 1.5)?;
                        PixelFilter::Gaussian {
                            stddev: sigma as f32,
                        }
                    }
                    other => {
                        self.warn(format!("PixelFilter \"{other}\": not supported; pbrt-v4's default Gaussian (σ = 0.5) is used"));
                        for p in &params.params {
                            p.used.set(true);
                        }
                        PixelFilter::Gaussian { stddev: 0.5 }
                    }
                };
                self.desc.filter = filter;
                self.warn_unused(&format!("PixelFilter \"{kind}\""), &params);
            }
            "Integrator" => {
                let depth = self.float(&params, "maxdepth", 5.0)?;
                if depth < 0.0 {
                    return Err(self.error(format!("Integrator: maxdepth {depth} must be >= 0")));
                }
                // pbrt counts bounces as pathlab does: 0 is emission seen directly, 1 direct
                // lighting.
                self.desc.hints.max_depth = Some(depth.min(u32::MAX as f64 - 1.0) as u32);
                self.desc.hints.integrator = Some(IntegratorHint::Path);
                match kind.as_str() {
                    "path" | "volpath" => {}
                    "bdpt" | "mlt" | "sppm" | "lightpath" | "simplepath" | "simplevolpath"
                    | "randomwalk" => {
                        self.warn(format!("Integrator \"{kind}\": rendered by the path tracer, which converges to the same image"));
                    }
                    other => self.warn(format!(
                        "Integrator \"{other}\": not supported; the path tracer renders the scene"
                    )),
                }
                for p in [
                    "regularize",
                    "lightsampler",
                    "samplelights",
                    "samplebsdf",
                    "visualizestrategies",
                    "visualizeweights",
                    "photonsperiteration",
                    "radius",
                    "iterations",
                    "bootstrapsamples",
                    "chains",
                    "mutationsperpixel",
                    "largestepprobability",
                    "sigma",
                ] {
                    params.get(p);
                }
                self.warn_unused(&format!("Integrator \"{kind}\""), &params);
            }
            _ => {
                // Accelerator: pathlab builds its own BVH.
                for p in &params.params {
                    p.used.set(true);
                }
            }
        }
        Ok(())
    }

    /// The camera and film, once the whole file is read.
    pub(crate) fn finish_options(&mut self) -> Result<(), Error> {
        let (mut w, mut h) = (1280u32, 720u32);
        if let Some((kind, params, line)) = self.options.film.take() {
            self.line = line;
            let xr = self.float(&params, "xresolution", 1280.0)?;
            let yr = self.float(&params, "yresolution", 720.0)?;
            if !(1.0..=16384.0).contains(&xr) || !(1.0..=16384.0).contains(&yr) {
                return Err(self.error(format!(
                    "Film: resolution {xr} x {yr} must be between 1 and 16384"
                )));
            }
            (w, h) = (xr as u32, yr as u32);
            for p in ["filename", "savefp16", "maxcomponentvalue"] {
                params.get(p);
            }
            if params.has("cropwindow") || params.has("pixelbounds") {
                params.get("cropwindow");
                params.get("pixelbounds");
                self.warn("Film: cropwindow and pixelbounds are not supported; the whole image is rendered (use --crop)");
            }
            if kind != "rgb" {
                self.warn(format!("Film \"{kind}\": rendered as an RGB film"));
            }
            self.warn_unused(&format!("Film \"{kind}\""), &params);
        }
        self.desc.resolution = [w, h];
        let aspect = w as f32 / h as f32;
        let (kind, params, camera_from_world, line) = self.options.camera.take().unwrap_or((
            "perspective".into(),
            ParamList::default(),
            DMat4::IDENTITY,
            0,
        ));
        self.line = line;
        let world_from_camera = self.world_fix * camera_from_world.inverse();
        let origin = world_from_camera.transform_point3(DVec3::ZERO).as_vec3();
        let dir = world_from_camera
            .transform_vector3(DVec3::Z)
            .as_vec3()
            .normalize();
        let up = world_from_camera
            .transform_vector3(DVec3::Y)
            .as_vec3()
            .normalize();
        let mut camera = CameraDesc {
            origin,
            target: origin + dir,
            up,
            fov_axis: FovAxis::Smaller,
            ..Default::default()
        };
        match kind.as_str() {
            "perspective" | "orthographic" => {}
            other => self.warn(format!(
                "Camera \"{other}\": not supported; a perspective camera is used"
            )),
        }
        if kind == "orthographic" {
            let half = if aspect > 1.0 {
                Vec2::new(aspect, 1.0)
            } else {
                Vec2::new(1.0, 1.0 / aspect)
            };
            camera.projection = Projection::Orthographic { half_extent: half };
        } else {
            let fov = self.float(&params, "fov", 90.0)?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(self.error(format!(
                    "Camera: fov {fov} must be between 0 and 180 degrees"
                )));
            }
            camera.fov_degrees = fov as f32;
        }
        camera.lens_radius = self.float(&params, "lensradius", 0.0)? as f32;
        camera.focal_distance = self.float(&params, "focaldistance", 1e6)? as f32;
        if camera.lens_radius < 0.0 || camera.focal_distance <= 0.0 {
            return Err(self.error("Camera: lensradius must be >= 0 and focaldistance > 0"));
        }
        for p in ["shutteropen", "shutterclose"] {
            params.get(p);
        }
        if params.has("screenwindow") || params.has("frameaspectratio") {
            params.get("screenwindow");
            params.get("frameaspectratio");
            self.warn("Camera: screenwindow and frameaspectratio are not supported; the film's aspect is used");
        }
        self.warn_unused(&format!("Camera \"{kind}\""), &params);
        self.desc.camera = camera;
        Ok(())
    }

    /// The current transform into pathlab's world.
    pub(crate) fn to_world(&self) -> DMat4 {
        self.world_fix * self.gs.ctm
    }

    /// A light's `scale`, times what `power`-like parameters ask for (`per_unit`: the
    /// factor from the spectrum's unit to the requested quantity).
    fn light_scale(&mut self, params: &ParamList, power_name: &str, k: f64) -> Result<f32, Error> {
        let mut scale = self.float(params, "scale", 1.0)?;
        let power = self.float(params, power_name, -1.0)?;
        if power > 0.0 {
            scale *= power / k;
        }
        Ok(scale as f32)
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
                self.warn("spot: pbrt-v4's smoothstep falloff over the cone's last conedelta degrees is approximated by a linear falloff in angle");
                self.desc.projectors.push(ProjectorDesc {
                    position: m.transform_point3(from).as_vec3(),
                    frame: Mat3::from_cols(x, y, z),
                    texture: TextureDesc::value(1.0),
                    kind: ProjectorKind::Spot {
                        intensity: i * scale,
                        cutoff: cone.to_radians() as f32,
                        beam_width: (cone - delta).max(0.0).to_radians() as f32,
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
                    self.float(&params, "scale", 1.0)?;
                    params.get("illuminance");
                    params.get("portal");
                    self.warn(format!(
                        "infinite light \"{file}\": image-based lights (pbrt-v4's equal-area octahedral maps) are not supported yet; the scene is rendered without it"
                    ));
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
