//! Choosing a light: by emitter, and within an emitter in proportion to power.

use super::Light;
use pathlab_mc::distribution::AliasTable;

/// Chooses lights (alias method): every emitter equally likely, and among the lights of one
/// emitter (the triangles of an emitting mesh) in proportion to their power, as Mitsuba
/// chooses them (uniformly among emitters, a mesh's points by area). Lights that may be
/// sampled but have zero power get a tiny share of their emitter's so that every one stays
/// reachable; lights that must not be sampled (seen by camera rays only) get none.
#[derive(Clone, Debug)]
pub struct LightSampler {
    table: Option<AliasTable>,
}

impl LightSampler {
    /// The sampler for `lights`, light `i` belonging to emitter `groups[i]`; those with
    /// `sampleable[i] == false` are never chosen.
    pub fn new(lights: &[Light], sampleable: &[bool], groups: &[u32]) -> Self {
        let phi = |i: usize| (lights[i].phi() as f64).max(0.0);
        let mut totals: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        for i in (0..lights.len()).filter(|&i| sampleable[i]) {
            *totals.entry(groups[i]).or_insert(0.0) += phi(i);
        }
        let emitters = totals.len().max(1) as f64;
        let mut counts: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for i in (0..lights.len()).filter(|&i| sampleable[i]) {
            *counts.entry(groups[i]).or_insert(0) += 1;
        }
        let weights: Vec<f64> = (0..lights.len())
            .map(|i| {
                if !sampleable[i] {
                    return 0.0;
                }
                let total = totals[&groups[i]];
                let share = if total > 0.0 {
                    phi(i).max(total * 1e-6) / total
                } else {
                    1.0 / counts[&groups[i]] as f64
                };
                share / emitters
            })
            .collect();
        LightSampler {
            table: AliasTable::new(&weights).ok(),
        }
    }

    /// A light index and its probability, or `None` when there are no lights.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        self.table.as_ref().map(|t| {
            let (index, pmf) = t.choose(u);
            (index, pmf as f32)
        })
    }

    /// The probability of choosing light `index`.
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        self.table.as_ref().map_or(0.0, |t| t.pmf(index) as f32)
    }
}
