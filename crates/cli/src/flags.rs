//! What several commands' flags share: the scene they work on, how a value is checked against
//! its rule, and the parsers of values that more than one command takes.

use anyhow::{bail, Context, Result};
use clap::Args;
use pathlab_render::desc::SceneDesc;
use pathlab_render::limits;

pub use pathlab_lab::render::within;

/// The scene a command renders, as every such command names it.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// The scene: a file (.xml Mitsuba 3, .pbrt pbrt-v4, .dae the course's COLLADA, .obj, .ply,
    /// .gltf, .glb) or a built-in scene's name (cornell-box).
    #[arg(value_name = "SCENE", default_value = "cornell-box")]
    pub name: String,
    /// A scene parameter, NAME=VALUE, for the `$NAME` references of a Mitsuba scene (its
    /// `<default>`s give the others). Repeat for several.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE")]
    pub define: Vec<String>,
    /// Image size in pixels (default: the scene's). The view is scaled to fit, except for the
    /// course's .dae scenes, whose camera keeps the course viewer's pixel scale: a smaller
    /// size shows a centred crop, a larger one more around it (`render --scale` resizes
    /// those).
    #[arg(short = 'r', long, num_args = 2, value_names = ["W", "H"], allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=limits::MAX_IMAGE_SIDE as i64))]
    pub resolution: Option<Vec<u32>>,
}

impl SceneArgs {
    /// The `-r W H` size (clap takes exactly two values).
    pub fn size(&self) -> Option<[u32; 2]> {
        self.resolution.as_deref().map(|r| [r[0], r[1]])
    }

    /// The `-D NAME=VALUE` parameters.
    pub fn params(&self) -> Result<Vec<(String, String)>> {
        self.define
            .iter()
            .map(|d| match d.split_once('=') {
                Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.to_string())),
                _ => bail!("-D {d}: expected NAME=VALUE"),
            })
            .collect()
    }

    /// The scene at the size asked for; its loader's warnings printed.
    pub fn load(&self) -> Result<SceneDesc> {
        let mut desc = pathlab_scene::load_with(&self.name, &self.params()?)?;
        for w in &desc.warnings {
            eprintln!("warning: {w}");
        }
        pathlab_lab::render::apply_resolution(&mut desc, self.size())?;
        Ok(desc)
    }
}

/// A `--max-depth` value: a number of bounces or `inf` (also `-1`).
pub fn max_depth(text: &str) -> Result<u32> {
    if text.eq_ignore_ascii_case("inf") || text == "-1" {
        return Ok(u32::MAX);
    }
    text.parse::<u32>().with_context(|| {
        format!("--max-depth {text}: expected a number of bounces (0, 1, 2, ...) or inf")
    })
}

/// [`max_depth`] as a clap value parser.
pub fn max_depth_arg(text: &str) -> std::result::Result<u32, String> {
    max_depth(text).map_err(|e| e.to_string())
}

/// A `-n` number of samples: 1 to 2³² - 1.
pub fn sample_count(n: u64) -> Result<u32> {
    match u32::try_from(n) {
        Ok(n) if n > 0 => Ok(n),
        _ => bail!("-n must be between 1 and {}, got {n}", u32::MAX),
    }
}
