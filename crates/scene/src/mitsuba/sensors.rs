//! Mitsuba sensors (`perspective`, `thinlens`, `orthographic`), their film (`hdrfilm` and its
//! `rfilter`) and sampler, and the integrator.

use super::{Ctx, Obj};
use crate::{sampler_note, Error, SamplerName};
use glam::{DVec3, Vec2};
use pathlab_render::desc::*;
use pathlab_render::mc::sampler::SamplerKind;

/// The horizontal field of view in degrees of a sensor or projector with image aspect
/// `aspect` (width / height): `fov` along `fov_axis` (default x), or a 35 mm `focal_length`
/// (default 50 mm, measured on the film diagonal), as Mitsuba's `parse_fov`.
pub(super) fn fov_x(ctx: &Ctx, o: Obj, aspect: f64) -> Result<f64, Error> {
    let (fov, axis) = match ctx.opt_float(o, "fov")? {
        Some(fov) => {
            if ctx.has(o, "focal_length") {
                return Err(ctx.error(
                    o.loc,
                    format!(
                        "{}: give either 'fov' or 'focal_length', not both",
                        ctx.what(o)
                    ),
                ));
            }
            if !(fov > 0.0 && fov < 180.0) {
                return Err(ctx.error(
                    ctx.loc_of(o, "fov"),
                    format!(
                        "{}: fov {fov} must be between 0 and 180 degrees",
                        ctx.what(o)
                    ),
                ));
            }
            let axis = ctx.choice(o, "fov_axis", &["x", "y", "diagonal", "smaller", "larger"])?;
            let axis = match axis {
                "smaller" if aspect > 1.0 => "y",
                "smaller" => "x",
                "larger" if aspect > 1.0 => "x",
                "larger" => "y",
                a => a,
            };
            (fov, axis)
        }
        None => {
            let text = ctx
                .string(o, "focal_length")?
                .unwrap_or_else(|| "50mm".into());
            let mm = text
                .trim()
                .trim_end_matches("mm")
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|f| *f > 0.0)
                .ok_or_else(|| {
                    ctx.error(
                        ctx.loc_of(o, "focal_length"),
                        format!(
                            "{}: focal_length '{text}' is not a length such as 50mm",
                            ctx.what(o)
                        ),
                    )
                })?;
            let diagonal = (36.0f64 * 36.0 + 24.0 * 24.0).sqrt();
            (
                2.0 * (diagonal / (2.0 * mm)).atan().to_degrees(),
                "diagonal",
            )
        }
    };
    let half = (0.5 * fov).to_radians().tan();
    let x = match axis {
        "y" => half * aspect,
        "diagonal" => half / (1.0 + 1.0 / (aspect * aspect)).sqrt(),
        _ => half,
    };
    Ok(2.0 * x.atan().to_degrees())
}

/// The sensor `s`: camera, image size, pixel filter and sample count.
pub(super) fn sensor(ctx: &mut Ctx, s: Obj) -> Result<(), Error> {
    // Film first: the field of view depends on the image's aspect.
    let films = ctx.children(s, "film")?;
    if let Some((_, film)) = films.first() {
        film_settings(ctx, *film)?;
    }
    for (_, sampler) in ctx.children(s, "sampler")? {
        if let Some(n) = ctx.opt_float(sampler, "sample_count")? {
            if !(n >= 1.0 && n <= u32::MAX as f64) {
                return Err(ctx.error(
                    ctx.loc_of(sampler, "sample_count"),
                    format!("sample_count {n} must be a positive count"),
                ));
            }
            ctx.desc.hints.spp = Some(n as u32);
        }
        // `ldsampler` (a (0, 2)-sequence) is what `pathlab export` writes for Sobol.
        let (kind, name) = match sampler.plugin {
            "independent" => (SamplerKind::Independent, SamplerName::Own),
            "stratified" => (SamplerKind::Stratified, SamplerName::Own),
            "ldsampler" => (SamplerKind::Sobol, SamplerName::Own),
            "multijitter" => (SamplerKind::Stratified, SamplerName::StandIn),
            "orthogonal" => (SamplerKind::Sobol, SamplerName::StandIn),
            _ => (SamplerKind::Sobol, SamplerName::Unknown),
        };
        if let Some(note) = sampler_note(kind, name, "Mitsuba 3") {
            let what = ctx.what(sampler);
            ctx.warn(sampler.loc, format!("{what}: {note}"));
        }
        ctx.desc.hints.sampler = Some(kind);
        // Seeds and jitter settings give other noise, not another image.
        ctx.accept(sampler, &["seed", "jitter", "scramble", "dimension"]);
    }
    let [w, h] = ctx.desc.resolution;
    let aspect = w as f64 / h as f64;
    let m = ctx.transform(s, "to_world")?;
    let origin = m.transform_point3(DVec3::ZERO);
    let forward = m.transform_vector3(DVec3::Z);
    let up = m.transform_vector3(DVec3::Y);
    let near = ctx.float(s, "near_clip", 0.01)? as f32;
    let far = ctx.float(s, "far_clip", 10000.0)? as f32;
    if !(near >= 0.0 && far > near) {
        return Err(ctx.error(
            s.loc,
            format!(
                "{}: need 0 <= near_clip ({near}) < far_clip ({far})",
                ctx.what(s)
            ),
        ));
    }
    let offset = Vec2::new(
        ctx.float(s, "principal_point_offset_x", 0.0)? as f32,
        ctx.float(s, "principal_point_offset_y", 0.0)? as f32,
    );
    ctx.accept(s, &["shutter_open", "shutter_close", "srf"]);
    let mut camera = CameraDesc {
        origin: origin.as_vec3(),
        target: (origin + forward.normalize_or(DVec3::Z)).as_vec3(),
        up: up.normalize_or(DVec3::Y).as_vec3(),
        fov_degrees: 45.0,
        fov_axis: FovAxis::X,
        lens_radius: 0.0,
        focal_distance: 1.0,
        focal_pixels: None,
        near_clip: near,
        far_clip: far,
        principal_point_offset: offset,
        projection: Projection::Perspective,
    };
    match s.plugin {
        "perspective" | "thinlens" => {
            camera.fov_degrees = fov_x(ctx, s, aspect)? as f32;
            if s.plugin == "thinlens" {
                camera.lens_radius = ctx.float(s, "aperture_radius", 0.0)? as f32;
                camera.focal_distance = ctx.positive(s, "focus_distance", 1.0)? as f32;
                camera.target = (origin
                    + forward.normalize_or(DVec3::Z) * camera.focal_distance as f64)
                    .as_vec3();
            }
        }
        "orthographic" => {
            // Mitsuba's orthographic sensor sees [-1, 1] × [-1/aspect, 1/aspect] of its local
            // xy plane, scaled by to_world.
            let sx = m.transform_vector3(DVec3::X).length() as f32;
            let sy = m.transform_vector3(DVec3::Y).length() as f32;
            camera.projection = Projection::Orthographic {
                half_extent: Vec2::new(sx, sy / aspect as f32),
            };
        }
        other => {
            let what = ctx.what(s);
            ctx.warn(
                s.loc,
                format!("{what} is not supported by pathlab; using a perspective camera"),
            );
            camera.fov_degrees = fov_x(ctx, s, aspect)? as f32;
            let _ = other;
        }
    }
    ctx.desc.camera = camera;
    Ok(())
}

fn film_settings(ctx: &mut Ctx, film: Obj) -> Result<(), Error> {
    if film.plugin != "hdrfilm" {
        let what = ctx.what(film);
        ctx.warn(film.loc, format!("{what} is read as an hdrfilm"));
    }
    let w = ctx.int(film, "width", 768)?;
    let h = ctx.int(film, "height", 576)?;
    if !(1..=65536).contains(&w) || !(1..=65536).contains(&h) {
        return Err(ctx.error(film.loc, format!("film size {w} x {h} is out of range")));
    }
    ctx.desc.resolution = [w as u32, h as u32];
    // The output format is chosen by pathlab's -o; these change nothing in the image.
    ctx.accept(
        film,
        &[
            "pixel_format",
            "component_format",
            "file_format",
            "banner",
            "high_quality_edges",
            "compensate",
        ],
    );
    let keys = [
        "crop_offset_x",
        "crop_offset_y",
        "crop_width",
        "crop_height",
    ];
    if keys.iter().any(|k| ctx.has(film, k)) {
        let x = ctx.int(film, "crop_offset_x", 0)?;
        let y = ctx.int(film, "crop_offset_y", 0)?;
        let cw = ctx.int(film, "crop_width", w)?;
        let ch = ctx.int(film, "crop_height", h)?;
        // As Mitsuba checks them: the window lies inside the film and holds a pixel.
        if x < 0 || y < 0 || cw < 1 || ch < 1 || x + cw > w || y + ch > h {
            return Err(ctx.error(
                film.loc,
                format!("the crop window ({x}, {y}) size {cw} x {ch} does not lie inside the {w} x {h} film"),
            ));
        }
        ctx.desc.hints.crop = Some(CropHint {
            window: [x, y, x + cw, y + ch].map(|v| v as u32),
            of: [w as u32, h as u32],
        });
    }
    if ctx.boolean(film, "sample_border", false)? {
        ctx.warn(
            ctx.loc_of(film, "sample_border"),
            "<film>: sample_border is not supported; ignored",
        );
    }
    let filters = ctx.children(film, "rfilter")?;
    ctx.desc.filter = match filters.first() {
        None => PixelFilter::gaussian(0.5),
        Some((_, f)) => match f.plugin {
            "box" => PixelFilter::Box,
            "tent" => PixelFilter::Tent {
                radius: ctx.positive(*f, "radius", 1.0)? as f32,
            },
            "gaussian" => PixelFilter::gaussian(ctx.positive(*f, "stddev", 0.5)? as f32),
            "mitchell" => PixelFilter::Mitchell {
                radius: 2.0,
                b: ctx.float(*f, "B", 1.0 / 3.0)? as f32,
                c: ctx.float(*f, "C", 1.0 / 3.0)? as f32,
            },
            "catmullrom" => PixelFilter::Mitchell {
                radius: 2.0,
                b: 0.0,
                c: 0.5,
            },
            "lanczos" => {
                let lobes = ctx.positive(*f, "lobes", 3.0)? as f32;
                PixelFilter::LanczosSinc {
                    radius: lobes,
                    tau: lobes,
                }
            }
            _ => {
                let what = ctx.what(*f);
                ctx.warn(
                    f.loc,
                    format!("{what} is not supported by pathlab; using a box filter"),
                );
                PixelFilter::Box
            }
        },
    };
    Ok(())
}

/// The integrator `i` as render hints. `moment` wraps another integrator; `ptracer` (a
/// particle tracer) converges to the same image as the path tracer, which renders it.
pub(super) fn integrator(ctx: &mut Ctx, i: Obj) -> Result<(), Error> {
    let hints = &mut ctx.desc.hints;
    let _ = hints;
    match i.plugin {
        "moment" => {
            for (_, inner) in ctx.children(i, "integrator")? {
                integrator(ctx, inner)?;
            }
            return Ok(());
        }
        "path" | "ptracer" | "volpath" | "volpathmis" => {
            if i.plugin.starts_with("volpath") {
                ctx.warn(
                    i.loc,
                    format!(
                        "<integrator type=\"{}\">: participating media are not supported; rendering surfaces with the path tracer",
                        i.plugin
                    ),
                );
            }
            ctx.desc.hints.integrator = Some(IntegratorHint::Path);
            ctx.accept(i, &["samples_per_pass", "timeout", "samples_per_pass"]);
        }
        "direct" => {
            let shading = ctx.int(i, "shading_samples", 1)?;
            let emitter_samples = ctx.int(i, "emitter_samples", shading)?;
            let bsdf_samples = ctx.int(i, "bsdf_samples", shading)?;
            if emitter_samples < 0 || bsdf_samples < 0 || emitter_samples + bsdf_samples == 0 {
                return Err(ctx.error(
                    i.loc,
                    "<integrator type=\"direct\">: needs at least one emitter or BSDF sample",
                ));
            }
            ctx.desc.hints.integrator = Some(IntegratorHint::Direct {
                emitter_samples: emitter_samples as u32,
                bsdf_samples: bsdf_samples as u32,
            });
        }
        other => {
            let what = ctx.what(i);
            ctx.warn(
                i.loc,
                format!("{what} is not supported by pathlab; rendering with the path tracer"),
            );
            let _ = other;
            ctx.desc.hints.integrator = Some(IntegratorHint::Path);
        }
    }
    if let Some(d) = ctx.opt_float(i, "max_depth")? {
        // Mitsuba counts the camera ray as depth 1; -1 is unbounded.
        ctx.desc.hints.max_depth = Some(if d < 0.0 {
            u32::MAX
        } else {
            (d as u32).max(1) - 1
        });
    }
    if let Some(d) = ctx.opt_float(i, "rr_depth")? {
        ctx.desc.hints.rr_depth = Some((d.max(1.0) as u32) - 1);
    }
    if ctx.boolean(i, "hide_emitters", false)? {
        ctx.desc.hints.hide_emitters = true;
    }
    Ok(())
}
