//! Renders that survive and scale: what identifies a render (for checkpoints and shards),
//! stopping on signals, and `pathlab merge`.

use anyhow::{bail, Context, Result};
use clap::Args;
use pathlab_render::desc::SceneDesc;
use pathlab_render::film_file::{self, FilmHeader};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// A streaming FNV-1a hash of formatted text.
struct Hasher(u64);

impl std::fmt::Write for Hasher {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for &b in s.as_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        Ok(())
    }
}

/// A key for the scene, every setting that changes the image (`settings`) and the program's
/// version: checkpoints and shards are accepted only by a render with the same key.
pub fn render_key(desc: &SceneDesc, settings: &str) -> String {
    let mut h = Hasher(0xcbf2_9ce4_8422_2325);
    // The scene as the renderer gets it (after every command-line change), then the
    // settings, and the program's version (another version may sample differently).
    let _ = write!(h, "{desc:?}|{settings}|{}", env!("CARGO_PKG_VERSION"));
    format!("{:016x}", h.0)
}

/// The header of a film file for this render.
pub fn header(
    desc: &SceneDesc,
    key: &str,
    description: &str,
    seed: u64,
    spp: u32,
    range: [u32; 2],
) -> FilmHeader {
    FilmHeader {
        resolution: desc.resolution,
        key: key.to_string(),
        description: description.to_string(),
        seed,
        spp,
        range,
        writer: format!("pathlab {}", env!("CARGO_PKG_VERSION")),
    }
}

/// `--shard I/N` as the sample range of shard I (from 0) of N over `spp` samples.
pub fn shard_range(text: &str, spp: u32) -> Result<[u32; 2]> {
    let (i, n) = text
        .split_once('/')
        .and_then(|(a, b)| Some((a.trim().parse::<u64>().ok()?, b.trim().parse::<u64>().ok()?)))
        .with_context(|| format!("--shard {text}: expected I/N, such as 0/4"))?;
    if n == 0 || i >= n {
        bail!("--shard {text}: need 0 <= I < N");
    }
    if n > spp as u64 {
        bail!("--shard {text}: {n} shards of {spp} samples per pixel would leave some empty");
    }
    let at = |k: u64| (k * spp as u64 / n) as u32;
    Ok([at(i), at(i + 1)])
}

/// Checks that the film file `path` (header `h`) belongs to this render.
pub fn check_matches(path: &std::path::Path, h: &FilmHeader, ours: &FilmHeader) -> Result<()> {
    let p = path.display();
    if h.resolution != ours.resolution {
        bail!(
            "{p}: the film is {}x{}, this render {}x{}",
            h.resolution[0],
            h.resolution[1],
            ours.resolution[0],
            ours.resolution[1]
        );
    }
    if h.key != ours.key {
        bail!(
            "{p}: it belongs to another scene or settings ({}), not this render's ({})",
            h.description,
            ours.description
        );
    }
    if h.seed != ours.seed || h.spp != ours.spp {
        bail!(
            "{p}: seed {} and {} spp, this render seed {} and {} spp",
            h.seed,
            h.spp,
            ours.seed,
            ours.spp
        );
    }
    if h.range != ours.range {
        bail!(
            "{p}: samples {}..{}, this render {}..{}",
            h.range[0],
            h.range[1],
            ours.range[0],
            ours.range[1]
        );
    }
    Ok(())
}

/// The signals that stop a render: SIGINT and SIGTERM set `cancel`; SIGTERM also sets
/// `terminated` (exit status 143 instead of 130).
pub struct Signals {
    /// Set by either signal.
    pub cancel: Arc<AtomicBool>,
    /// Set by SIGTERM.
    pub terminated: Arc<AtomicBool>,
}

impl Signals {
    /// Registers the handlers (a failure to register leaves the default behaviour).
    pub fn install() -> Signals {
        let s = Signals {
            cancel: Arc::new(AtomicBool::new(false)),
            terminated: Arc::new(AtomicBool::new(false)),
        };
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            let _ = signal_hook::flag::register(sig, Arc::clone(&s.cancel));
        }
        let _ =
            signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&s.terminated));
        s
    }
}

/// Raw command-line arguments of `pathlab merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The merged image: .exr (linear, with variance.R/G/B and samples.Y layers), .png or
    /// .plf (the merged film, exact).
    pub output: PathBuf,
    /// The shards' films (.plf, from `pathlab render --shard I/N -o PART.plf`).
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Exposure in stops applied before PNG encoding.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
}

/// Runs `pathlab merge`: checks that the parts are of one render and cover its samples once,
/// then adds them (exactly: the result is the single render's film to the bit).
pub fn run_merge(args: &MergeArgs) -> Result<()> {
    let mut parts = Vec::new();
    for p in &args.parts {
        let (h, film) = film_file::read(p)?;
        parts.push((p.display().to_string(), h, film));
    }
    let (header, film) = film_file::merge(&parts).map_err(anyhow::Error::msg)?;
    let (first, [w, h]) = (&header, header.resolution);
    crate::render_cmd::write_film_image(&film, &args.output, &header, args.exposure)?;
    eprintln!(
        "merged {} parts ({} spp, {}x{}); wrote {}",
        parts.len(),
        first.spp,
        w,
        h,
        args.output.display()
    );
    Ok(())
}
