//! The film: per pixel, the number of samples and the running mean and variance of radiance.

use crate::desc::Rgb;
use glam::{DVec3, Vec3};
use pathlab_mc::exact::{add_fixed, add_fixed_with_squares, from_fixed, ExactStats, Sums8};

/// Statistics of one pixel's samples: their count, and exact sums of each channel and of
/// luminance and of their squares ([`pathlab_mc::exact`]): the same for any order in which
/// samples arrive, so passes, resumed checkpoints and merged shards give the same image to the
/// bit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelStats {
    n: u64,
    /// Σ of R, G, B and luminance, then Σ of their squares, in fixed point.
    sums: Sums8,
}

/// Bytes of one pixel in [`PixelStats::to_bytes`].
pub const PIXEL_BYTES: usize = 8 + 8 * 16;

impl PixelStats {
    /// Adds a sample.
    #[inline]
    pub fn add(&mut self, l: Rgb) {
        self.n += 1;
        let lum = crate::color::luminance(l);
        add_fixed_with_squares(&mut self.sums, [l.x, l.y, l.z, lum]);
    }

    /// Statistics of channel `c` (0, 1, 2: R, G, B; 3: luminance).
    #[inline]
    fn channel(&self, c: usize) -> ExactStats {
        ExactStats::from_raw(self.n, self.sums.get(c), self.sums.get(4 + c))
    }

    /// Statistics of the samples' luminance (the "illuminance" of the course's adaptive
    /// sampling).
    pub fn luminance(&self) -> ExactStats {
        self.channel(3)
    }

    /// Combines with another set of samples of the same pixel (exactly).
    pub fn merge(&mut self, o: &PixelStats) {
        self.n += o.n;
        for k in 0..8 {
            self.sums
                .set(k, self.sums.get(k).saturating_add(o.sums.get(k)));
        }
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Mean radiance.
    pub fn mean(&self) -> DVec3 {
        DVec3::new(
            self.channel(0).mean(),
            self.channel(1).mean(),
            self.channel(2).mean(),
        )
    }

    /// Sample variance of one sample, per channel.
    pub fn variance(&self) -> DVec3 {
        DVec3::new(
            self.channel(0).variance(),
            self.channel(1).variance(),
            self.channel(2).variance(),
        )
    }

    /// Variance of the mean (squared standard error), per channel.
    pub fn variance_of_mean(&self) -> DVec3 {
        let n = self.count();
        if n == 0 {
            DVec3::ZERO
        } else {
            self.variance() / n as f64
        }
    }

    /// The exact state, little-endian: count, then the sums, then the sums of squares.
    pub fn to_bytes(&self, out: &mut Vec<u8>) {
        out.extend(self.n.to_le_bytes());
        for v in self.sums.to_array() {
            out.extend(v.to_le_bytes());
        }
    }

    /// The state [`PixelStats::to_bytes`] wrote (exactly [`PIXEL_BYTES`] bytes).
    pub fn from_bytes(b: &[u8]) -> Option<PixelStats> {
        if b.len() != PIXEL_BYTES {
            return None;
        }
        let n = u64::from_le_bytes(b[..8].try_into().ok()?);
        let mut v = [0i128; 8];
        for (k, chunk) in b[8..].chunks_exact(16).enumerate() {
            v[k] = i128::from_le_bytes(chunk.try_into().ok()?);
        }
        Some(PixelStats {
            n,
            sums: Sums8::from_array(v),
        })
    }
}

/// An image of pixel statistics, row 0 at the top; and, for integrators that trace light to
/// the lens (the bidirectional path tracer), the light it brought to each pixel: exact sums of
/// splatted radiance and the number of light paths traced, whose ratio (times the pixel
/// count, as camera importance is normalised over the whole image) adds to each pixel's mean.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<PixelStats>,
    /// Σ of splatted R, G, B per pixel, fixed point (empty until the first splat).
    splats: Vec<[i128; 3]>,
    /// Light paths traced for the splats (one per camera sample that traced one).
    light_paths: u64,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            pixels: vec![PixelStats::default(); width as usize * height as usize],
            splats: Vec::new(),
            light_paths: 0,
        }
    }

    /// Bytes a film of this size holds in memory (its pixels' exact sums).
    pub fn bytes_for(width: u32, height: u32) -> u64 {
        width as u64 * height as u64 * std::mem::size_of::<PixelStats>() as u64
    }

    /// An empty film, or an error saying how much memory it needs when that cannot be had
    /// (where [`Film::new`] would abort the program).
    pub fn try_new(width: u32, height: u32) -> Result<Self, String> {
        let n = width as usize * height as usize;
        let mut pixels = Vec::new();
        pixels.try_reserve_exact(n).map_err(|_| {
            let gib = Film::bytes_for(width, height) as f64 / (1u64 << 30) as f64;
            format!(
                "a {width}x{height} film needs {gib:.1} GiB of memory ({} bytes a pixel: each \
                 pixel's exact sums), which cannot be allocated here; render a smaller \
                 image (-r or --scale)",
                std::mem::size_of::<PixelStats>()
            )
        })?;
        pixels.resize(n, PixelStats::default());
        Ok(Film {
            width,
            height,
            pixels,
            splats: Vec::new(),
            light_paths: 0,
        })
    }

    /// Adds radiance splatted on pixel (x, y) by a light path.
    pub fn add_splat(&mut self, x: u32, y: u32, v: Rgb) {
        if self.splats.is_empty() {
            self.splats = vec![[0; 3]; self.pixels.len()];
        }
        let s = &mut self.splats[(y * self.width + x) as usize];
        for (c, v) in [v.x, v.y, v.z].into_iter().enumerate() {
            s[c] = add_fixed(s[c], f64::from(v));
        }
    }

    /// Counts `n` more light paths traced for the splats.
    pub fn add_light_paths(&mut self, n: u64) {
        self.light_paths += n;
    }

    /// Light paths traced for the splats.
    pub fn light_paths(&self) -> u64 {
        self.light_paths
    }

    /// The exact splat sums, row-major (empty when nothing was splatted).
    pub fn splat_sums(&self) -> &[[i128; 3]] {
        &self.splats
    }

    /// Sets the splat sums and light-path count (a film file's).
    pub fn set_splats(&mut self, sums: Vec<[i128; 3]>, light_paths: u64) {
        debug_assert!(sums.is_empty() || sums.len() == self.pixels.len());
        self.splats = sums;
        self.light_paths = light_paths;
    }

    /// Adds another film's splats and light paths (exactly).
    pub fn merge_splats(&mut self, o: &Film) {
        self.light_paths += o.light_paths;
        if o.splats.is_empty() {
            return;
        }
        if self.splats.is_empty() {
            self.splats = vec![[0; 3]; self.pixels.len()];
        }
        for (a, b) in self.splats.iter_mut().zip(&o.splats) {
            for c in 0..3 {
                a[c] = a[c].saturating_add(b[c]);
            }
        }
    }

    /// What light traced to the lens adds to pixel `i`'s mean.
    fn splat_mean(&self, i: usize) -> DVec3 {
        match self.splats.get(i) {
            Some(s) if self.light_paths > 0 => {
                let scale = self.pixels.len() as f64 / self.light_paths as f64;
                DVec3::new(from_fixed(s[0]), from_fixed(s[1]), from_fixed(s[2])) * scale
            }
            _ => DVec3::ZERO,
        }
    }

    /// The radiance estimate of pixel `i`: its samples' mean, plus the light traced to it.
    pub fn pixel_value(&self, i: usize) -> DVec3 {
        let mean = self.pixels[i].mean();
        if self.light_paths == 0 || self.splats.is_empty() {
            // Nothing traced to the lens: the samples' mean to the bit (-0.0 included).
            return mean;
        }
        mean + self.splat_mean(i)
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The statistics of pixel (x, y).
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> &PixelStats {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// Mutable statistics of pixel (x, y).
    #[inline]
    pub fn pixel_mut(&mut self, x: u32, y: u32) -> &mut PixelStats {
        &mut self.pixels[(y * self.width + x) as usize]
    }

    /// All pixels, row-major.
    pub fn pixels(&self) -> &[PixelStats] {
        &self.pixels
    }

    /// All pixels, row-major, mutable.
    pub fn pixels_mut(&mut self) -> &mut [PixelStats] {
        &mut self.pixels
    }

    /// Mean radiance per pixel (with the light traced to it), row-major.
    pub fn mean_image(&self) -> Vec<Vec3> {
        (0..self.pixels.len())
            .map(|i| self.pixel_value(i).as_vec3())
            .collect()
    }

    /// Variance of each pixel's mean, row-major.
    pub fn variance_image(&self) -> Vec<Vec3> {
        self.pixels
            .iter()
            .map(|p| p.variance_of_mean().as_vec3())
            .collect()
    }

    /// Samples per pixel, row-major.
    pub fn sample_counts(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| p.count() as f32).collect()
    }

    /// The fewest, the most and the mean samples per pixel, over the values
    /// [`Film::sample_counts`] holds (adaptive and progressive renders vary them per pixel).
    pub fn sample_count_range(&self) -> SampleCountRange {
        let counts = self.sample_counts();
        let (min, max) = counts.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
        let mean = counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
        SampleCountRange { min, max, mean }
    }

    /// Mean of all pixel values ([`Film::pixel_value`]).
    pub fn image_mean(&self) -> DVec3 {
        let sum: DVec3 = (0..self.pixels.len()).map(|i| self.pixel_value(i)).sum();
        sum / self.pixels.len().max(1) as f64
    }

    /// Standard error of [`Film::image_mean`], from the pixels' own variances (pixels are
    /// independent).
    pub fn image_mean_std_error(&self) -> DVec3 {
        let sum: DVec3 = self.pixels.iter().map(|p| p.variance_of_mean()).sum();
        let n = self.pixels.len().max(1) as f64;
        (sum / (n * n)).map(f64::sqrt)
    }
}

/// Samples per pixel over a film ([`Film::sample_count_range`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleCountRange {
    /// The fewest a pixel holds.
    pub min: f32,
    /// The most a pixel holds.
    pub max: f32,
    /// Their mean over the pixels.
    pub mean: f64,
}
