//! # pathlab-scene: scenes for the renderer
//!
//! Turns scene sources into the renderer's plain [`SceneDesc`]: the built-in scenes
//! ([`builtin`], compiled into the binary) and files: the CS184 course's COLLADA scenes
//! ([`collada`]), Mitsuba 3 XML ([`mitsuba`]), OBJ and PLY meshes ([`meshfile`]), glTF 2.0
//! ([`gltf_scene`]). [`load`] picks the loader by extension; every loader returns an [`Error`]
//! naming the file, the line and column, and what was expected.
//!
//! ```
//! let desc = pathlab_scene::builtin::load("cornell-box").unwrap();
//! assert_eq!(desc.meshes.iter().map(|m| m.indices.len() / 3).sum::<usize>(), 36);
//! assert_eq!(desc.resolution, [256, 256]);
//! ```
#![deny(missing_docs)]

pub mod builtin;
pub mod collada;
pub mod envmap;
pub mod gltf_scene;
pub mod info;
pub mod meshfile;
pub mod mitsuba;
pub mod pbrt;
mod ply_binary;
pub mod spectrum;
pub mod texture;
mod xml;

pub use pathlab_render::desc::SceneDesc;

use std::path::Path;
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
    /// A file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// A file's content is not what the format expects (`path:line:column:` where the
    /// format's parser gives them, `path:line:` or `path:` where it gives less).
    #[error("{path}{}: {message}", location(*line, *column))]
    Parse {
        /// The file (or built-in source).
        path: String,
        /// Line, from 1 (0 when unknown).
        line: usize,
        /// Column, from 1 (0 when unknown).
        column: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// The file's extension names no format pathlab reads.
    #[error("{path}: unknown scene format (expected .xml, .dae, .pbrt, .pbrt.gz, .obj, .ply, .gltf or .glb, or a built-in scene name: {known})")]
    UnknownFormat {
        /// The file.
        path: String,
        /// Built-in scene names.
        known: String,
    },
}

/// How a sampler named in a scene file maps onto pathlab's samplers.
#[derive(Clone, Copy)]
pub(crate) enum SamplerName {
    /// One of pathlab's own (or what `pathlab export` writes for it).
    Own,
    /// One of the format's samplers that pathlab lacks; another one stands in.
    StandIn,
    /// None of the format's samplers.
    Unknown,
}

/// What a loader of `format` says of a sampler its file names, where `kind` renders in its
/// place: nothing for one of pathlab's own, a note that another sequence converging to the same
/// image renders it otherwise.
pub(crate) fn sampler_note(
    kind: pathlab_render::mc::sampler::SamplerKind,
    name: SamplerName,
    format: &str,
) -> Option<String> {
    use pathlab_render::mc::sampler::SamplerKind;
    let sampler = match kind {
        SamplerKind::Sobol => "Sobol",
        other => other.name(),
    };
    match name {
        SamplerName::Own => None,
        SamplerName::StandIn => Some(format!(
            "rendered with the {sampler} sampler (other noise, the same image)"
        )),
        SamplerName::Unknown => Some(format!(
            "not a {format} sampler; the {sampler} sampler renders the scene"
        )),
    }
}

/// `:line:column`, `:line` or nothing, as far as they are known (0: unknown).
fn location(line: usize, column: usize) -> String {
    match (line, column) {
        (0, _) => String::new(),
        (l, 0) => format!(":{l}"),
        (l, c) => format!(":{l}:{c}"),
    }
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: &Path, e: std::io::Error) -> Self {
        Error::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

/// Loads a scene: a built-in scene's name, or a file whose extension picks the loader.
pub fn load(source: &str) -> Result<SceneDesc, Error> {
    load_with(source, &[])
}

/// [`load`] with scene parameters (`-D name=value`): Mitsuba XML files use them for their
/// `$name` references; for other formats, which have none, they are reported as unused.
pub fn load_with(source: &str, params: &[(String, String)]) -> Result<SceneDesc, Error> {
    let path = Path::new(source);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let mut desc = match ext.as_deref() {
        Some("dae") => collada::load(path),
        Some("obj") => meshfile::load_obj(path),
        Some("ply") => meshfile::load_ply(path),
        Some("xml") => return mitsuba::load_with(path, params),
        Some("gltf") | Some("glb") => gltf_scene::load(path),
        Some("pbrt") => pbrt::load(path),
        Some("gz") if source.to_ascii_lowercase().ends_with(".pbrt.gz") => pbrt::load(path),
        None if builtin::NAMES.contains(&source) => builtin::load(source),
        None if !path.exists() => builtin::load(source),
        _ => Err(Error::UnknownFormat {
            path: source.to_string(),
            known: builtin::NAMES.join(", "),
        }),
    }?;
    for (name, _) in params {
        desc.warnings.push(format!(
            "{source}: parameter '{name}' is not used (only Mitsuba XML scenes take parameters)"
        ));
    }
    Ok(desc)
}
