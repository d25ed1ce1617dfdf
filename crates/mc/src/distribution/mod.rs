//! Distributions sampled by the inversion method, and discrete choices.
//!
//! - [`Exponential`]: x = -ln(1 - U)/λ, the textbook example of inverting a CDF.
//! - [`PiecewiseConstant1D`]: any tabulated non-negative function on an interval, normalised
//!   into a pdf; its CDF is built once and inverted by binary search. Continuous and discrete
//!   sampling.
//! - [`PiecewiseConstant2D`]: a tabulated function on a rectangle, sampled by a marginal
//!   distribution over rows and a conditional one within the chosen row (what environment-map
//!   importance sampling uses).
//! - [`PiecewiseConstantAlias2D`]: the same density on the unit square, the row and the cell
//!   chosen by alias tables in constant time (environment maps: one cache line of a large
//!   table per sample).
//! - [`AliasTable`]: O(1) sampling of a discrete distribution (Walker's alias method, built by
//!   Vose's algorithm), e.g. choosing a light in proportion to its power.
//!
//! Every `sample` returns the value *and* its pdf (or pmf), and every distribution has a
//! matching `pdf` so that the two can be checked against each other.

mod alias;
mod alias2d;
mod exponential;
mod piecewise;

pub use alias::{AliasSample, AliasTable};
pub use alias2d::PiecewiseConstantAlias2D;
pub use exponential::Exponential;
pub use piecewise::{DiscreteSample, PiecewiseConstant1D, PiecewiseConstant2D, PiecewiseSample};

use crate::error::{Error, Result};

/// Checks that `func` is a grid of `nu` × `nv` values (both at least 1), each finite and
/// non-negative.
pub(crate) fn check_grid(what: &'static str, func: &[f32], nu: usize, nv: usize) -> Result<()> {
    if nu == 0 || nv == 0 || func.len() != nu.saturating_mul(nv) {
        return Err(Error::InvalidParameter {
            what,
            message: format!(
                "expected {nu} x {nv} = {} values, got {}",
                nu.saturating_mul(nv),
                func.len()
            ),
        });
    }
    check_weights(what, func)
}

/// Checks that every value is finite and non-negative.
pub(crate) fn check_weights<T: Copy + Into<f64>>(what: &'static str, values: &[T]) -> Result<()> {
    if values.is_empty() {
        return Err(Error::Empty { what });
    }
    for (index, &v) in values.iter().enumerate() {
        let value: f64 = v.into();
        if !value.is_finite() || value < 0.0 {
            return Err(Error::InvalidValue { what, index, value });
        }
    }
    Ok(())
}
