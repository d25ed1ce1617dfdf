//! Reading image textures for diffuse albedo.

use crate::Error;
use pathlab_render::desc::Texture;
use pathlab_render::image_io::{read_rgb, ImageError};
use std::path::Path;
use std::sync::Arc;

/// Reads an image's RGB (see [`read_rgb`]), with failures as the loaders' I/O error naming
/// the file once.
pub(crate) fn read_image(
    path: &Path,
    decode_srgb: bool,
) -> Result<(u32, u32, Vec<pathlab_render::desc::Rgb>), Error> {
    read_rgb(path, decode_srgb).map_err(|e| Error::Io {
        path: path.display().to_string(),
        message: match e {
            ImageError::Exr { message, .. } | ImageError::Decode { message, .. } => message,
            other => other.to_string(),
        },
    })
}

/// Reads a colour texture: EXR/HDR are linear; PNG/JPEG are decoded from sRGB unless `raw`.
pub fn load(path: &Path, raw: bool) -> Result<Arc<Texture>, Error> {
    let (w, h, texels) = read_image(path, !raw)?;
    Texture::new(path.display().to_string(), w as usize, h as usize, texels)
        .map(Arc::new)
        .ok_or_else(|| Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: "the image is empty".into(),
        })
}
