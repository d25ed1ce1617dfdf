//! `pathlab info`: what a scene contains, without rendering it.

use anyhow::Result;
use clap::Args;
use pathlab_lab::info::SceneReport;

/// Raw command-line arguments of `pathlab info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The scene: a file (.xml Mitsuba 3, .pbrt pbrt-v4, .dae the course's COLLADA, .obj, .ply,
    /// .gltf, .glb) or
    /// a built-in scene's name (cornell-box), as `render` takes it (and, as there, the built-in
    /// Cornell box when none is given).
    #[arg(value_name = "SCENE", default_value = "cornell-box")]
    pub scene: String,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let report = SceneReport::of(&args.scene)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report.json())?);
    } else {
        println!("{}", report.text());
    }
    Ok(())
}
