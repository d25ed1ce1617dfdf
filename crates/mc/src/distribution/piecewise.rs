//! Piecewise-constant distributions in 1D ([`PiecewiseConstant1D`]) and 2D
//! ([`PiecewiseConstant2D`]), sampled by inverting their tabulated CDFs, continuous or
//! discrete.

use super::{check_grid, check_weights};
use crate::error::{Error, Result};
use crate::simd::lanes::Real;
use glam::Vec2;

/// A continuous sample of a [`PiecewiseConstant1D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiecewiseSample {
    /// The sampled point in `[min, max)`.
    pub x: f32,
    /// Its density with respect to x.
    pub pdf: f32,
    /// The index of the piece it fell in.
    pub offset: usize,
}

/// A discrete sample of a [`PiecewiseConstant1D`]: a piece chosen with probability
/// proportional to its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteSample {
    /// The chosen piece.
    pub index: usize,
    /// Its probability.
    pub pmf: f32,
    /// The random number, stretched back to [0, 1) inside the chosen piece, so that it can be
    /// reused for another decision.
    pub u_remapped: f32,
}

/// Pieces per bucket of the guide table, on average: the table has a quarter as many
/// buckets as there are pieces (rounded to a power of two).
const PIECES_PER_BUCKET: usize = 4;

/// Entry `i` of a tabulated distribution: the CDF at the start of piece `i` and the piece's
/// value (0 for the entry after the last piece). Kept side by side so that the search's block
/// of the CDF brings the found piece's value with it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
struct Entry {
    cdf: f32,
    func: f32,
}

/// How many of `entries` have a CDF value at most `u` (a NaN is not): four comparisons per
/// SSE2 instruction on x86-64 (whose every CPU has SSE2), one at a time elsewhere.
#[inline]
fn count_cdf_at_most(entries: &[Entry], u: f32) -> usize {
    #[cfg(target_arch = "x86_64")]
    return count_by_fours(
        entries,
        u,
        |e| e.cdf,
        |four| {
            use std::arch::x86_64::*;
            // SAFETY: SSE2, all these intrinsics require, is part of every x86-64 CPU. An
            // `Entry` is two `f32` (`repr(C)`), so a chunk of exactly four entries is eight
            // floats, read by two loads of four, whose even lanes are the CDF values.
            unsafe {
                let p = four.as_ptr().cast::<f32>();
                _mm_shuffle_ps::<0b10_00_10_00>(_mm_loadu_ps(p), _mm_loadu_ps(p.add(4)))
            }
        },
    );
    #[cfg(not(target_arch = "x86_64"))]
    entries.iter().filter(|e| e.cdf <= u).count()
}

/// How many of `items` have a `key` at most `u`: the keys of each chunk of four, as `keys`
/// loads them into one register, compared with one SSE2 instruction, the last few one at a
/// time.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn count_by_fours<T>(
    items: &[T],
    u: f32,
    key: impl Fn(&T) -> f32,
    keys: impl Fn(&[T]) -> std::arch::x86_64::__m128,
) -> usize {
    use std::arch::x86_64::*;
    let mut chunks = items.chunks_exact(4);
    // SAFETY: SSE2, all these intrinsics require, is part of every x86-64 CPU.
    let counted = unsafe {
        let u4 = _mm_set1_ps(u);
        // A true comparison is all ones, -1 as an integer: subtracting it counts.
        let mut counts = _mm_setzero_si128();
        for four in &mut chunks {
            let le = _mm_cmple_ps(keys(four), u4);
            counts = _mm_sub_epi32(counts, _mm_castps_si128(le));
        }
        let pairs = _mm_add_epi32(counts, _mm_shuffle_epi32::<0b01_00_11_10>(counts));
        let all = _mm_add_epi32(pairs, _mm_shuffle_epi32::<0b10_11_00_01>(pairs));
        _mm_cvtsi128_si32(all) as usize
    };
    counted + chunks.remainder().iter().filter(|x| key(x) <= u).count()
}

/// The tables of one 1D distribution, borrowed: what sampling and evaluation read. A
/// [`PiecewiseConstant1D`] lends its own; a [`PiecewiseConstant2D`] lends one row of its flat
/// tables. One implementation of the search and the inversion serves both.
#[derive(Clone, Copy)]
struct Pieces<'a> {
    /// `n + 1` entries.
    entries: &'a [Entry],
    /// The guide table ([`guide_table`]): `K + 2` counts for `K` buckets.
    guide: &'a [u32],
    min: f32,
    max: f32,
    func_int: f32,
}

impl Pieces<'_> {
    /// The number of pieces.
    #[inline]
    fn len(&self) -> usize {
        self.entries.len() - 1
    }

    /// The piece `o` with `cdf[o] <= u < cdf[o + 1]` (pieces of zero probability are skipped).
    #[inline]
    fn find_piece(&self, u: f32) -> usize {
        self.piece_of_count(self.cdf_entries_at_most(u))
    }

    /// The piece of a `u` that `count` CDF entries are at most: the count less one, kept
    /// within 0..n.
    #[inline]
    fn piece_of_count(&self, count: usize) -> usize {
        count.saturating_sub(1).min(self.len() - 1)
    }

    /// The number of CDF entries `<= u` (the CDF does not decrease, so they are its first
    /// ones): the guide table gives the counts at the two multiples of 1/K around `u`, and
    /// the entries between them are counted. The same count as a binary search over the
    /// whole CDF.
    #[inline]
    fn cdf_entries_at_most(&self, u: f32) -> usize {
        match self.bucket(u) {
            Some((lo, hi)) => lo + count_cdf_at_most(&self.entries[lo..hi], u),
            None => 0,
        }
    }

    /// The entries `lo..hi` of `u`'s bucket of the guide table: entries before `lo` are
    /// ≤ k/K ≤ u, entries from `hi` on exceed (k + 1)/K > u (bucket K, u ≥ 1, runs to the
    /// end). None where `u` is NaN or negative: every CDF entry is ≥ 0, and none compares
    /// ≤ NaN.
    #[inline(always)]
    fn bucket(&self, u: f32) -> Option<(usize, usize)> {
        let buckets = self.guide.len() - 2;
        // K is a power of two, so t is exactly u·K and k/K ≤ u < (k + 1)/K.
        let t = u * buckets as f32;
        if t.is_nan() || t < 0.0 {
            return None;
        }
        let k = (t as usize).min(buckets);
        Some((self.guide[k] as usize, self.guide[k + 1] as usize))
    }

    /// Density of piece `o` with respect to x.
    #[inline]
    fn piece_pdf(&self, o: usize) -> f32 {
        density_of_piece(self.entries[o].func, self.func_int, self.min, self.max)
    }

    /// Whether the domain is [0, 1] ([`is_unit_domain`]).
    #[inline]
    fn unit_domain(&self) -> bool {
        is_unit_domain(self.min, self.max)
    }

    /// The index of the piece containing `x` (clamped to the domain).
    #[inline]
    fn offset_of(&self, x: f32) -> usize {
        let n = self.len();
        // On [0, 1], (x - 0) / 1 is x itself: subtracting 0 and dividing by 1 are exact.
        let t = if self.unit_domain() {
            x
        } else {
            (x - self.min) / (self.max - self.min)
        };
        ((t * n as f32) as isize).clamp(0, n as isize - 1) as usize
    }

    #[inline]
    fn sample(&self, u: f32) -> PiecewiseSample {
        let o = self.piece_of_count(self.cdf_entries_at_most(u));
        let piece = self.piece(o);
        let x = point_in_piece(u, o as f32, piece, self.len(), self.min, self.max);
        PiecewiseSample {
            x: self.settle_in_piece(x, o),
            pdf: density_of_piece(piece.func, self.func_int, self.min, self.max),
            offset: o,
        }
    }

    /// Piece `o`'s CDF at its two ends and its value.
    #[inline(always)]
    fn piece(&self, o: usize) -> Piece<f32> {
        let (e0, e1) = (self.entries[o], self.entries[o + 1]);
        Piece {
            c0: e0.cdf,
            c1: e1.cdf,
            func: e0.func,
        }
    }

    /// `x`, a point [`point_in_piece`] put in piece `o`, or the nearest float inside piece `o`
    /// where rounding put it at the edge of a neighbouring piece, whose density differs (or
    /// is zero).
    #[inline(always)]
    fn settle_in_piece(&self, x: f32, o: usize) -> f32 {
        if self.offset_of(x) == o {
            x
        } else {
            step_into_piece(x, o, |x| self.offset_of(x))
        }
    }

    fn invert_sample(&self, x: f32) -> f32 {
        let n = self.len();
        let t = ((x - self.min) / (self.max - self.min)).clamp(0.0, 1.0) * n as f32;
        let o = (t as usize).min(n - 1);
        let frac = t - o as f32;
        let (c0, c1) = (self.entries[o].cdf, self.entries[o + 1].cdf);
        c0 + frac * (c1 - c0)
    }
}

/// `x`, a point outside piece `o` (by `offset_of`, which does not decrease with x), moved to
/// the nearest float inside it: rounding puts a point at most a float or two past its piece's
/// edge. Out of line: it is rare.
#[inline(never)]
pub(super) fn step_into_piece(mut x: f32, o: usize, offset_of: impl Fn(f32) -> usize) -> f32 {
    for _ in 0..8 {
        match offset_of(x).cmp(&o) {
            std::cmp::Ordering::Less => x = x.next_up(),
            std::cmp::Ordering::Greater => x = x.next_down(),
            std::cmp::Ordering::Equal => break,
        }
    }
    x
}

/// A piece of a tabulated distribution as sampling reads it, for one value or lanes: the CDF
/// at its start and end and its value.
#[derive(Clone, Copy, Debug, Default)]
struct Piece<R> {
    c0: R,
    c1: R,
    func: R,
}

/// The point that `u` maps to in piece `o` (as a number) of `n` equal pieces over
/// `[min, max]`: the CDF inverted linearly inside the piece, kept below `max`; before
/// [`Pieces::settle_in_piece`]. Written once for one value and for lanes (the `f32` minimum
/// and clamp as selects with their NaN rules: a NaN `du` stays NaN, a NaN `t` or `x` takes the
/// bound).
#[inline(always)]
fn point_in_piece<R: Real>(u: R, o: R, piece: Piece<R>, n: usize, min: f32, max: f32) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let width = piece.c1 - piece.c0;
    let du = u - piece.c0;
    let du = R::select(width.gt(zero), du / width, du);
    let du = R::select(du.lt(zero), zero, R::select(du.gt(one), one, du));
    let t = divide_by_count(o + du, n);
    let t = R::select(t.lt(one), t, one);
    // On [0, 1], 0 + t · 1 is t itself (t ≥ +0: o + du is never -0).
    let x = if is_unit_domain(min, max) {
        t
    } else {
        R::splat(min) + t * R::splat(max - min)
    };
    let top = R::splat(max.next_down());
    R::select(x.lt(top), x, top)
}

/// Whether `[min, max]` is [0, 1], where the maps between x and the fraction of the domain
/// before it are the identity.
#[inline(always)]
fn is_unit_domain(min: f32, max: f32) -> bool {
    min == 0.0 && max == 1.0
}

/// The density with respect to x of a piece of value `func` in a distribution over
/// `[min, max]` whose values integrate to `func_int` (uniform where they are all zero), for
/// one value or lanes.
#[inline(always)]
fn density_of_piece<R: Real>(func: R, func_int: R, min: f32, max: f32) -> R {
    R::select(
        func_int.gt(R::splat(0.0)),
        func / func_int,
        R::splat(1.0 / (max - min)),
    )
}

/// `a / n`, by a product with 1/n where `n` is a power of two: 1/n is then exact, and `a · 1/n`
/// and `a / n` are both the correctly rounded value of the same real number, so they are the
/// same float (subnormal results included); a division where it is not.
#[inline(always)]
pub(super) fn divide_by_count<R: Real>(a: R, n: usize) -> R {
    if n.is_power_of_two() {
        // 2^-k from its exponent bits (k < 64 < 127: a normal float).
        a * R::splat(f32::from_bits((127 - n.trailing_zeros()) << 23))
    } else {
        a / R::splat(n as f32)
    }
}

/// The guide table of a CDF (Chen and Asau's cutpoints): for `K` buckets (a power of two, a
/// quarter of the pieces), entry `k` of `0..=K` is the number of CDF entries at most `k/K`,
/// and a last entry counts them all. A `u` in bucket `k` has between entries `k` and
/// `k + 1` CDF entries at most it, so a search reads two counts and the few entries between.
fn guide_table(cdf: &[f32]) -> Vec<u32> {
    let buckets = (cdf.len().saturating_sub(1).next_power_of_two() / PIECES_PER_BUCKET).max(1);
    // Counts fit in u32: a distribution of 2^32 pieces would need 32 GiB of entries.
    let count = |x: f32| cdf.partition_point(|&c| c <= x) as u32;
    (0..=buckets)
        .map(|k| count(k as f32 / buckets as f32))
        .chain([cdf.len() as u32])
        .collect()
}

/// A piecewise-constant density on `[min, max]`: `n` equal pieces with values `f[i]`,
/// normalised so that it integrates to one.
///
/// Construction builds the CDF (running sums in `f64`, stored in `f32`); sampling inverts it by
/// search for the piece (a guide table of where each quarter-of-four-pieces' worth of u starts,
/// then the few entries of one bucket) and
/// linear interpolation inside the piece. A function that is
/// zero everywhere is treated as uniform, so that sampling is always defined.
///
/// ```
/// use pathlab_mc::distribution::PiecewiseConstant1D;
/// let d = PiecewiseConstant1D::new(&[1.0, 3.0], 0.0, 1.0).unwrap();
/// let s = d.sample(0.5);          // the CDF is 0.25 at x = 0.5
/// assert_eq!(s.offset, 1);
/// assert!((s.pdf - 1.5).abs() < 1e-6 && (d.pdf(0.25) - 0.5).abs() < 1e-6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant1D {
    /// `n + 1` entries: the CDF at the piece boundaries and the pieces' values.
    entries: Vec<Entry>,
    /// The guide table ([`guide_table`]): the search reads two of its counts, then the few
    /// entries between them, a cache line or two of a long CDF rather than one per halving.
    guide: Vec<u32>,
    min: f32,
    max: f32,
    func_int: f32,
}

impl PiecewiseConstant1D {
    /// The distribution of the values `func` (finite, ≥ 0, at least one) over `[min, max]`.
    pub fn new(func: &[f32], min: f32, max: f32) -> Result<Self> {
        const WHAT: &str = "piecewise-constant distribution";
        check_weights(WHAT, func)?;
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(Error::InvalidParameter {
                what: WHAT,
                message: format!("domain [{min}, {max}] must be a finite, non-empty interval"),
            });
        }
        let n = func.len();
        let width = (max - min) as f64;
        let mut sums = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        sums.push(0.0);
        for &f in func {
            acc += f as f64 * width / n as f64;
            sums.push(acc);
        }
        let func_int = acc;
        let mut cdf: Vec<f32> = if func_int > 0.0 {
            sums.iter().map(|&c| (c / func_int) as f32).collect()
        } else {
            (0..=n).map(|i| (i as f64 / n as f64) as f32).collect()
        };
        cdf[n] = 1.0;
        let entries = cdf
            .iter()
            .zip(func.iter().chain([&0.0]))
            .map(|(&cdf, &func)| Entry { cdf, func })
            .collect();
        Ok(PiecewiseConstant1D {
            entries,
            guide: guide_table(&cdf),
            min,
            max,
            func_int: func_int as f32,
        })
    }

    #[inline]
    fn pieces(&self) -> Pieces<'_> {
        Pieces {
            entries: &self.entries,
            guide: &self.guide,
            min: self.min,
            max: self.max,
            func_int: self.func_int,
        }
    }

    /// The number of pieces.
    pub fn len(&self) -> usize {
        self.entries.len() - 1
    }

    /// Always false: a distribution has at least one piece.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// ∫ f(x) dx over the domain (before normalisation).
    pub fn integral(&self) -> f32 {
        self.func_int
    }

    /// The domain `[min, max]`.
    pub fn domain(&self) -> (f32, f32) {
        (self.min, self.max)
    }

    /// The value of piece `i` as given.
    pub fn value(&self, i: usize) -> f32 {
        self.entries[..self.len()].get(i).map_or(0.0, |e| e.func)
    }

    /// The CDF at the piece boundaries (`len() + 1` values from 0 to 1).
    pub fn cdf(&self) -> impl ExactSizeIterator<Item = f32> + '_ {
        self.entries.iter().map(|e| e.cdf)
    }

    /// A point with density `pdf(x)`, by inverting the CDF at `u` in [0, 1).
    pub fn sample(&self, u: f32) -> PiecewiseSample {
        self.pieces().sample(u)
    }

    /// The density at `x` (0 outside the domain).
    pub fn pdf(&self, x: f32) -> f32 {
        if !(self.min..=self.max).contains(&x) {
            return 0.0;
        }
        let p = self.pieces();
        p.piece_pdf(p.offset_of(x))
    }

    /// The index of the piece containing `x` (clamped to the domain).
    #[inline]
    pub fn offset_of(&self, x: f32) -> usize {
        self.pieces().offset_of(x)
    }

    /// The `u` that [`PiecewiseConstant1D::sample`] maps to `x`: the CDF at `x`.
    pub fn invert_sample(&self, x: f32) -> f32 {
        self.pieces().invert_sample(x)
    }

    /// A piece chosen with probability proportional to its value (uniform if all are zero).
    pub fn sample_discrete(&self, u: f32) -> DiscreteSample {
        let o = self.pieces().find_piece(u);
        let (c0, c1) = (self.entries[o].cdf, self.entries[o + 1].cdf);
        let pmf = c1 - c0;
        let u_remapped = if pmf > 0.0 {
            ((u - c0) / pmf).clamp(0.0, 1.0f32.next_down())
        } else {
            0.0
        };
        DiscreteSample {
            index: o,
            pmf,
            u_remapped,
        }
    }

    /// The probability [`PiecewiseConstant1D::sample_discrete`] gives piece `index`.
    pub fn discrete_pmf(&self, index: usize) -> f32 {
        match (self.entries.get(index), self.entries.get(index + 1)) {
            (Some(e0), Some(e1)) => e1.cdf - e0.cdf,
            _ => 0.0,
        }
    }
}

/// A piecewise-constant density on a rectangle: `nu × nv` cells with values `f[v][u]`.
///
/// Sampled by the marginal-conditional method: first a row `v` from the marginal density
/// p(v) = ∫ f(u, v) du / ∫∫ f, then `u` from the conditional p(u | v) = f(u, v) / ∫ f(u, v) du
/// within that row; the joint density is their product, f(u, v) / ∫∫ f. For environment maps
/// the values are luminance × sin θ so that the density is uniform in solid angle where the map
/// is constant.
///
/// The rows' tables are held in two flat arrays, every row's guide table in one and every
/// row's CDF and values in the other, so that sampling a row of a large table reads a cache
/// line of each.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant2D {
    /// Pieces per row.
    nu: usize,
    /// `nu + 1` entries per row.
    entries: Vec<Entry>,
    /// Guide tables, `guide_len` per row.
    guide: Vec<u32>,
    guide_len: usize,
    /// ∫ f(u, v) du of each row.
    row_integrals: Vec<f32>,
    marginal: PiecewiseConstant1D,
    min: Vec2,
    max: Vec2,
}

impl PiecewiseConstant2D {
    /// The distribution of `func` (row-major, `nu` values per row, `nv` rows) over the
    /// rectangle `[min, max]`.
    pub fn new(func: &[f32], nu: usize, nv: usize, min: Vec2, max: Vec2) -> Result<Self> {
        check_grid("2D piecewise-constant distribution", func, nu, nv)?;
        let mut entries = Vec::with_capacity((nu + 1) * nv);
        let mut guide = Vec::new();
        let mut guide_len = 0;
        let mut row_integrals = Vec::with_capacity(nv);
        for row in func.chunks_exact(nu) {
            let d = PiecewiseConstant1D::new(row, min.x, max.x)?;
            entries.extend_from_slice(&d.entries);
            guide_len = d.guide.len();
            guide.extend_from_slice(&d.guide);
            row_integrals.push(d.func_int);
        }
        let marginal = PiecewiseConstant1D::new(&row_integrals, min.y, max.y)?;
        Ok(PiecewiseConstant2D {
            nu,
            entries,
            guide,
            guide_len,
            row_integrals,
            marginal,
            min,
            max,
        })
    }

    /// Row `v`'s conditional distribution in u.
    #[inline]
    fn row(&self, v: usize) -> Pieces<'_> {
        let n = self.nu + 1;
        Pieces {
            entries: &self.entries[v * n..(v + 1) * n],
            guide: &self.guide[v * self.guide_len..(v + 1) * self.guide_len],
            min: self.min.x,
            max: self.max.x,
            func_int: self.row_integrals[v],
        }
    }

    /// ∫∫ f over the rectangle.
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// The rectangle `(min, max)`.
    pub fn domain(&self) -> (Vec2, Vec2) {
        (self.min, self.max)
    }

    /// A point of the rectangle and its density (per unit area of the rectangle).
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let row = self.marginal.sample(u.y);
        let col = self.row(row.offset).sample(u.x);
        (Vec2::new(col.x, row.x), col.pdf * row.pdf)
    }

    /// The density at `p` (0 outside the rectangle).
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(self.min.x..=self.max.x).contains(&p.x) || !(self.min.y..=self.max.y).contains(&p.y) {
            return 0.0;
        }
        let row = self.row(self.marginal.offset_of(p.y));
        if self.marginal.integral() > 0.0 {
            row.entries[row.offset_of(p.x)].func / self.marginal.integral()
        } else {
            let size = self.max - self.min;
            1.0 / (size.x * size.y)
        }
    }

    /// The `u` that [`PiecewiseConstant2D::sample`] maps to `p`.
    pub fn invert_sample(&self, p: Vec2) -> Vec2 {
        let v = self.marginal.offset_of(p.y);
        Vec2::new(
            self.row(v).invert_sample(p.x),
            self.marginal.invert_sample(p.y),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    #[test]
    fn the_guided_search_counts_what_a_binary_search_counts() {
        let mut rng = Pcg32::new(3, 7);
        for n in [1, 2, 15, 16, 17, 31, 32, 33, 255, 256, 512, 1000] {
            // Runs of zero pieces (flat CDF stretches), a few large pieces and small ones.
            let func: Vec<f32> = (0..n)
                .map(|i| match rng.uniform_f32() {
                    x if x < 0.3 => 0.0,
                    x if x < 0.35 => 1e4 * x,
                    x => x * (i % 7) as f32,
                })
                .collect();
            let d = PiecewiseConstant1D::new(&func, 0.0, 1.0).unwrap();
            let cdf: Vec<f32> = d.cdf().collect();
            let mut us: Vec<f32> = vec![0.0, 1.0, 1.0f32.next_down(), -0.0, f32::NAN];
            for &c in &cdf {
                us.extend([c, c.next_up(), c.next_down()]);
            }
            us.extend((0..2000).map(|_| rng.uniform_f32()));
            for u in us {
                let want = cdf.partition_point(|&c| c <= u);
                assert_eq!(d.pieces().cdf_entries_at_most(u), want, "n = {n}, u = {u}");
            }
        }
    }

    #[test]
    fn the_shortcuts_compute_what_the_divisions_compute() {
        let mut rng = Pcg32::new(9, 2);
        let mut xs: Vec<f32> = vec![0.0, -0.0, 1.0, 1.0f32.next_down(), 1e-40, 1e-45, 0.5, 7.0];
        xs.extend((0..5000).map(|_| rng.uniform_f32()));
        xs.extend((0..5000).map(|_| f32::from_bits(rng.next_u32() & 0x7fff_ffff)));
        for n in (0..63).map(|k| 1usize << k).chain([3, 255, 1000]) {
            for &x in &xs {
                let a = x * (n.min(1 << 20)) as f32;
                assert_eq!(
                    divide_by_count(a, n).to_bits(),
                    (a / n as f32).to_bits(),
                    "{a} / {n}"
                );
            }
        }
        // The unit domain's identities, as `offset_of` and `sample` use them.
        for &x in xs.iter().filter(|x| !x.is_nan()) {
            assert_eq!(((x - 0.0) / (1.0 - 0.0)).to_bits(), x.to_bits(), "{x}");
            // (`sample`'s t = (o + du) / n is never -0: o + du adds to o ≥ +0.)
            if x.is_sign_positive() {
                assert_eq!((0.0 + x * (1.0 - 0.0)).to_bits(), x.to_bits(), "{x}");
            }
        }
    }

    #[test]
    fn a_row_of_the_flat_2d_tables_samples_as_its_own_1d_distribution() {
        let mut rng = Pcg32::new(5, 11);
        let (nu, nv) = (37, 9);
        let func: Vec<f32> = (0..nu * nv)
            .map(|i| {
                if i % 5 == 0 {
                    0.0
                } else {
                    rng.uniform_f32() * (i % 13) as f32
                }
            })
            .collect();
        let (min, max) = (Vec2::new(-1.0, 2.0), Vec2::new(3.0, 2.5));
        let d = PiecewiseConstant2D::new(&func, nu, nv, min, max).unwrap();
        for (v, row) in func.chunks_exact(nu).enumerate() {
            let alone = PiecewiseConstant1D::new(row, min.x, max.x).unwrap();
            for _ in 0..200 {
                let u = rng.uniform_f32();
                assert_eq!(d.row(v).sample(u), alone.sample(u), "row {v}, u = {u}");
                let x = min.x + (max.x - min.x) * rng.uniform_f32();
                assert_eq!(d.row(v).invert_sample(x), alone.invert_sample(x));
                assert_eq!(d.row(v).piece_pdf(d.row(v).offset_of(x)), alone.pdf(x));
            }
        }
    }
}
