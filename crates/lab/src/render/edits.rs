//! Changes a caller makes to a scene as its file describes it: another resolution, a scaled
//! view or another field of view, a thin lens, an environment map, Schlick's Fresnel on glass.
//!
//! Values that need no scene to be judged (a negative lens radius, a field of view of 200°)
//! are refused before loading by [`super::RenderRequest::check`]; what depends on
//! the scene (an orthographic camera has no field of view; a scale that makes the image too
//! large) is refused here.

use anyhow::{bail, Result};
use pathlab_render::desc::{FovAxis, FresnelModel, MaterialDesc, Projection, SceneDesc};
use pathlab_render::limits::{self, MAX_IMAGE_SIDE};
use std::path::PathBuf;

/// What changes in the scene before it is built.
#[derive(Clone, Debug, Default)]
pub struct SceneEdits {
    /// The thin lens's radius (0: a pinhole).
    pub lens_radius: Option<f32>,
    /// The distance in focus.
    pub focal_distance: Option<f32>,
    /// An environment map (lat-long image) and its scale, replacing the scene's environment.
    pub envmap: Option<(PathBuf, f32)>,
    /// Glass takes Schlick's approximation of the Fresnel reflectance.
    pub schlick_fresnel: bool,
    /// Another image size: the same camera sees more or less of the scene.
    pub resolution: Option<[u32; 2]>,
    /// The scene's view at this factor of its (or the new) resolution.
    pub scale: Option<f32>,
    /// A field of view in degrees, on the image's shorter axis.
    pub fov: Option<f32>,
}

impl SceneEdits {
    /// Applies every change to `desc`.
    pub fn apply(&self, desc: &mut SceneDesc) -> Result<()> {
        if let Some(b) = self.lens_radius {
            desc.camera.lens_radius = b;
        }
        if let Some(d) = self.focal_distance {
            desc.camera.focal_distance = d;
        }
        if let Some((file, scale)) = &self.envmap {
            desc.environment_map = Some(pathlab_scene::envmap::load(
                file,
                glam::Mat3::IDENTITY,
                *scale,
            )?);
            desc.environment = None;
        }
        if self.schlick_fresnel {
            for m in &mut desc.materials {
                if let MaterialDesc::Glass { fresnel, .. } = m {
                    *fresnel = FresnelModel::Schlick;
                }
            }
        }
        apply_resolution(desc, self.resolution)?;
        apply_view(desc, self.scale, self.fov)
    }
}

/// Gives the scene another image size, checked.
pub fn apply_resolution(desc: &mut SceneDesc, resolution: Option<[u32; 2]>) -> Result<()> {
    if let Some([w, h]) = resolution {
        desc.resolution =
            limits::resolution([w, h]).map_err(|e| anyhow::anyhow!("--resolution {w} {h}: {e}"))?;
    }
    Ok(())
}

/// The scene's view at `scale` times its resolution, and a field of view of `fov` degrees.
pub fn apply_view(desc: &mut SceneDesc, scale: Option<f32>, fov: Option<f32>) -> Result<()> {
    if let Some(f) = scale {
        let [w, h] = desc.resolution;
        let size = |n: u32| (n as f64 * f as f64).round();
        let (sw, sh) = (size(w), size(h));
        let side = 1.0..=MAX_IMAGE_SIDE as f64;
        if !side.contains(&sw) || !side.contains(&sh) {
            bail!("--scale {f}: {w}x{h} would become {sw}x{sh}; width and height must be between 1 and {MAX_IMAGE_SIDE}");
        }
        desc.resolution = [sw as u32, sh as u32];
        // A camera whose field of view follows from its resolution keeps its view.
        if let Some(p) = desc.camera.focal_pixels.as_mut() {
            *p *= sw as f32 / w as f32;
        }
    }
    if let Some(deg) = fov {
        if !matches!(desc.camera.projection, Projection::Perspective) {
            bail!("--fov {deg}: the scene's camera is orthographic, which has no field of view");
        }
        desc.camera.fov_degrees = deg;
        desc.camera.fov_axis = FovAxis::Smaller;
        desc.camera.focal_pixels = None;
    }
    Ok(())
}
