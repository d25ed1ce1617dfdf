//! Walker's alias method ([`AliasTable`]): a discrete choice among n outcomes in constant time.

use super::check_weights;
use crate::error::{Error, Result};

/// One outcome of [`AliasTable::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AliasSample {
    /// The chosen index.
    pub index: usize,
    /// Its probability.
    pub pmf: f64,
    /// The random number stretched back to [0, 1) within the decision, for reuse.
    pub u_remapped: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Bin {
    /// Probability of keeping this bin's own index once the bin is chosen.
    q: f64,
    /// The index used otherwise.
    alias: usize,
}

/// Vose's construction of the bins of an alias table from `scaled`, each outcome's probability
/// times the number of outcomes (so they average 1): bin `i`'s probability `q` of keeping `i`
/// and its alias. Bins are filled by pairing an under-full outcome with an over-full one until
/// every bin holds exactly 1/n of probability; an outcome of zero probability keeps none.
pub(crate) fn vose_bins(mut scaled: Vec<f64>) -> Vec<(f64, usize)> {
    let n = scaled.len();
    let mut bins: Vec<(f64, usize)> = (0..n).map(|i| (1.0, i)).collect();
    // A bin is "small" below 1 and "large" above.
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        bins[s] = (scaled[s], l);
        // The large outcome gives (1 - q_s) of its scaled probability to bin s.
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What remains in either list holds (up to rounding) exactly one bin's worth.
    for i in small.into_iter().chain(large) {
        bins[i] = (1.0, i);
    }
    bins
}

/// Walker's alias method: a discrete distribution over `0..n` sampled in O(1).
///
/// Each of `n` equally likely bins holds its own index with probability `q` and an alias
/// otherwise; Vose's construction ("A linear algorithm for generating random numbers with a
/// given distribution", 1991) fills the bins by pairing an under-full index with an over-full
/// one until every bin holds exactly 1/n of probability.
///
/// ```
/// use pathlab_mc::distribution::AliasTable;
/// let t = AliasTable::new(&[1.0, 0.0, 3.0]).unwrap();
/// assert!((t.pmf(2) - 0.75).abs() < 1e-12);
/// assert_eq!(t.pmf(1), 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct AliasTable {
    bins: Vec<Bin>,
    pmf: Vec<f64>,
}

impl AliasTable {
    /// The table for `weights` (finite, ≥ 0, not all zero).
    pub fn new(weights: &[f64]) -> Result<Self> {
        const WHAT: &str = "alias table";
        check_weights(WHAT, weights)?;
        let sum: f64 = weights.iter().sum();
        if sum <= 0.0 || !sum.is_finite() {
            return Err(Error::InvalidParameter {
                what: WHAT,
                message: "weights must have a finite, positive sum".to_string(),
            });
        }
        let n = weights.len();
        let pmf: Vec<f64> = weights.iter().map(|w| w / sum).collect();
        let bins = vose_bins(pmf.iter().map(|p| p * n as f64).collect())
            .into_iter()
            .map(|(q, alias)| Bin { q, alias })
            .collect();
        Ok(AliasTable { bins, pmf })
    }

    /// The number of outcomes.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Always false: a table has at least one outcome.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// The probability of `index` (0 outside the table).
    pub fn pmf(&self, index: usize) -> f64 {
        self.pmf.get(index).copied().unwrap_or(0.0)
    }

    /// The bin `u` in [0, 1) falls in, where within the bin it lies (in [0, 1]), and the bin.
    #[inline]
    fn bin(&self, u: f32) -> (usize, f64, Bin) {
        let n = self.bins.len();
        let scaled = u as f64 * n as f64;
        let offset = (scaled as usize).min(n - 1);
        let up = (scaled - offset as f64).clamp(0.0, 1.0);
        (offset, up, self.bins[offset])
    }

    /// An index drawn with probability [`AliasTable::pmf`], from `u` in [0, 1).
    #[inline]
    pub fn sample(&self, u: f32) -> AliasSample {
        let (offset, up, bin) = self.bin(u);
        let one_below = 1.0f32.next_down();
        if up < bin.q {
            AliasSample {
                index: offset,
                pmf: self.pmf[offset],
                u_remapped: ((up / bin.q) as f32).min(one_below),
            }
        } else {
            AliasSample {
                index: bin.alias,
                pmf: self.pmf[bin.alias],
                u_remapped: (((up - bin.q) / (1.0 - bin.q)) as f32).min(one_below),
            }
        }
    }

    /// The index and probability [`AliasTable::sample`] draws from `u`, without the remapped
    /// random number: for callers that do not reuse it, a select instead of a branch and a
    /// division.
    #[inline]
    pub fn choose(&self, u: f32) -> (usize, f64) {
        let (offset, up, bin) = self.bin(u);
        let index = if up < bin.q { offset } else { bin.alias };
        (index, self.pmf[index])
    }
}
