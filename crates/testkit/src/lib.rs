//! # pathlab-testkit: what the test suites share
//!
//! A dev-dependency of the crates' tests, not part of pathlab:
//! - [`render`]: renders with independent samples (whose per-pixel variances are honest), the
//!   path tracer at a depth, and the z-tests of an image mean against a known value and of two
//!   images against each other;
//! - [`reference`]: reference images with per-pixel standard errors (Mitsuba 3's renders) and
//!   the comparisons against them: per pixel, on 8 x 8 blocks, of the image mean, and squared
//!   errors;
//! - [`process`]: running a binary the way a user does and reading what it printed, its
//!   one-line errors, and scratch paths.
//!
//! Every tolerance here comes from a standard error: |z| beyond [`render::MAX_Z`] = 4 is an
//! outlier, and at most a fixed small fraction of outliers is allowed.

pub mod process;
pub mod reference;
pub mod render;
