//! # pathlab-reference-tests: pathlab's images against other renderers'
//!
//! This crate holds only tests (`tests/`): renders of scene files, loaded by `pathlab-scene`
//! and rendered by `pathlab-render`, judged against reference images that other renderers
//! made, with their standard errors where the references have them:
//! - `cornell_reference`: the built-in Cornell box at four depths, every direct-lighting
//!   strategy, and the reference scenes (rough, spheres, thin lens, sky) against Mitsuba 3;
//! - `cornell_adaptive`: the adaptive sampling rules against the same references;
//! - `mitsuba_suite`: Mitsuba 3's own render regression suite, by its own rule;
//! - `bitterli`: Bitterli's pbrt-v4 scenes against his Tungsten renders.
//!
//! The first three are the full tier (`--features pathlab-reference-tests/full`); the
//! references are in `tests/data` at the repository's root, each folder with a README saying
//! where it came from.
