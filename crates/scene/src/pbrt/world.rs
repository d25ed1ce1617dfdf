//! pbrt-v4's scene-wide options (camera, film, sampler, pixel filter, integrator) and its
//! lights.

use super::params::ParamList;
use super::spectra::Use;
use super::Builder;
use crate::Error;
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use pathlab_render::desc::*;
use pathlab_render::mc::sampler::SamplerKind;

/// pbrt-v4's pixel filter where a file names none: a Gaussian of σ = 0.5 pixels and radius 1.5.
pub(crate) const PBRT_DEFAULT_FILTER: PixelFilter = PixelFilter::Gaussian {
    stddev: 0.5,
    radius: 1.5,
};

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
                self.desc.filter = self.pixel_filter(&kind, &params)?;
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

    /// The part of the image `Film` asks to render: `pixelbounds` (pixels x0 x1 y0 y1) or
    /// `cropwindow` (fractions x0 x1 y0 y1, each edge at the first pixel at or past it), as
    /// pbrt-v4 reads them (`pixelbounds` first), cut to the image of size `of`.
    fn crop_hint(&mut self, params: &ParamList, of: [u32; 2]) -> Result<Option<CropHint>, Error> {
        let bounds = self.param_numbers(params, "pixelbounds")?;
        let fractions = self.param_numbers(params, "cropwindow")?;
        let [w, h] = of.map(f64::from);
        let four = |v: &[f64], what: &str| {
            if v.len() == 4 && v.iter().all(|x| x.is_finite()) {
                Ok([v[0], v[1], v[2], v[3]])
            } else {
                Err(self.error(format!("Film: {what} takes four numbers x0 x1 y0 y1")))
            }
        };
        let [x0, x1, y0, y1] = match (bounds, fractions) {
            (Some(b), f) => {
                let b = four(b, "pixelbounds")?;
                if f.is_some() {
                    self.warn("Film: both pixelbounds and cropwindow are given; pixelbounds is used, as in pbrt-v4");
                }
                b
            }
            (None, Some(f)) => {
                let [a, b, c, d] = four(f, "cropwindow")?;
                let unit = |v: f64| v.clamp(0.0, 1.0);
                [
                    (w * unit(a.min(b))).ceil(),
                    (w * unit(a.max(b))).ceil(),
                    (h * unit(c.min(d))).ceil(),
                    (h * unit(c.max(d))).ceil(),
                ]
            }
            (None, None) => return Ok(None),
        };
        let window = [
            x0.clamp(0.0, w) as u32,
            y0.clamp(0.0, h) as u32,
            x1.clamp(0.0, w) as u32,
            y1.clamp(0.0, h) as u32,
        ];
        if window[0] >= window[2] || window[1] >= window[3] {
            self.warn(
                "Film: the crop window holds no pixel of the image; the whole image is rendered",
            );
            return Ok(None);
        }
        Ok(Some(CropHint { window, of }))
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
            for p in ["filename", "savefp16"] {
                params.get(p);
            }
            let clamp = self.float(&params, "maxcomponentvalue", f64::INFINITY)?;
            if clamp.is_finite() {
                self.warn(format!("Film: maxcomponentvalue {clamp} (a clamp of each sample) is not supported; samples are not clamped"));
            }
            self.desc.hints.crop = self.crop_hint(&params, [w, h])?;
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
        self.screen_window(&params, &mut camera, aspect)?;
        self.warn_unused(&format!("Camera \"{kind}\""), &params);
        self.desc.camera = camera;
        Ok(())
    }

    /// pbrt-v4's `PixelFilter`: box, triangle, gaussian, mitchell and sinc with their radii
    /// and parameters; others are warned about and pbrt-v4's default Gaussian is used.
    fn pixel_filter(&mut self, kind: &str, params: &ParamList) -> Result<PixelFilter, Error> {
        Ok(match kind {
            "box" => {
                let r = self.float(params, "xradius", 0.5)?;
                self.float(params, "yradius", r)?;
                if (r - 0.5).abs() > 1e-6 {
                    self.warn(format!(
                        "PixelFilter \"box\": radius {r} is read as 0.5 (the pixel)"
                    ));
                }
                PixelFilter::Box
            }
            "triangle" => PixelFilter::Tent {
                radius: self.filter_radius(params, kind, 2.0)?,
            },
            "gaussian" => {
                let sigma = self.float(params, "sigma", 0.5)?;
                PixelFilter::Gaussian {
                    stddev: sigma as f32,
                    radius: self.filter_radius(params, kind, 1.5)?,
                }
            }
            "mitchell" => {
                let r = self.filter_radius(params, kind, 2.0)?;
                let b = self.float(params, "B", 1.0 / 3.0)? as f32;
                let c = self.float(params, "C", 1.0 / 3.0)? as f32;
                PixelFilter::Mitchell { radius: r, b, c }
            }
            "sinc" => {
                let r = self.filter_radius(params, kind, 4.0)?;
                let tau = self.float(params, "tau", 3.0)? as f32;
                PixelFilter::LanczosSinc { radius: r, tau }
            }
            other => {
                self.warn(format!("PixelFilter \"{other}\": not supported; pbrt-v4's default Gaussian (σ = 0.5, radius 1.5) is used"));
                for p in &params.params {
                    p.used.set(true);
                }
                PBRT_DEFAULT_FILTER
            }
        })
    }

    /// A filter's `xradius` (`default` without one); a different `yradius` is warned about,
    /// the filters being one radius in both axes here. A radius must be positive.
    fn filter_radius(
        &mut self,
        params: &ParamList,
        kind: &str,
        default: f64,
    ) -> Result<f32, Error> {
        let r = self.float(params, "xradius", default)?;
        let ry = self.float(params, "yradius", r)?;
        if !(r > 0.0 && r.is_finite()) {
            return Err(self.error(format!(
                "PixelFilter \"{kind}\": radius {r} must be positive"
            )));
        }
        if (r - ry).abs() > 1e-6 {
            self.warn(format!(
                "PixelFilter \"{kind}\": different x and y radii; the x radius is used"
            ));
        }
        Ok(r as f32)
    }

    /// pbrt-v4's `screenwindow` [x0 x1 y0 y1] (and `frameaspectratio`, which sets the default
    /// window [-a, a, -1, 1] or [-1, 1, -1/a, 1/a]): the part of the screen the film shows,
    /// in units of tan(fov / 2) on the screen's shorter axis (of world units for an
    /// orthographic camera), as a vertical field of view and a shift of the image's centre.
    /// A window whose shape differs from the film's would need non-square pixels: warned, the
    /// window's height kept.
    fn screen_window(
        &mut self,
        params: &ParamList,
        camera: &mut CameraDesc,
        aspect: f32,
    ) -> Result<(), Error> {
        let frame = self.float(params, "frameaspectratio", aspect as f64)? as f32;
        if !(frame > 0.0 && frame.is_finite()) {
            return Err(self.error(format!(
                "Camera: frameaspectratio {frame} must be a positive number"
            )));
        }
        let window = match params.get("screenwindow") {
            None if (frame - aspect).abs() <= 1e-4 * aspect => return Ok(()),
            None if frame > 1.0 => [-frame, frame, -1.0, 1.0],
            None => [-1.0, 1.0, -1.0 / frame, 1.0 / frame],
            Some(p) => match p.numbers() {
                Some(&[x0, x1, y0, y1]) if x0 < x1 && y0 < y1 => {
                    [x0 as f32, x1 as f32, y0 as f32, y1 as f32]
                }
                _ => {
                    return Err(self.error(format!(
                        "\"{} screenwindow\" (line {}): expected four numbers x0 x1 y0 y1 with x0 < x1 and y0 < y1",
                        p.ty, p.line
                    )))
                }
            },
        };
        let [x0, x1, y0, y1] = window;
        let (hx, hy) = (0.5 * (x1 - x0), 0.5 * (y1 - y0));
        if (hx / hy - aspect).abs() > 1e-3 * aspect {
            self.warn(format!(
                "Camera: a screen window of aspect {:.4} on a film of aspect {aspect:.4} needs non-square pixels; the window's height is kept",
                hx / hy
            ));
        }
        camera.principal_point_offset =
            Vec2::new(0.5 * (x0 + x1) / (2.0 * hx), -0.5 * (y0 + y1) / (2.0 * hy));
        match &mut camera.projection {
            Projection::Orthographic { half_extent } => {
                *half_extent = Vec2::new(hy * aspect, hy);
            }
            Projection::Perspective => {
                // The screen's unit is tan(fov / 2) on the shorter axis.
                let unit = (0.5 * camera.fov_degrees.to_radians()).tan();
                camera.fov_degrees = 2.0 * (hy * unit).atan().to_degrees();
                camera.fov_axis = FovAxis::Y;
            }
        }
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
                    let scale = self.float(&params, "scale", 1.0)? as f32;
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
