//! # pathlab-mc: the Monte Carlo toolkit
//!
//! The probability and sampling machinery of a renderer, usable on its own: everything here
//! knows nothing about rendering.
//!
//! - [`rng`]: the PCG32 generator and hashing, for reproducible streams per pixel sample;
//! - [`sampler`]: independent, stratified and Owen-scrambled Sobol samplers behind one trait,
//!   whose numbers depend only on `(seed, pixel, sample index, dimension)`;
//! - [`warp`]: maps from the unit square to disks, hemispheres, spheres, cones and triangles,
//!   each with its pdf and its inverse;
//! - [`distribution`]: sampling by inversion (exponential, piecewise-constant 1D and 2D) and
//!   the alias method for discrete choices;
//! - [`estimator`]: running mean and variance, standard errors and confidence intervals, and
//!   the estimator F_N = 1/N Σ f(X_i)/p(X_i);
//! - [`simd`]: the one home of SIMD: eight `f32` lanes ([`simd::lanes`]) and the
//!   [`simd::lanes::Real`] / [`simd::lanes::Vector3`] traits through which the warps (and the
//!   renderer's physics) are written once for one value and for eight, the widths' names, and
//!   the CPU-extension tokens of run-time dispatch;
//! - [`stats`]: chi-square goodness-of-fit tests of samplers against their pdfs, z-tests and
//!   F-tests, used by the test suites of every part of pathlab.
//!
//! Conventions: every sampling routine returns its value and its pdf and has a matching pdf
//! function; pdfs of directions are per unit solid angle, of points per unit area; uniform
//! numbers are `f32` in [0, 1) (24 random bits), estimates are accumulated in `f64`.
//!
//! ```
//! use pathlab_mc::distribution::Exponential;
//! use pathlab_mc::estimator::RunningStats;
//! use pathlab_mc::sampler::{IndependentSampler, Sampler};
//!
//! // Sample the exponential distribution by inversion and check its mean against 1/λ.
//! let exp = Exponential::new(2.0).unwrap();
//! let mut sampler = IndependentSampler::new(1, 42);
//! let mut stats = RunningStats::new();
//! for i in 0..100_000 {
//!     sampler.start_pixel_sample([0, 0], i, 0);
//!     stats.push(exp.sample(sampler.next_1d() as f64));
//! }
//! let z = (stats.mean() - exp.mean()) / stats.std_error();
//! assert!(z.abs() < 4.0);
//! ```
#![deny(missing_docs)]

pub mod distribution;
pub mod error;
pub mod estimator;
pub mod exact;
pub mod named;
pub mod quadrature;
pub mod rng;
pub mod sampler;
pub mod simd;
pub mod stats;
pub mod warp;

pub use error::{Error, Result};

/// The crate README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
