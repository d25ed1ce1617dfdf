//! From flags to what the renderer gets: the scene description with the flags' changes, the
//! integrator and the render settings.

use super::args::{Checked, FresnelName, LightingName, RenderArgs, RuleName};
use anyhow::{bail, Result};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::desc::{FovAxis, FresnelModel, MaterialDesc, Projection, SceneDesc};
use pathlab_render::integrator::{IntegratorChoice, IntegratorKind, PathLighting};
use pathlab_render::render::{AdaptiveRule, RenderSettings};
use pathlab_render::scene::Scene;
use std::sync::atomic::AtomicBool;

/// The scene `args` names, with `-D` parameters, and the camera, environment and Fresnel
/// flags applied (its warnings printed unless `-q`); resolution and view are applied by the
/// caller once the scene's hints are read.
pub(super) fn scene_desc(args: &RenderArgs, params: &[(String, String)]) -> Result<SceneDesc> {
    let mut desc = pathlab_scene::load_with(&args.scene, params)?;
    if !args.quiet {
        for w in &desc.warnings {
            eprintln!("warning: {w}");
        }
    }
    if let Some(b) = args.lens_radius {
        if !(b.is_finite() && b >= 0.0) {
            bail!("--lens-radius {b}: must be a finite number >= 0");
        }
        desc.camera.lens_radius = b;
    }
    if let Some(d) = args.focal_distance {
        if !(d.is_finite() && d > 0.0) {
            bail!("--focal-distance {d}: must be a positive distance");
        }
        desc.camera.focal_distance = d;
    }
    if let Some(file) = &args.envmap {
        if !(args.envmap_scale.is_finite() && args.envmap_scale >= 0.0) {
            bail!(
                "--envmap-scale {}: must be a number >= 0",
                args.envmap_scale
            );
        }
        desc.environment_map = Some(pathlab_scene::envmap::load(
            file,
            glam::Mat3::IDENTITY,
            args.envmap_scale,
        )?);
        desc.environment = None;
    }
    if args.fresnel == FresnelName::Schlick {
        for m in &mut desc.materials {
            if let MaterialDesc::Glass { fresnel, .. } = m {
                *fresnel = FresnelModel::Schlick;
            }
        }
    }
    Ok(desc)
}

/// The integrator the flags ask for; the scene's hints fill what they leave open
/// ([`IntegratorChoice::integrator`]).
pub(super) fn integrator_choice(args: &RenderArgs, checked: &Checked) -> IntegratorChoice {
    IntegratorChoice {
        name: args.integrator,
        max_depth: checked.cli_depth,
        rr_depth: args.rr_depth,
        only_bounce: args.only_bounce,
        light_samples: args.light_samples,
        lighting: match args.lighting.unwrap_or(LightingName::Mis) {
            LightingName::Mis => PathLighting::Mis,
            LightingName::Bsdf => PathLighting::Bsdf,
            LightingName::Light => PathLighting::Light,
        },
        direct: args.direct,
    }
}

/// The render settings: samples, seed, sampler (the scene's or the mode's default), adaptive
/// rule (the Neyman rule's pilot is rendered here), crop and shard.
pub(super) fn settings(
    args: &RenderArgs,
    checked: &Checked,
    desc: &SceneDesc,
    scene: &Scene,
    integrator: &IntegratorKind,
    spp: u32,
    cancel: &AtomicBool,
) -> Result<RenderSettings> {
    let sampler = args
        .sampler
        .or(desc.hints.sampler)
        .unwrap_or(if checked.progressive {
            SamplerKind::Independent
        } else {
            SamplerKind::Sobol
        });
    let mut settings = RenderSettings::new(spp, args.seed, sampler);
    settings.adaptive = checked.adaptive;
    if let Some(c) = &args.crop {
        let [w, h] = desc.resolution;
        if c[0] >= c[2] || c[1] >= c[3] || c[2] > w || c[3] > h {
            bail!(
                "--crop {} {} {} {}: need x0 < x1 <= {w} and y0 < y1 <= {h}",
                c[0],
                c[1],
                c[2],
                c[3]
            );
        }
        settings.crop = Some([c[0], c[1], c[2], c[3]]);
    }
    if args.adaptive_rule == Some(RuleName::Neyman) {
        if let Some(a) = settings.adaptive.as_mut() {
            let seed = args.seed.wrapping_add(1);
            let (rule, _) =
                AdaptiveRule::neyman_from_pilot(scene, integrator, seed, sampler, cancel);
            if let Some(rule) = rule {
                a.rule = rule;
            }
        }
    }
    if let Some(shard) = &args.shard {
        settings.sample_range = Some(crate::farm::shard_range(shard, spp)?);
    }
    Ok(settings)
}

/// Applies a `-r W H` override to a scene, checking the size.
pub fn apply_resolution(desc: &mut SceneDesc, resolution: Option<&[u32]>) -> Result<()> {
    if let Some(&[w, h]) = resolution {
        if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
            bail!("--resolution {w} {h}: width and height must be between 1 and 16384");
        }
        desc.resolution = [w, h];
    }
    Ok(())
}

/// Applies `--scale F` (the scene's view at F times its resolution) and `--fov DEG`.
pub fn apply_view(desc: &mut SceneDesc, scale: Option<f32>, fov: Option<f32>) -> Result<()> {
    if let Some(f) = scale {
        if !(f.is_finite() && f > 0.0) {
            bail!("--scale {f}: must be a positive factor such as 0.5 or 2");
        }
        let [w, h] = desc.resolution;
        let size = |n: u32| (n as f64 * f as f64).round();
        let (sw, sh) = (size(w), size(h));
        if !(1.0..=16384.0).contains(&sw) || !(1.0..=16384.0).contains(&sh) {
            bail!("--scale {f}: {w}x{h} would become {sw}x{sh}; width and height must be between 1 and 16384");
        }
        desc.resolution = [sw as u32, sh as u32];
        // A camera whose field of view follows from its resolution keeps its view.
        if let Some(p) = desc.camera.focal_pixels.as_mut() {
            *p *= sw as f32 / w as f32;
        }
    }
    if let Some(deg) = fov {
        if !(deg.is_finite() && deg > 0.0 && deg < 180.0) {
            bail!("--fov {deg}: must be an angle between 0 and 180 degrees");
        }
        if !matches!(desc.camera.projection, Projection::Perspective) {
            bail!("--fov {deg}: the scene's camera is orthographic, which has no field of view");
        }
        desc.camera.fov_degrees = deg;
        desc.camera.fov_axis = FovAxis::Smaller;
        desc.camera.focal_pixels = None;
    }
    Ok(())
}
