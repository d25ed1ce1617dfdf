//! The film: per pixel, the number of samples and the running mean and variance of radiance.

use crate::desc::Rgb;
use glam::{DVec3, Vec3};
use pathlab_mc::estimator::RunningStats;

/// Statistics of one pixel's samples, per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    channels: [RunningStats; 3],
    luminance: RunningStats,
}

impl PixelStats {
    /// Adds a sample.
    #[inline]
    pub fn add(&mut self, l: Rgb) {
        for (c, v) in self.channels.iter_mut().zip(l.to_array()) {
            c.push(v as f64);
        }
        self.luminance.push(crate::light::luminance(l) as f64);
    }

    /// Statistics of the samples' luminance (the "illuminance" of the course's adaptive
    /// sampling).
    pub fn luminance(&self) -> &RunningStats {
        &self.luminance
    }

    /// Combines with another set of samples of the same pixel.
    pub fn merge(&mut self, o: &PixelStats) {
        for (c, d) in self.channels.iter_mut().zip(&o.channels) {
            c.merge(d);
        }
        self.luminance.merge(&o.luminance);
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.channels[0].count()
    }

    /// Mean radiance.
    pub fn mean(&self) -> DVec3 {
        DVec3::new(
            self.channels[0].mean(),
            self.channels[1].mean(),
            self.channels[2].mean(),
        )
    }

    /// Sample variance of one sample, per channel.
    pub fn variance(&self) -> DVec3 {
        DVec3::new(
            self.channels[0].variance(),
            self.channels[1].variance(),
            self.channels[2].variance(),
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
}

/// An image of pixel statistics, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<PixelStats>,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            pixels: vec![PixelStats::default(); width as usize * height as usize],
        }
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

    /// Mean radiance per pixel, row-major.
    pub fn mean_image(&self) -> Vec<Vec3> {
        self.pixels.iter().map(|p| p.mean().as_vec3()).collect()
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

    /// Mean of all pixel means.
    pub fn image_mean(&self) -> DVec3 {
        let sum: DVec3 = self.pixels.iter().map(|p| p.mean()).sum();
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
