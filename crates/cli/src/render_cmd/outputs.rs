//! The outputs `-o` names, checked before rendering (writing them is
//! [`pathlab_lab::outputs`]'s).

use super::args::RenderArgs;
use anyhow::{bail, Result};
use pathlab_lab::outputs::{check_writable, output_format, OutputFormat};
use std::path::{Path, PathBuf};

/// The outputs `-o` names (default: the scene's name as PNG), each checked writable, and the
/// checkpoint's.
pub(super) fn checked_outputs(args: &RenderArgs) -> Result<(Vec<PathBuf>, Vec<OutputFormat>)> {
    let outputs = if args.output.is_empty() {
        let stem = Path::new(&args.scene.name)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("render");
        vec![PathBuf::from(format!("{stem}.png"))]
    } else {
        args.output.clone()
    };
    let formats = outputs
        .iter()
        .map(|o| output_format(o))
        .collect::<Result<Vec<_>>>()?;
    for o in outputs.iter().chain(&args.checkpoint) {
        check_writable(o)?;
    }
    if args.shard.is_some() && !formats.contains(&OutputFormat::Film) {
        bail!("--shard: write the part as a film (-o PART.plf) so that `pathlab merge` can add the parts exactly");
    }
    Ok((outputs, formats))
}
