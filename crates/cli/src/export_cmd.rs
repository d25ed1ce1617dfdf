//! `pathlab export`: a scene, from any format pathlab reads, written as Mitsuba 3 XML.

use crate::flags::SceneArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab export`.
#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The Mitsuba 3 XML file to write; its meshes go to the folder NAME-meshes beside it
    /// (binary PLY).
    #[arg(short = 'o', long, value_name = "FILE.xml")]
    pub output: PathBuf,
}

/// Runs `pathlab export`.
pub fn run(args: &ExportArgs) -> Result<()> {
    let desc = args.scene.load()?;
    let warnings = pathlab_scene::mitsuba::export::write_mitsuba(&desc, &args.output)
        .with_context(|| args.scene.name.clone())?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "{}: wrote {} ({} meshes, {} spheres, {} materials)",
        args.scene.name,
        args.output.display(),
        desc.meshes.len(),
        desc.spheres.len(),
        desc.materials.len()
    );
    Ok(())
}
