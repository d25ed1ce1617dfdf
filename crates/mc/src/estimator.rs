//! Estimators: running statistics and the Monte Carlo integral F_N = 1/N Σ f(X_i)/p(X_i).
//!
//! [`RunningStats`] keeps the count, mean and sum of squared deviations of a stream of values
//! (Welford's algorithm, numerically stable in one pass) and merges with another in O(1)
//! (Chan, Golub and LeVeque's pairwise update), so parallel workers can each keep their own
//! and combine them at the end. [`Estimate`] is what is reported: mean, standard error and a
//! 95% confidence interval.
//!
//! [`integrate`] is the estimator itself: draw X_i with density p, average f(X_i)/p(X_i). It is
//! unbiased whenever p > 0 wherever f ≠ 0; its variance is Var[f(X)/p(X)]/N, which importance
//! sampling makes small by choosing p close to proportional to |f|.
//!
//! ```
//! use pathlab_mc::estimator::integrate;
//! use pathlab_mc::sampler::{IndependentSampler, Sampler};
//! use pathlab_mc::warp::{sample_uniform_hemisphere, uniform_hemisphere_pdf};
//! // ∫ cos θ dω over the hemisphere = π
//! let mut s = IndependentSampler::new(1, 1);
//! let est = integrate(
//!     |w: &glam::Vec3| w.z as f64,
//!     &mut s,
//!     |s| (sample_uniform_hemisphere(s.next_2d()), uniform_hemisphere_pdf() as f64),
//!     100_000,
//! );
//! assert!((est.mean - std::f64::consts::PI).abs() < 4.0 * est.std_error);
//! ```

use crate::sampler::Sampler;
use rayon::prelude::*;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Count, mean and sum of squared deviations of a stream of values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunningStats {
    n: u64,
    mean: f64,
    m2: f64,
}

impl RunningStats {
    /// No values yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one value (Welford's update).
    #[inline]
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// Combines with the statistics of another, disjoint set of values: the result is what
    /// pushing all of them into one would give (up to rounding).
    pub fn merge(&mut self, other: &RunningStats) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let n = self.n + other.n;
        let delta = other.mean - self.mean;
        let (na, nb) = (self.n as f64, other.n as f64);
        self.mean += delta * nb / n as f64;
        self.m2 += other.m2 + delta * delta * na * nb / n as f64;
        self.n = n;
    }

    /// Number of values.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Their mean (0 when empty).
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// The unbiased sample variance Σ (x - mean)² / (n - 1) (0 with fewer than two values).
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Standard deviation, √variance.
    pub fn std_dev(&self) -> f64 {
        self.variance().sqrt()
    }

    /// Standard error of the mean, √(variance / n).
    pub fn std_error(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.variance() / self.n as f64).sqrt()
        }
    }

    /// The summary of these values as an estimate of their expectation.
    pub fn estimate(&self) -> Estimate {
        Estimate::from_stats(self)
    }
}

/// A Monte Carlo estimate with its uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Number of samples.
    pub n: u64,
    /// The estimate F_N.
    pub mean: f64,
    /// Sample variance of the individual terms f(X_i)/p(X_i).
    pub variance: f64,
    /// Standard error of F_N, √(variance / N).
    pub std_error: f64,
    /// Two-sided 95% confidence interval for the expectation (Student's t with N - 1 degrees of
    /// freedom, which is the normal 1.96 for large N).
    pub ci95: (f64, f64),
}

impl Estimate {
    /// Summarises running statistics.
    pub fn from_stats(stats: &RunningStats) -> Self {
        let se = stats.std_error();
        let half = t_quantile_975(stats.count()) * se;
        Estimate {
            n: stats.count(),
            mean: stats.mean(),
            variance: stats.variance(),
            std_error: se,
            ci95: (stats.mean() - half, stats.mean() + half),
        }
    }

    /// Relative standard error, σ_F / |F| (infinite for a zero estimate with nonzero error).
    pub fn relative_error(&self) -> f64 {
        if self.std_error == 0.0 {
            0.0
        } else {
            self.std_error / self.mean.abs()
        }
    }

    /// Half the width of the 95% confidence interval.
    pub fn ci95_half_width(&self) -> f64 {
        0.5 * (self.ci95.1 - self.ci95.0)
    }

    /// Whether `value` lies inside the 95% confidence interval.
    pub fn ci95_contains(&self, value: f64) -> bool {
        (self.ci95.0..=self.ci95.1).contains(&value)
    }
}

/// The 0.975 quantile of Student's t with n - 1 degrees of freedom.
fn t_quantile_975(n: u64) -> f64 {
    if n < 2 {
        return f64::INFINITY;
    }
    if n > 100_000 {
        return 1.959_963_984_540_054; // the normal quantile, to 1e-5 relative
    }
    StudentsT::new(0.0, 1.0, (n - 1) as f64)
        .map(|t| t.inverse_cdf(0.975))
        .unwrap_or(1.959_963_984_540_054)
}

/// The Monte Carlo estimator F_N = 1/N Σ f(X_i)/p(X_i).
///
/// For `i` in `0..n`, positions `sampler` at sample `i` (pixel (0, 0), dimension 0), calls
/// `sample` to draw X_i and its density p(X_i) from the sampler, and averages f(X_i)/p(X_i).
/// A draw with p = 0 contributes 0: such points are outside the sampled domain, and the
/// estimate is of the integral of f over the set where p > 0.
pub fn integrate<S: Sampler, X>(
    mut f: impl FnMut(&X) -> f64,
    sampler: &mut S,
    mut sample: impl FnMut(&mut S) -> (X, f64),
    n: u32,
) -> Estimate {
    let mut stats = RunningStats::new();
    for i in 0..n {
        sampler.start_pixel_sample([0, 0], i, 0);
        stats.push(weighted_value(&mut f, sampler, &mut sample));
    }
    stats.estimate()
}

#[inline]
fn weighted_value<S, X>(
    f: &mut impl FnMut(&X) -> f64,
    sampler: &mut S,
    sample: &mut impl FnMut(&mut S) -> (X, f64),
) -> f64 {
    let (x, pdf) = sample(sampler);
    if pdf > 0.0 {
        f(&x) / pdf
    } else {
        0.0
    }
}

/// Samples per work unit in [`integrate_parallel`].
pub const PARALLEL_CHUNK: u32 = 4096;

/// [`integrate`] on all threads, with the same result for any thread count.
///
/// Sample indices are cut into chunks of [`PARALLEL_CHUNK`]; each chunk runs on a clone of
/// `sampler` and keeps its own [`RunningStats`]; the chunks are merged in index order. Because
/// each sample depends only on its index, the estimate is bit-for-bit the same for any number
/// of threads (it can differ from [`integrate`] in the last bits, from the merge order).
pub fn integrate_parallel<S, X>(
    f: impl Fn(&X) -> f64 + Sync,
    sampler: &S,
    sample: impl Fn(&mut S) -> (X, f64) + Sync,
    n: u32,
) -> Estimate
where
    S: Sampler + Clone + Send + Sync,
{
    let chunks = n.div_ceil(PARALLEL_CHUNK);
    let partial: Vec<RunningStats> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut s = sampler.clone();
            let mut stats = RunningStats::new();
            let start = c * PARALLEL_CHUNK;
            let end = start.saturating_add(PARALLEL_CHUNK).min(n);
            for i in start..end {
                s.start_pixel_sample([0, 0], i, 0);
                stats.push(weighted_value(&mut &f, &mut s, &mut &sample));
            }
            stats
        })
        .collect();
    let mut total = RunningStats::new();
    for p in &partial {
        total.merge(p);
    }
    total.estimate()
}

/// The share of the sample variance that the single largest term carries:
/// max (v_i - mean)² / Σ (v_i - mean)² over the `n` terms f/p that [`integrate_parallel`]
/// draws (the same terms, recomputed). With finite variance it falls towards zero as n grows
/// (like ln² n / n for exponential tails); when the terms have infinite variance, one term
/// keeps a sizeable share however many there are, and the standard error means nothing.
pub fn largest_term_share<S, X>(
    f: impl Fn(&X) -> f64 + Sync,
    sampler: &S,
    sample: impl Fn(&mut S) -> (X, f64) + Sync,
    n: u32,
    mean: f64,
) -> f64
where
    S: Sampler + Clone + Send + Sync,
{
    let chunks = n.div_ceil(PARALLEL_CHUNK);
    let (sum, largest) = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut s = sampler.clone();
            let (mut sum, mut largest) = (0.0f64, 0.0f64);
            let start = c * PARALLEL_CHUNK;
            for i in start..start.saturating_add(PARALLEL_CHUNK).min(n) {
                s.start_pixel_sample([0, 0], i, 0);
                let d = weighted_value(&mut &f, &mut s, &mut &sample) - mean;
                sum += d * d;
                largest = largest.max(d * d);
            }
            (sum, largest)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .fold((0.0, 0.0), |(s, l), (cs, cl)| (s + cs, f64::max(l, cl)));
    if sum > 0.0 {
        largest / sum
    } else {
        0.0
    }
}

/// Whether a largest-term share ([`largest_term_share`]) of `n` terms is too large for a
/// distribution with finite variance: above 5% and above 10 ln² n / n, which light-tailed
/// terms (uniform, Gaussian, exponential) stay far below.
pub fn looks_heavy_tailed(share: f64, n: u64) -> bool {
    let ln = (n.max(2) as f64).ln();
    share > 0.05 && share > 10.0 * ln * ln / n as f64
}

/// The estimate from independent randomisations (replicates) of a sampler whose samples are
/// not independent (stratified, Sobol): `means` are the replicates' estimates, each of
/// `per_replicate` samples. The estimate is their mean, its standard error and interval those
/// of a mean of `means.len()` independent values (Student's t with R - 1 degrees of freedom);
/// `n` counts every sample and `variance` is scaled to one sample's (R × per_replicate × se²)
/// so that it compares with an independent sampler's.
pub fn replicate_estimate(means: &[f64], per_replicate: u64) -> Estimate {
    let mut stats = RunningStats::new();
    means.iter().for_each(|&m| stats.push(m));
    let mut e = stats.estimate();
    e.n = per_replicate * means.len() as u64;
    e.variance *= per_replicate as f64;
    e
}

/// The least-squares slope of ln(error) against ln(n) over the points `(n, error)` with a
/// positive, finite error and n > 0: the order of convergence an experiment shows (-1/2 for
/// plain Monte Carlo, steeper for quasi-Monte Carlo). NaN with fewer than two such points.
pub fn loglog_slope(points: impl IntoIterator<Item = (f64, f64)>) -> f64 {
    let pts: Vec<(f64, f64)> = points
        .into_iter()
        .filter(|&(n, e)| n > 0.0 && e > 0.0 && e.is_finite())
        .map(|(n, e)| (n.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return f64::NAN;
    }
    let k = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / k;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / k;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

#[cfg(test)]
mod tests {
    use crate::sampler::IndependentSampler;

    /// The largest-term share of f/p = g(U) for U uniform on (0, 1).
    fn share_of(g: impl Fn(f64) -> f64 + Sync, n: u32) -> (f64, f64) {
        let sampler = IndependentSampler::new(n, 7);
        let term = |x: &f64| g(*x);
        let draw = |s: &mut IndependentSampler| (s.next_1d() as f64, 1.0);
        let est = integrate_parallel(term, &sampler, draw, n);
        (
            largest_term_share(term, &sampler, draw, n, est.mean),
            est.mean,
        )
    }

    #[test]
    fn heavy_tails_are_told_from_light_ones() {
        let n = 200_000;
        // ∫ 1/x over (0, 1) diverges; ∫ x^-0.75 = 4 has infinite variance (E[x^-1.5] = ∞).
        for g in [|x: f64| 1.0 / x, |x: f64| x.powf(-0.75)] {
            let (share, _) = share_of(g, n);
            assert!(looks_heavy_tailed(share, n as u64), "share {share}");
        }
        // Finite variance: uniform, exponential (-ln U), x^-0.25 (E[x^-0.5] = 2).
        for g in [|x: f64| x, |x: f64| -(1.0 - x).ln(), |x: f64| x.powf(-0.25)] {
            let (share, _) = share_of(g, n);
            assert!(!looks_heavy_tailed(share, n as u64), "share {share}");
        }
    }

    use super::*;

    #[test]
    fn welford_matches_two_pass() {
        let xs: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1000) as f64 * 0.01 + 1e6)
            .collect();
        let mut s = RunningStats::new();
        xs.iter().for_each(|&x| s.push(x));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (xs.len() - 1) as f64;
        assert!((s.mean() - mean).abs() < 1e-9 * mean);
        assert!((s.variance() - var).abs() < 1e-9 * var);
    }

    #[test]
    fn merge_equals_sequential() {
        let xs: Vec<f64> = (0..777).map(|i| (i as f64 * 0.37).sin() * 10.0).collect();
        let mut all = RunningStats::new();
        xs.iter().for_each(|&x| all.push(x));
        for split in [0, 1, 100, 776, 777] {
            let (mut a, mut b) = (RunningStats::new(), RunningStats::new());
            xs[..split].iter().for_each(|&x| a.push(x));
            xs[split..].iter().for_each(|&x| b.push(x));
            a.merge(&b);
            assert_eq!(a.count(), all.count());
            assert!((a.mean() - all.mean()).abs() < 1e-12);
            assert!((a.variance() - all.variance()).abs() < 1e-10);
        }
    }

    #[test]
    fn confidence_interval_uses_student_t() {
        let mut s = RunningStats::new();
        for x in [1.0, 2.0, 3.0] {
            s.push(x);
        }
        let e = s.estimate();
        // t_{0.975, 2} = 4.302653; se = 1/√3.
        let half = 4.302_652_729_911_275 / 3f64.sqrt();
        assert!((e.ci95_half_width() - half).abs() < 1e-9);
        assert!(e.ci95_contains(2.0));
    }

    #[test]
    fn loglog_slope_recovers_a_power_law() {
        let pts = (0..8).map(|k| {
            let n = 16.0 * 2f64.powi(k);
            (n, 3.0 * n.powf(-0.5))
        });
        assert!((loglog_slope(pts) + 0.5).abs() < 1e-12);
        assert!(loglog_slope([(1.0, 1.0)]).is_nan());
        assert!(loglog_slope([(1.0, 0.0), (2.0, f64::NAN)]).is_nan());
    }

    #[test]
    fn replicates_give_the_standard_error_of_their_mean() {
        let means = [1.0, 2.0, 3.0, 4.0];
        let e = replicate_estimate(&means, 100);
        assert_eq!(e.n, 400);
        assert_eq!(e.mean, 2.5);
        // Sample variance of the replicates 5/3; se² = (5/3)/4.
        assert!((e.std_error - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert!((e.variance - 100.0 * 5.0 / 3.0).abs() < 1e-9);
        // t with 3 degrees of freedom, not 1.96.
        let half = 3.182_446_305_284_263 * e.std_error;
        assert!((e.ci95.1 - e.mean - half).abs() < 1e-9);
    }
}
