//! [`PiecewiseConstantAlias2D`]: a piecewise-constant density on the unit square, sampled by
//! alias tables in constant time.

use super::alias::vose_bins;
use super::check_grid;
use super::piecewise::{divide_by_count, step_into_piece};
use crate::error::{Error, Result};
use crate::simd::lanes::{F8, W};
use glam::Vec2;
use std::hint::select_unpredictable;

/// The largest float below 1: positions within a bin stay in [0, 1).
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// A bin of the rows' alias table: the probability of keeping its own row, and the alias.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct RowBin {
    q: f32,
    alias: u32,
}

/// A bin of a row's alias table, with the densities of both cells it may give, so that a
/// sample reads one 16-byte bin of its row and nothing else there.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(16))]
struct CellBin {
    /// The probability of keeping this bin's own cell.
    q: f32,
    /// The cell given otherwise.
    alias: u32,
    /// The density of this bin's own cell ([`PiecewiseConstantAlias2D::pdf`] there).
    density: f32,
    /// The density of the alias cell.
    alias_density: f32,
}

/// A piecewise-constant density on the unit square: `nu × nv` cells of values `f[v][u]`,
/// with density f(u, v) / ∫∫ f (uniform where every value is zero), the density
/// [`super::PiecewiseConstant2D`] has on the unit square.
///
/// Sampled as that one is, a row then a cell within the row, but each choice by an alias
/// table ([`super::AliasTable`], Vose's construction) instead of a search of a CDF: `u.y`
/// picks one of the `nv` equal bins of the rows' table and, by where it falls in the bin,
/// the bin's own row or its alias; the fraction of the bin that chose the row, stretched to
/// [0, 1), is the point's place within the row. Then `u.x` does the same among the row's cells.
/// Each cell is reached with its probability, from a set of numbers of total length P for a
/// cell of probability P, as under inversion (so the points within a cell are as finely
/// spaced); but the map from `u` to cells does not keep neighbouring numbers in neighbouring
/// cells, as inversion does: stratified numbers stay stratified over the cells' counts, not
/// over the square.
///
/// A sample reads two bins, one of the rows' table (`nv` bins, small, usually in cache) and one
/// of its row's, which holds the density of both cells it may give: for large tables, such as
/// environment maps, one cache line of the big table per sample, where a CDF search reads
/// several, one after another.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstantAlias2D {
    nu: usize,
    nv: usize,
    rows: Vec<RowBin>,
    /// `nu` bins per row, row-major.
    cells: Vec<CellBin>,
    /// ∫∫ f over the unit square: the mean value.
    integral: f32,
}

impl PiecewiseConstantAlias2D {
    /// The distribution of `func` (row-major, `nu` finite, non-negative values per row, `nv`
    /// rows) over the unit square.
    pub fn new(func: &[f32], nu: usize, nv: usize) -> Result<Self> {
        const WHAT: &str = "2D piecewise-constant alias distribution";
        check_grid(WHAT, func, nu, nv)?;
        if nu.max(nv) > u32::MAX as usize {
            return Err(Error::InvalidParameter {
                what: WHAT,
                message: format!("{nu} x {nv} cells: at most 2^32 - 1 across and down"),
            });
        }
        let row_sums: Vec<f64> = func
            .chunks_exact(nu)
            .map(|row| row.iter().map(|&f| f as f64).sum())
            .collect();
        let total: f64 = row_sums.iter().sum();
        if !total.is_finite() {
            return Err(Error::InvalidParameter {
                what: WHAT,
                message: "the values' sum overflows".to_string(),
            });
        }
        let integral = (total / (nu * nv) as f64) as f32;
        // The density of a cell of value f: f / ∫∫ f, the division `pdf` users may repeat
        // from the value (an environment map does, from its texels); uniform where all are 0.
        let density = |f: f32| if integral > 0.0 { f / integral } else { 1.0 };
        let rows = vose_bins(shares(row_sums.iter().copied(), nv, total))
            .into_iter()
            .map(|(q, alias)| RowBin {
                q: q as f32,
                alias: alias as u32,
            })
            .collect();
        let mut cells = Vec::with_capacity(nu * nv);
        for (row, &sum) in func.chunks_exact(nu).zip(&row_sums) {
            let bins = vose_bins(shares(row.iter().map(|&f| f as f64), nu, sum));
            cells.extend(
                bins.into_iter()
                    .enumerate()
                    .map(|(own, (q, alias))| CellBin {
                        q: q as f32,
                        alias: alias as u32,
                        density: density(row[own]),
                        alias_density: density(row[alias]),
                    }),
            );
        }
        Ok(PiecewiseConstantAlias2D {
            nu,
            nv,
            rows,
            cells,
            integral,
        })
    }

    /// The number of cells across and down.
    pub fn size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }

    /// ∫∫ f over the unit square (0 where every value is zero).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The density at `p` (0 outside the unit square).
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
            return 0.0;
        }
        let (col, row) = (offset_of(p.x, self.nu), offset_of(p.y, self.nv));
        self.cells[row * self.nu + col].density
    }

    /// A point of the unit square and its density, from `u` in [0, 1)².
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let at = self.locate(u);
        self.finish(&at, self.cells[at.cell])
    }

    /// [`PiecewiseConstantAlias2D::sample`] of the lanes `active` of (`u[0]`, `u[1]`), each
    /// lane by the very steps of that function (the other lanes give zeros): the points'
    /// coordinates and densities. They run as three passes over the lanes, the rows chosen,
    /// the row's bins read, the cells chosen, so that the reads of the large table (most of
    /// the time a sample takes, as cache misses) are issued together, none behind a choice.
    pub fn sample_lanes(&self, u: [F8; 2], active: u32) -> ([F8; 2], F8) {
        let lanes = || (0..W).filter(move |i| active & (1 << i) != 0);
        let mut at = [Located::default(); W];
        for i in lanes() {
            at[i] = self.locate(Vec2::new(u[0].0[i], u[1].0[i]));
        }
        let mut bins = [CellBin::default(); W];
        for i in lanes() {
            bins[i] = self.cells[at[i].cell];
        }
        let mut point = [F8::splat(0.0); 2];
        let mut pdf = F8::splat(0.0);
        for i in lanes() {
            let (p, density) = self.finish(&at[i], bins[i]);
            (point[0].0[i], point[1].0[i], pdf.0[i]) = (p.x, p.y, density);
        }
        (point, pdf)
    }

    /// Asks memory for the bins of the large table that [`PiecewiseConstantAlias2D::sample_lanes`]
    /// will read for the lanes `active` of `u`, for a caller that knows the numbers some
    /// time before it samples.
    pub fn prefetch_lanes(&self, u: [F8; 2], active: u32) {
        for i in (0..W).filter(|i| active & (1 << i) != 0) {
            let at = self.locate(Vec2::new(u[0].0[i], u[1].0[i]));
            crate::simd::prefetch(&self.cells[at.cell]);
        }
    }

    /// The first half of a sample from `u`: the row, from the rows' table, and the bin of the
    /// row's table that `u.x` falls in.
    #[inline(always)]
    fn locate(&self, u: Vec2) -> Located {
        let (bin, up) = bin_of(u.y, self.nv);
        let RowBin { q, alias } = self.rows[bin];
        let (row, y, _) = choose(q, up, bin, alias as usize);
        let (bin, up_x) = bin_of(u.x, self.nu);
        Located {
            row,
            y,
            bin,
            up_x,
            cell: row * self.nu + bin,
        }
    }

    /// The second half of a sample: the cell from `at`'s bin, whose contents are `bin`, and
    /// the point and its density.
    #[inline(always)]
    fn finish(&self, at: &Located, bin: CellBin) -> (Vec2, f32) {
        let (col, x, own) = choose(bin.q, at.up_x, at.bin, bin.alias as usize);
        let density = select_unpredictable(own, bin.density, bin.alias_density);
        let p = Vec2::new(
            point_in_cell(x, col, self.nu),
            point_in_cell(at.y, at.row, self.nv),
        );
        (p, density)
    }
}

/// Where a sample stands after its row is chosen ([`PiecewiseConstantAlias2D::locate`]).
#[derive(Clone, Copy, Default)]
struct Located {
    /// The row and the place within it, in [0, 1).
    row: usize,
    y: f32,
    /// The bin of the row's table `u.x` falls in, where in it, and the bin's index in the
    /// whole table.
    bin: usize,
    up_x: f32,
    cell: usize,
}

/// The `n` values of a table summing to `sum`, each as its share of the table times `n`, so
/// that they average 1 ([`vose_bins`]' input); all 1 where the values are all zero.
fn shares(values: impl Iterator<Item = f64>, n: usize, sum: f64) -> Vec<f64> {
    if sum > 0.0 {
        values.map(|v| v / sum * n as f64).collect()
    } else {
        vec![1.0; n]
    }
}

/// The bin of `n` equal bins over [0, 1) that `u` falls in, and where in it, in [0, 1) (`u`
/// outside [0, 1) is clamped; NaN counts as 0).
#[inline(always)]
fn bin_of(u: f32, n: usize) -> (usize, f32) {
    let scaled = u * n as f32;
    // `as` saturates: NaN and negatives give bin 0.
    let bin = (scaled as usize).min(n - 1);
    // Not `clamp`, which keeps a NaN: `max` turns it into 0.
    #[allow(clippy::manual_clamp)]
    let up = (scaled - bin as f32).max(0.0).min(ONE_BELOW);
    (bin, up)
}

/// The choice of an alias bin that keeps its own outcome `own` with probability `q` and gives
/// `alias` otherwise, from `up`, where in the bin the number fell: the outcome, `up` stretched
/// back to [0, 1) over the part of the bin that chose it, and whether it is `own`. Selects, not
/// branches: the choice is a coin toss the branch predictor cannot learn.
#[inline(always)]
fn choose(q: f32, up: f32, own: usize, alias: usize) -> (usize, f32, bool) {
    let keep = up < q;
    // Where `keep` is false, q < 1 (up < 1 ≤ q would keep), so 1 - q > 0.
    let t = select_unpredictable(keep, up / q, (up - q) / (1.0 - q));
    (
        select_unpredictable(keep, own, alias),
        t.min(ONE_BELOW),
        keep,
    )
}

/// The cell of `n` equal cells over [0, 1] that `x` lies in (clamped to the square).
#[inline(always)]
fn offset_of(x: f32, n: usize) -> usize {
    ((x * n as f32) as usize).min(n - 1)
}

/// The point at `t` in [0, 1) across cell `o` of `n`, below 1, nudged back into the cell where
/// rounding put it on the next one's edge (so that [`PiecewiseConstantAlias2D::pdf`] there is the
/// density the sample returned).
#[inline(always)]
fn point_in_cell(t: f32, o: usize, n: usize) -> f32 {
    let x = divide_by_count(o as f32 + t, n).min(ONE_BELOW);
    if offset_of(x, n) == o {
        x
    } else {
        step_into_piece(x, o, |x| offset_of(x, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    #[test]
    fn every_sample_lies_in_the_cell_whose_density_it_returns() {
        // Power-of-two and other sizes; a zero row and zero cells; numbers at the edges.
        for (nu, nv) in [(512, 255), (7, 3), (1, 1), (13, 64)] {
            let mut rng = Pcg32::new(nu as u64, nv as u64);
            let func: Vec<f32> = (0..nu * nv)
                .map(|i| {
                    if i % 7 == 2 || (i / nu) == nv / 2 && nv > 1 {
                        0.0
                    } else {
                        rng.uniform_f32() * 10.0
                    }
                })
                .collect();
            let d = PiecewiseConstantAlias2D::new(&func, nu, nv).unwrap();
            let edges = [0.0, ONE_BELOW, 0.5, 1.0, -0.0, f32::NAN];
            let mut us: Vec<Vec2> = (0..20_000)
                .map(|_| Vec2::new(rng.uniform_f32(), rng.uniform_f32()))
                .collect();
            us.extend(
                edges
                    .iter()
                    .flat_map(|&a| edges.iter().map(move |&b| Vec2::new(a, b))),
            );
            for u in us {
                let (p, pdf) = d.sample(u);
                assert!(pdf > 0.0, "{u:?} gave a cell of density 0 in {nu} x {nv}");
                assert!(
                    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                    "{p:?}"
                );
                assert_eq!(d.pdf(p).to_bits(), pdf.to_bits(), "{u:?} -> {p:?}");
            }
        }
    }

    #[test]
    fn the_lanes_sample_what_one_sample_at_a_time_gives() {
        // Sizes that divide by a product (powers of two) and by a division, a single cell, and
        // zero cells; numbers at and beyond the edges, NaN included, in some lanes.
        let below_one = 1.0 - f32::EPSILON / 2.0;
        let edges = F8([0.0, below_one, 0.5, 1.0, -0.0, f32::NAN, -0.5, 1e-9]);
        for (nu, nv) in [(40, 20), (64, 32), (1, 1), (7, 3)] {
            let func: Vec<f32> = (0..nu * nv).map(|i| ((i * 37) % 11) as f32).collect();
            let d = PiecewiseConstantAlias2D::new(&func, nu, nv).unwrap();
            let mut rng = Pcg32::new(5, nu as u64);
            for round in 0..400 {
                let active = match round % 5 {
                    0 => 0xff,
                    1 => 0,
                    2 => 0x01,
                    _ => rng.next_u32() & 0xff,
                };
                let mut u = [(); 2].map(|_| F8(std::array::from_fn(|_| rng.uniform_f32())));
                match round % 4 {
                    0 => u = [edges, F8(std::array::from_fn(|i| edges.0[7 - i]))],
                    1 => u[1] = edges,
                    _ => {}
                }
                // Asking for the bins changes nothing the lanes then compute (and indexes the
                // table as they do, edges included).
                d.prefetch_lanes(u, active);
                let (p, pdf) = d.sample_lanes(u, active);
                for i in 0..W {
                    let (one, one_pdf) = if active & (1 << i) != 0 {
                        d.sample(Vec2::new(u[0].0[i], u[1].0[i]))
                    } else {
                        (Vec2::ZERO, 0.0)
                    };
                    assert_eq!(
                        [p[0].0[i], p[1].0[i], pdf.0[i]].map(f32::to_bits),
                        [one.x, one.y, one_pdf].map(f32::to_bits),
                        "{nu} x {nv}, lane {i} of {u:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn all_zero_values_give_the_uniform_density() {
        let d = PiecewiseConstantAlias2D::new(&[0.0; 6], 3, 2).unwrap();
        assert_eq!(d.integral(), 0.0);
        assert_eq!(d.sample(Vec2::new(0.3, 0.9)).1, 1.0);
        assert_eq!(d.pdf(Vec2::new(0.9, 0.1)), 1.0);
        assert_eq!(d.pdf(Vec2::new(1.5, 0.1)), 0.0);
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(PiecewiseConstantAlias2D::new(&[1.0; 5], 2, 3).is_err());
        assert!(PiecewiseConstantAlias2D::new(&[], 0, 0).is_err());
        assert!(PiecewiseConstantAlias2D::new(&[1.0, -1.0], 2, 1).is_err());
        assert!(PiecewiseConstantAlias2D::new(&[1.0, f32::NAN], 2, 1).is_err());
        assert!(PiecewiseConstantAlias2D::new(&[f32::MAX; 4], 2, 2).is_ok());
    }
}
