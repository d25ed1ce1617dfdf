//! # pathlab-render: the renderer core
//!
//! Geometry, acceleration structure, cameras, BSDFs, lights, integrators, film and the parallel
//! render loop, built on [`pathlab_mc`]. This crate is being built up; today it only re-exports
//! the toolkit it builds on.
#![deny(missing_docs)]

pub use pathlab_mc as mc;
