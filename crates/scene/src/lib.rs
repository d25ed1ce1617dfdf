//! # pathlab-scene: scenes for the renderer
//!
//! Turns scene sources into the renderer's plain [`SceneDesc`]. Today: the built-in scenes
//! ([`builtin`]), compiled into the binary so that `pathlab render` needs no files.
//!
//! ```
//! let desc = pathlab_scene::builtin::load("cornell-box").unwrap();
//! assert_eq!(desc.meshes.iter().map(|m| m.indices.len() / 3).sum::<usize>(), 36);
//! assert_eq!(desc.resolution, [256, 256]);
//! ```
#![deny(missing_docs)]

pub mod builtin;

pub use pathlab_render::desc::SceneDesc;

use thiserror::Error;

/// What went wrong loading a scene.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// No built-in scene has this name.
    #[error("unknown built-in scene '{name}' (built-in scenes: {known})")]
    UnknownBuiltin {
        /// The name asked for.
        name: String,
        /// The names that exist.
        known: String,
    },
    /// A file could not be parsed.
    #[error("{path}: {message}")]
    Parse {
        /// The file (or built-in source).
        path: String,
        /// What was expected.
        message: String,
    },
}
