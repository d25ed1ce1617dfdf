//! Renders that survive and scale: shards of a render, stopping on signals, and
//! `pathlab merge` (a render's identity and checkpoints are [`pathlab_lab::job`]'s).

use anyhow::Result;
use clap::Args;
use pathlab_render::{film_file, limits};
use std::path::{Path, PathBuf};
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
    /// The merged image, then the shards' films: `pathlab merge OUT PART...`. With `-o OUT`,
    /// every file named here is a part. The shards' films are .plf files from `pathlab render
    /// --shard I/N -o PART.plf`.
    #[arg(required = true, value_name = "FILES")]
    pub files: Vec<PathBuf>,
    /// The merged image (instead of the first file): .exr (linear, with variance.R/G/B and
    /// samples.Y layers), .png or .plf (the merged film, exact).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Exposure in stops applied before PNG encoding.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
}

/// Runs `pathlab merge`: checks that the parts are of one render and cover its samples once,
/// then adds them (exactly: the result is the single render's film to the bit).
pub fn run_merge(args: &MergeArgs) -> Result<()> {
    crate::flags::within("--exposure", Some(args.exposure), limits::exposure)?;
    let (output, parts) = merge_files(args)?;
    // A part at a time: the merge holds the sum and the part being added.
    let mut merged = film_file::Merge::default();
    for p in parts {
        let (h, film) = film_file::read(p)?;
        let name = p.display().to_string();
        merged.add(name, h, film).map_err(anyhow::Error::msg)?;
    }
    let (header, film) = merged.finish().map_err(anyhow::Error::msg)?;
    let (first, [w, h]) = (&header, header.resolution);
    pathlab_lab::outputs::write_film_image(&film, output, &header, args.exposure)?;
    eprintln!(
        "merged {} parts ({} spp, {}x{}); wrote {}",
        parts.len(),
        first.spp,
        w,
        h,
        output.display()
    );
    Ok(())
}

/// The merge's output and its parts: `-o OUT` and every file, or the first file and the
/// rest. An output that is also a part is refused: writing it would destroy that part.
fn merge_files(args: &MergeArgs) -> Result<(&Path, &[PathBuf])> {
    let (output, parts) = match &args.output {
        Some(out) => (out.as_path(), args.files.as_slice()),
        None => match args.files.as_slice() {
            [out, parts @ ..] if !parts.is_empty() => (out.as_path(), parts),
            _ => anyhow::bail!(
                "pathlab merge: name the merged image and at least one part: `pathlab merge OUT.exr PART.plf...` or `pathlab merge -o OUT.exr PART.plf...`"
            ),
        },
    };
    let same_file = |p: &Path| match (output.canonicalize(), p.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => output == p,
    };
    if let Some(p) = parts.iter().find(|p| same_file(p)) {
        anyhow::bail!(
            "pathlab merge: the output {} is also one of the parts; writing it would destroy that part (the output comes first, or after -o)",
            p.display()
        );
    }
    Ok((output, parts))
}
