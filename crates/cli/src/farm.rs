//! Renders that survive and scale: shards of a render, stopping on signals, and
//! `pathlab merge` (a render's identity and checkpoints are [`pathlab_lab::job`]'s).

use anyhow::Result;
use clap::Args;
use pathlab_render::{film_file, limits};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

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
    crate::flags::within("--exposure", Some(args.exposure), limits::exposure)?;
    // A part at a time: the merge holds the sum and the part being added.
    let mut merged = film_file::Merge::default();
    for p in &args.parts {
        let (h, film) = film_file::read(p)?;
        let name = p.display().to_string();
        merged.add(name, h, film).map_err(anyhow::Error::msg)?;
    }
    let (header, film) = merged.finish().map_err(anyhow::Error::msg)?;
    let (first, [w, h]) = (&header, header.resolution);
    pathlab_lab::outputs::write_film_image(&film, &args.output, &header, args.exposure)?;
    eprintln!(
        "merged {} parts ({} spp, {}x{}); wrote {}",
        args.parts.len(),
        first.spp,
        w,
        h,
        args.output.display()
    );
    Ok(())
}
