//! What the inspector shows of one pixel beyond its running mean: the histogram of its
//! samples' luminance (where heavy tails and fireflies show) and their mean split by bounce.
//! Both come from the pixel's first samples, rendered again one by one with the image's
//! sampler and seed, so they are the very samples the image's mean is made of.

use crate::controls::Controls;
use pathlab_render::color::luminance_f64;
use pathlab_render::integrator::{Integrator, IntegratorKind};
use pathlab_render::render::pixel_sample_values;
use pathlab_render::scene::Scene;

/// The most samples of a pixel a probe looks at.
pub const PROBE_SAMPLES: u32 = 4096;
/// Bins of the histogram of positive luminances (log-spaced).
pub const HISTOGRAM_BINS: usize = 24;
/// Bounces shown one by one; the light of deeper ones is shown together.
pub const PROBE_BOUNCES: u32 = 8;

/// A pixel's first `samples` samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Probe {
    /// How many samples.
    pub samples: u32,
    /// How many of them are black (luminance ≤ 0).
    pub zero: u32,
    /// log10 of the range `[lo, hi]` the histogram's bins divide evenly.
    pub log10_range: [f64; 2],
    /// Positive samples per bin.
    pub counts: Vec<u32>,
    /// The mean luminance the light of bounce 0, 1, ... adds (bounce 0: emission seen
    /// directly), then that of all deeper bounces; empty unless the path tracer renders every
    /// bounce.
    pub bounces: Vec<f64>,
}

/// How many samples a probe of a pixel with `held` samples takes: a power of two, so that a
/// probe is made again only when the count doubles, and at most [`PROBE_SAMPLES`].
pub fn probe_size(held: u32) -> u32 {
    if held == 0 {
        0
    } else {
        (1u32 << (31 - held.leading_zeros())).min(PROBE_SAMPLES)
    }
}

/// The probe of `pixel`'s first `n` samples as `controls` render them (`spp` and `seed`: the
/// image's sampler's).
pub fn probe(
    scene: &Scene,
    controls: &Controls,
    (spp, seed): (u32, u64),
    pixel: [u32; 2],
    n: u32,
) -> Probe {
    let integrator = controls.integrator();
    let values = |integrator: &dyn Integrator| -> Vec<f64> {
        pixel_sample_values(
            scene,
            integrator,
            (controls.sampler, spp, seed),
            pixel,
            0..n,
        )
        .into_iter()
        .map(|l| luminance_f64(l.as_dvec3()))
        .collect()
    };
    let all = values(&integrator);
    let mut probe = histogram(&all);
    if let IntegratorKind::Path(path) = integrator {
        if path.only_bounce.is_none() {
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
            let mut bounces: Vec<f64> = (0..PROBE_BOUNCES.min(path.max_depth.saturating_add(1)))
                .map(|k| {
                    let one = IntegratorKind::Path(pathlab_render::integrator::PathIntegrator {
                        only_bounce: Some(k),
                        ..path
                    });
                    mean(&values(&one))
                })
                .collect();
            // Deeper bounces: what the whole paths add beyond the bounces shown.
            bounces.push((mean(&all) - bounces.iter().sum::<f64>()).max(0.0));
            probe.bounces = bounces;
        }
    }
    probe
}

/// The histogram of `values` (black ones counted apart, the positive ones in log-spaced bins
/// from the smallest to the largest).
fn histogram(values: &[f64]) -> Probe {
    let positive: Vec<f64> = values
        .iter()
        .copied()
        .filter(|&v| v > 0.0 && v.is_finite())
        .collect();
    let mut probe = Probe {
        samples: values.len() as u32,
        zero: (values.len() - positive.len()) as u32,
        counts: vec![0; HISTOGRAM_BINS],
        ..Probe::default()
    };
    if positive.is_empty() {
        return probe;
    }
    let lo = positive
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .log10();
    let hi = positive.iter().copied().fold(0.0, f64::max).log10();
    let (lo, hi) = (lo.floor(), hi.ceil().max(lo.floor() + 1.0));
    for v in positive {
        let t = (v.log10() - lo) / (hi - lo);
        let bin = ((t * HISTOGRAM_BINS as f64) as usize).min(HISTOGRAM_BINS - 1);
        probe.counts[bin] += 1;
    }
    probe.log10_range = [lo, hi];
    probe
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bounces_add_up_to_the_whole_paths_and_the_histogram_holds_every_sample() {
        let mut desc = pathlab_scene::builtin::load("cornell-box").unwrap();
        desc.resolution = [16, 16];
        let scene = Scene::build(&desc).unwrap();
        let controls = Controls::for_scene(&desc.hints);
        assert_eq!(controls.max_depth, 5, "the built-in box's depth");
        let (settings, n) = ((1024, 3), 256);
        // A pixel of the floor: lit directly and through every bounce.
        let p = probe(&scene, &controls, settings, [8, 13], n);
        assert_eq!(p.samples, n);
        assert_eq!(p.zero + p.counts.iter().sum::<u32>(), n);
        // Bounces 0 to 5 are all the path tracer counts at depth 5: the light of deeper ones,
        // measured as the whole paths' mean less theirs, is nothing but rounding.
        assert_eq!(p.bounces.len(), 7);
        let mean = pixel_sample_values(
            &scene,
            &controls.integrator(),
            (controls.sampler, 1024, 3),
            [8, 13],
            0..n,
        )
        .iter()
        .map(|l| luminance_f64(l.as_dvec3()))
        .sum::<f64>()
            / n as f64;
        let shown: f64 = p.bounces[..6].iter().sum();
        assert!(
            (shown - mean).abs() <= 1e-6 * mean,
            "{shown} against {mean}"
        );
        assert!(p.bounces[6] <= 1e-6 * mean);
        // The floor (here in the tall block's shadow) sees no light directly; light reaches
        // it over several bounces.
        assert_eq!(p.bounces[0], 0.0);
        let lit = p.bounces[1..6].iter().filter(|&&b| b > 0.0).count();
        assert!(lit >= 3, "{:?}", p.bounces);
        // Direct lighting alone has no bounces to split.
        let mut direct = controls.clone();
        direct.integrator = "direct".into();
        assert!(probe(&scene, &direct, settings, [8, 13], 16)
            .bounces
            .is_empty());
    }

    #[test]
    fn probes_take_powers_of_two_up_to_the_cap() {
        assert_eq!(
            [0, 1, 3, 4, 1000, 4096, 65536].map(probe_size),
            [0, 1, 2, 4, 512, 4096, 4096]
        );
    }

    #[test]
    fn the_histogram_counts_every_sample_once() {
        let values = [0.0, 0.0, 1e-3, 0.02, 0.5, 0.5, 3.0, 250.0];
        let p = histogram(&values);
        assert_eq!((p.samples, p.zero), (8, 2));
        assert_eq!(p.counts.iter().sum::<u32>(), 6);
        assert_eq!(p.log10_range, [-3.0, 3.0]);
        // 250 (log10 2.4) in the bin of [2.25, 2.5); 1e-3 in the first.
        assert_eq!((p.counts[0], p.counts[21]), (1, 1));
        assert_eq!(histogram(&[0.0; 3]).counts.iter().sum::<u32>(), 0);
    }
}
