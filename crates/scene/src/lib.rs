//! # pathlab-scene: scene loaders
//!
//! Turns files (CS184 COLLADA, Mitsuba 3 XML, OBJ/PLY/glTF) and the built-in scenes into the
//! renderer's plain scene description. This crate is being built up; today it only re-exports
//! the renderer core it feeds.
#![deny(missing_docs)]

pub use pathlab_render as render;
