//! pathlab's experiments as functions that return data, for the command line, a notebook or a
//! viewer to present:
//! - [`sample`]: a distribution's samples against its exact pdf (moments, chi-square fit);
//! - [`integrate`]: Monte Carlo integration of an expression ([`expr`]) over a box, with an
//!   error that holds for every sampler, and the samplers' convergence study;
//! - [`compare`]: strategies side by side on one scene (variance, RMSE, efficiency);
//! - [`converge`]: a scene's error against a reference as samples grow, per way of sampling;
//! - [`info`]: what a scene contains and what building it costs;
//! - [`images`]: image metrics (RMSE, relative MSE) and the check that a reference belongs to
//!   a render;
//! - [`plot`]: the plots of all of them (PNG or SVG);
//! - [`render`]: a render as its caller asks for it and as the scene completes it, and its
//!   summary;
//! - [`job`]: a render as a job: its film files' identity, checkpoints, progressive stops;
//! - [`outputs`]: a render's images written (EXR with AOV layers, PNG, film files, heat maps).

pub mod compare;
pub mod converge;
pub mod expr;
pub mod images;
pub mod info;
pub mod integrate;
pub mod job;
pub mod outputs;
pub mod plot;
pub mod render;
pub mod sample;
