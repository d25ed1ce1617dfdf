//! Comparing images: RMSE and relative MSE, and the check that a reference belongs to the
//! render it is compared with.

use anyhow::{bail, Result};
use glam::Vec3;
use pathlab_render::film::Film;
use pathlab_render::image_io::{read_exr_rgb, read_rgb, write_exr};
use std::path::{Path, PathBuf};

/// The reference image at `path` (a linear EXR), checked to be of `resolution`.
pub fn read_reference(path: &Path, resolution: [u32; 2]) -> Result<Vec<Vec3>> {
    let (rw, rh, pixels) = read_exr_rgb(path)?;
    let [w, h] = resolution;
    if [rw, rh] != resolution {
        bail!(
            "{}: the reference is {rw}x{rh} but the scene renders at {w}x{h}",
            path.display()
        );
    }
    Ok(pixels)
}

/// A largest bounce as the command line writes it: a number, or `inf` for unbounded.
pub fn depth_text(max_depth: u32) -> String {
    match max_depth {
        u32::MAX => "inf".to_string(),
        d => d.to_string(),
    }
}

/// Root mean squared error over pixels and channels.
pub fn rmse(a: &[Vec3], b: &[Vec3]) -> f64 {
    let n = a.len().min(b.len()).max(1) as f64;
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (*p - *q).length_squared() as f64 / 3.0)
        .sum();
    (sum / n).sqrt()
}

/// Relative mean squared error, (a - b)² / (b² + 0.01) averaged over pixels and channels (the
/// 0.01 keeps black pixels of `b` from dominating).
pub fn relative_mse(a: &[Vec3], b: &[Vec3]) -> f64 {
    let n = a.len().min(b.len()).max(1) as f64 * 3.0;
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| {
            (0..3).map(move |c| {
                let d = (p[c] - q[c]) as f64;
                d * d / ((q[c] as f64).powi(2) + 0.01)
            })
        })
        .sum();
    sum / n
}

/// How two images of one size differ: the numbers `pathlab diff` reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDifference {
    /// [`rmse`] of the first against the second.
    pub rmse: f64,
    /// [`relative_mse`] of the first against the second.
    pub relative_mse: f64,
    /// The largest |a - b| of any pixel's channel.
    pub max_abs: f32,
    /// Mean colour of the first image.
    pub mean_a: Vec3,
    /// Mean colour of the second image.
    pub mean_b: Vec3,
}

impl ImageDifference {
    /// The difference of images `a` and `b` (pixels in the same order).
    pub fn of(a: &[Vec3], b: &[Vec3]) -> ImageDifference {
        let mean = |img: &[Vec3]| img.iter().sum::<Vec3>() / img.len().max(1) as f32;
        ImageDifference {
            rmse: rmse(a, b),
            relative_mse: relative_mse(a, b),
            max_abs: a
                .iter()
                .zip(b)
                .map(|(p, q)| (*p - *q).abs().max_element())
                .fold(0.0f32, f32::max),
            mean_a: mean(a),
            mean_b: mean(b),
        }
    }
}

/// The render's RMSE against `reference`.
pub fn film_rmse(film: &Film, reference: &[Vec3]) -> f64 {
    rmse(&film.mean_image(), reference)
}

/// The depth a reference's file name states, as Mitsuba names its renders (`maxdepth-D`,
/// `max_depth=D`, ...): pathlab's `-m` for it (Mitsuba's depth D counts the camera ray, so it is
/// pathlab's D - 1; -1 and inf are unbounded).
pub fn depth_from_name(path: &Path) -> Option<String> {
    let name = path.file_stem()?.to_str()?.to_ascii_lowercase();
    let at = ["maxdepth", "max_depth", "max-depth"]
        .iter()
        .find_map(|k| name.find(k).map(|i| i + k.len()))?;
    let rest = &name[at..];
    let rest = rest.strip_prefix(['-', '_', '=']).unwrap_or(rest);
    if rest.starts_with("inf") || rest.starts_with("-1") {
        return Some("inf".to_string());
    }
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    let d: u32 = digits.parse().ok()?;
    Some(d.saturating_sub(1).to_string())
}

use pathlab_render::color::{luminance as luminance_f32, luminance_f64 as luminance};

/// A warning when `reference` cannot be an image of what `film` renders: the image means,
/// in luminance, differ by more than five of the render's standard errors (plus 0.1% of the
/// mean for the reference's own error) — another scene, depth or exposure. Says which
/// depth the reference's file name suggests. `depth` is the render's `-m` as written.
pub fn reference_mismatch(
    film: &Film,
    reference: &[Vec3],
    reference_path: &Path,
    depth: &str,
) -> Option<String> {
    let ours = luminance(film.image_mean());
    let se = luminance(film.image_mean_std_error());
    let n = reference.len().max(1) as f64;
    let theirs = luminance(reference.iter().map(|p| p.as_dvec3()).sum::<glam::DVec3>() / n);
    let tolerance = (se * se + (1e-3 * theirs).powi(2)).sqrt();
    let z = (ours - theirs) / tolerance.max(f64::MIN_POSITIVE);
    if z.abs() <= 5.0 || !z.is_finite() {
        return None;
    }
    let hint = match depth_from_name(reference_path) {
        Some(d) if d != depth => format!("; its name suggests -m {d}"),
        _ => String::new(),
    };
    Some(format!(
        "{}: the reference's mean luminance {theirs:.5} is {:.0} standard errors from this render's {ours:.5} (at -m {depth}): is it the same scene, depth and exposure?{hint}",
        reference_path.display(),
        z.abs()
    ))
}

/// Two image files of one size compared.
pub struct FileDifference {
    /// The image judged.
    pub a: PathBuf,
    /// The image it is compared with.
    pub b: PathBuf,
    /// Where the difference image was written.
    pub output: Option<PathBuf>,
    /// Their size.
    pub resolution: [u32; 2],
    /// How they differ.
    pub difference: ImageDifference,
    /// The heat map's white level, when the difference was written as a PNG.
    pub heat_top: Option<f32>,
}

/// Reads images `a` and `b` (any format [`read_rgb`] reads; of one size) and measures how they
/// differ; with `output`, writes the difference there: an `.exr` holds a - b per channel,
/// anything else is a PNG heat map of |a - b| ([`write_difference_heat_map`]).
pub fn diff_files(a: &Path, b: &Path, output: Option<&Path>) -> Result<FileDifference> {
    let (wa, ha, pa) = read_rgb(a, true)?;
    let (wb, hb, pb) = read_rgb(b, true)?;
    if (wa, ha) != (wb, hb) {
        bail!(
            "{} is {wa}x{ha} but {} is {wb}x{hb}: images of one size are compared",
            a.display(),
            b.display()
        );
    }
    let mut heat_top = None;
    if let Some(out) = output {
        let diff: Vec<Vec3> = pa.iter().zip(&pb).map(|(p, q)| *p - *q).collect();
        let exr = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if exr {
            write_exr(out, wa, ha, &diff, &[])?;
        } else {
            heat_top = Some(write_difference_heat_map(out, wa, ha, &diff)?);
        }
    }
    Ok(FileDifference {
        a: a.to_path_buf(),
        b: b.to_path_buf(),
        output: output.map(Path::to_path_buf),
        resolution: [wa, ha],
        difference: ImageDifference::of(&pa, &pb),
        heat_top,
    })
}

impl FileDifference {
    /// The numbers as JSON.
    pub fn json(&self) -> serde_json::Value {
        let d = &self.difference;
        let rgb = |c: Vec3| [c.x, c.y, c.z];
        serde_json::json!({
            "a": self.a,
            "b": self.b,
            "resolution": self.resolution,
            "rmse": d.rmse,
            "relative_mse": d.relative_mse,
            "max_abs_difference": d.max_abs,
            "mean_a": rgb(d.mean_a),
            "mean_b": rgb(d.mean_b),
            "output": self.output,
        })
    }

    /// The numbers as one line of text.
    pub fn text(&self) -> String {
        let ([w, h], d) = (self.resolution, &self.difference);
        let written = self
            .output
            .as_ref()
            .map_or(String::new(), |o| format!("; wrote {}", o.display()));
        format!(
            "{w}x{h}: RMSE {:.6}, relative MSE {:.6}, largest difference {:.6}; mean {:.5} vs {:.5}{written}",
            d.rmse,
            d.relative_mse,
            d.max_abs,
            d.mean_a.element_sum() / 3.0,
            d.mean_b.element_sum() / 3.0,
        )
    }
}

/// |difference| in luminance as grey levels: black at zero, white at the 99th percentile (the
/// scale returned), so that a few fireflies do not hide the rest.
pub fn write_difference_heat_map(
    path: &Path,
    w: u32,
    h: u32,
    diff: &[Vec3],
) -> Result<f32, pathlab_render::image_io::ImageError> {
    let lum: Vec<f32> = diff.iter().map(|d| luminance_f32(*d).abs()).collect();
    let mut sorted = lum.clone();
    sorted.sort_by(f32::total_cmp);
    let top = sorted
        .get((sorted.len() as f64 * 0.99) as usize)
        .or(sorted.last())
        .copied()
        .unwrap_or(0.0)
        .max(f32::MIN_POSITIVE);
    let bytes: Vec<u8> = lum
        .iter()
        .flat_map(|&v| {
            let g = ((v / top).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            [g, g, g]
        })
        .collect();
    pathlab_render::image_io::write_rgb8(path, w, h, &bytes)?;
    Ok(top)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depths_from_mitsuba_file_names() {
        let d = |s: &str| depth_from_name(Path::new(s));
        assert_eq!(d("mean-maxdepth-2.exr").as_deref(), Some("1"));
        assert_eq!(d("ref_max_depth=5.exr").as_deref(), Some("4"));
        assert_eq!(d("mean-maxdepth-inf.exr").as_deref(), Some("inf"));
        assert_eq!(d("cornell_maxdepth--1.exr").as_deref(), Some("inf"));
        assert_eq!(d("reference.exr"), None);
    }

    #[test]
    fn errors_of_equal_and_shifted_images() {
        let a = vec![Vec3::ONE; 4];
        let b = vec![Vec3::splat(1.5); 4];
        assert_eq!(rmse(&a, &a), 0.0);
        assert!((rmse(&a, &b) - 0.5).abs() < 1e-9);
        assert!((relative_mse(&b, &a) - 0.25 / 1.01).abs() < 1e-9);
        let d = ImageDifference::of(&b, &a);
        assert_eq!((d.max_abs, d.mean_a, d.mean_b), (0.5, b[0], a[0]));
        assert_eq!(
            (d.rmse, d.relative_mse),
            (rmse(&b, &a), relative_mse(&b, &a))
        );
    }
}
