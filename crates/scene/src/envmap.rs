//! Reading environment maps (equirectangular OpenEXR, Radiance HDR, or 8-bit sRGB images).

use crate::Error;
use glam::Mat3;
use pathlab_render::desc::EnvironmentMapDesc;
use std::path::Path;
use std::sync::Arc;

/// Reads the image at `path` as an environment map rotated by `to_world` and scaled by
/// `scale`.
pub fn load(path: &Path, to_world: Mat3, scale: f32) -> Result<EnvironmentMapDesc, Error> {
    // 8-bit images are sRGB-encoded: decode them to linear radiance.
    let (w, h, texels) = crate::texture::read_image(path, true)?;
    if w < 2 || h < 3 {
        return Err(Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: format!("an environment map needs at least 2 x 3 pixels, found {w} x {h}"),
        });
    }
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: format!("the scale must be a non-negative number, got {scale}"),
        });
    }
    Ok(EnvironmentMapDesc {
        source: path.display().to_string(),
        width: w as usize,
        height: h as usize,
        texels: Arc::new(texels),
        to_world,
        scale,
    })
}
