//! Samplers: where the uniform numbers of each pixel sample come from.
//!
//! A [`Sampler`] hands out the random numbers of one *pixel sample* at a time, one dimension after
//! another. [`Sampler::start_pixel_sample`] positions it; from then on the values it returns are a
//! pure function of `(seed, pixel, sample index, dimension)`, so a render or an integral gives
//! the same result for the same seed whatever the thread count or the order of work.
//!
//! Three implementations, all behind the same trait and also gathered in the [`AnySampler`]
//! enum for static dispatch:
//! - [`IndependentSampler`]: independent uniform numbers (PCG32 streams);
//! - [`StratifiedSampler`]: jittered stratification of each 1D and 2D dimension, strata
//!   decorrelated between dimensions by hashed permutations ("padding");
//! - [`SobolSampler`]: the Sobol sequence with hash-based Owen scrambling (Burley 2020), a
//!   randomised quasi-Monte Carlo sampler.
//!
//! ```
//! use pathlab_mc::sampler::{Sampler, SobolSampler};
//! let mut s = SobolSampler::new(64, 7);
//! s.start_pixel_sample([3, 4], 0, 0);
//! let film = s.next_pixel_2d();
//! let u = s.next_1d();
//! assert!((0.0..1.0).contains(&film.x) && (0.0..1.0).contains(&u));
//! ```

mod independent;
mod sobol;
mod stratified;

pub use independent::IndependentSampler;
pub use sobol::{SobolSampler, PATH_LANES};
pub use stratified::{permutation_element, StratifiedSampler};

use glam::Vec2;

/// A source of uniform numbers in [0, 1) for pixel samples.
pub trait Sampler {
    /// The number of samples per pixel the sampler was set up for (stratification and
    /// low-discrepancy patterns are built for this count).
    fn samples_per_pixel(&self) -> u32;

    /// Positions the sampler at `dimension` of sample `sample_index` of `pixel`.
    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32);

    /// The next dimension: a uniform number in [0, 1).
    fn next_1d(&mut self) -> f32;

    /// The next two dimensions as a point of [0, 1)², stratified jointly where the sampler can.
    fn next_2d(&mut self) -> Vec2;

    /// The sample position inside the pixel (the first two dimensions of a pixel sample).
    fn next_pixel_2d(&mut self) -> Vec2 {
        self.next_2d()
    }

    /// The next `x.len()` dimensions as a point of [0, 1)^d: two at a time from
    /// [`Sampler::next_2d`] (stratified jointly), the last alone from [`Sampler::next_1d`] when
    /// `d` is odd.
    fn next_point(&mut self, x: &mut [f64]) {
        let mut pairs = x.chunks_exact_mut(2);
        for pair in &mut pairs {
            let u = self.next_2d();
            pair[0] = u.x as f64;
            pair[1] = u.y as f64;
        }
        if let [last] = pairs.into_remainder() {
            *last = self.next_1d() as f64;
        }
    }
}

/// Which sampler to use, by name (for command lines and configuration).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// [`IndependentSampler`].
    Independent,
    /// [`StratifiedSampler`] with jitter.
    Stratified,
    /// [`SobolSampler`].
    Sobol,
}

impl SamplerKind {
    /// All kinds, in the order they are usually compared.
    pub const ALL: [SamplerKind; 3] = [
        SamplerKind::Independent,
        SamplerKind::Stratified,
        SamplerKind::Sobol,
    ];

    /// The lower-case name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
            SamplerKind::Sobol => "sobol",
        }
    }

    /// Builds the sampler for `samples_per_pixel` samples with `seed`.
    pub fn build(self, samples_per_pixel: u32, seed: u64) -> AnySampler {
        match self {
            SamplerKind::Independent => {
                AnySampler::Independent(IndependentSampler::new(samples_per_pixel, seed))
            }
            SamplerKind::Stratified => {
                AnySampler::Stratified(StratifiedSampler::with_count(samples_per_pixel, true, seed))
            }
            SamplerKind::Sobol => AnySampler::Sobol(SobolSampler::new(samples_per_pixel, seed)),
        }
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        crate::named::by_name(s, &SamplerKind::ALL, SamplerKind::name, "sampler")
    }
}

/// Any of the samplers, dispatched by `match` (no allocation, no virtual call per number).
#[derive(Clone, Debug)]
pub enum AnySampler {
    /// See [`IndependentSampler`].
    Independent(IndependentSampler),
    /// See [`StratifiedSampler`].
    Stratified(StratifiedSampler),
    /// See [`SobolSampler`].
    Sobol(SobolSampler),
}

macro_rules! dispatch {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            AnySampler::Independent($s) => $e,
            AnySampler::Stratified($s) => $e,
            AnySampler::Sobol($s) => $e,
        }
    };
}

impl Sampler for AnySampler {
    fn samples_per_pixel(&self) -> u32 {
        dispatch!(self, s => s.samples_per_pixel())
    }
    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        dispatch!(self, s => s.start_pixel_sample(pixel, sample_index, dimension))
    }
    #[inline]
    fn next_1d(&mut self) -> f32 {
        dispatch!(self, s => s.next_1d())
    }
    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        dispatch!(self, s => s.next_2d())
    }
    #[inline]
    fn next_pixel_2d(&mut self) -> Vec2 {
        dispatch!(self, s => s.next_pixel_2d())
    }
}

impl AnySampler {
    /// Draws for eight samplers at once what each would give for the requests `dims` (1 for
    /// [`Sampler::next_1d`], 2 for [`Sampler::next_2d`]) made in order: a value per dimension,
    /// lane by lane (`out[k][lane]`), for the lanes whose bit is set in `lanes`. The same
    /// numbers as those calls; Sobol samplers compute their scrambles for all lanes together
    /// ([`SobolSampler::next_lanes`]), independent ones step their generators together
    /// ([`IndependentSampler::next_lanes`]), the others draw one lane after another.
    pub fn next_lanes(
        samplers: &mut [AnySampler; PATH_LANES],
        lanes: u32,
        dims: &[u32],
        out: &mut [[f32; PATH_LANES]],
    ) {
        if let [AnySampler::Sobol(a), AnySampler::Sobol(b), AnySampler::Sobol(c), AnySampler::Sobol(d), AnySampler::Sobol(e), AnySampler::Sobol(f), AnySampler::Sobol(g), AnySampler::Sobol(h)] =
            samplers
        {
            return SobolSampler::next_lanes(&mut [a, b, c, d, e, f, g, h], lanes, dims, out);
        }
        if let [AnySampler::Independent(a), AnySampler::Independent(b), AnySampler::Independent(c), AnySampler::Independent(d), AnySampler::Independent(e), AnySampler::Independent(f), AnySampler::Independent(g), AnySampler::Independent(h)] =
            samplers
        {
            return IndependentSampler::next_lanes([a, b, c, d, e, f, g, h], lanes, dims, out);
        }
        for (lane, s) in samplers.iter_mut().enumerate() {
            if lanes & (1 << lane) != 0 {
                // One match per lane, then the sampler's own calls, inlined.
                dispatch!(s, s => draw_lane(s, lane, dims, out));
            }
        }
    }
}

/// The requests `dims` of [`AnySampler::next_lanes`] for one sampler, into lane `lane` of `out`.
#[inline]
fn draw_lane<S: Sampler>(s: &mut S, lane: usize, dims: &[u32], out: &mut [[f32; PATH_LANES]]) {
    let mut k = 0;
    for &n in dims {
        if n == 1 {
            out[k][lane] = s.next_1d();
            k += 1;
        } else {
            let v = s.next_2d();
            (out[k][lane], out[k + 1][lane]) = (v.x, v.y);
            k += 2;
        }
    }
}
