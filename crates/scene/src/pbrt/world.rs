//! pbrt-v4's scene-wide options: camera, film (size, crop window), sampler, pixel filter,
//! integrator. Lights are [`super::lights`]'s.

use super::params::ParamList;
use super::Builder;
use crate::{sampler_note, Error, SamplerName};
use glam::{DMat4, DVec3, Vec2};
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
                let (sampler, name) = match kind.as_str() {
                    "independent" => (SamplerKind::Independent, SamplerName::Own),
                    "stratified" => (SamplerKind::Stratified, SamplerName::Own),
                    "sobol" => (SamplerKind::Sobol, SamplerName::Own),
                    // pbrt-v4's other low-discrepancy samplers.
                    "zsobol" | "paddedsobol" | "halton" | "pmj02bn" => {
                        (SamplerKind::Sobol, SamplerName::StandIn)
                    }
                    _ => (SamplerKind::Sobol, SamplerName::Unknown),
                };
                if let Some(note) = sampler_note(sampler, name, "pbrt-v4") {
                    self.warn(format!("Sampler \"{kind}\": {note}"));
                }
                self.desc.hints.sampler = Some(sampler);
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
                    "bdpt" => self.desc.hints.integrator = Some(IntegratorHint::Bdpt),
                    "mlt" | "sppm" | "lightpath" | "simplepath" | "simplevolpath"
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
}
