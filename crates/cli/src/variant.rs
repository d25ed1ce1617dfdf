//! Builds of pathlab for newer CPUs, chosen at run time.
//!
//! The `pathlab` binary is built for the baseline x86-64 CPU, with its hottest kernels (box
//! and triangle tests, the lanes' shading, the samplers' draws) compiled a second time for
//! AVX2 and AVX-512 and chosen at run time. The rest of the code (the path tracer's
//! scheduling, cameras, lights, the film) gains from the newer instruction sets as well, which
//! only a whole build with `-C target-cpu` gives. `bash deploy/build-variants.sh` makes such
//! builds, `pathlab-x86-64-v4` (AVX-512) and `pathlab-x86-64-v3` (AVX2), beside `pathlab`;
//! when `pathlab` starts, it runs the best one this CPU can execute in its place, with the
//! same arguments. Every variant computes the same images to the bit (the same operations:
//! Rust never fuses a product and a sum on its own, and the library functions are the same),
//! which the script checks before it installs them.
//!
//! A variant is skipped when it is older than `pathlab` itself (a stale build beside a newer
//! one), when `PATHLAB_NO_VARIANT` is set, and, for the AVX-512 one, when `PATHLAB_NO_AVX512`
//! is (which turns the AVX-512 kernels off: the AVX-512 build would use those instructions
//! everywhere).

/// An instruction-set level: its name (as `-C target-cpu` takes it) and whether this CPU
/// runs its code.
#[cfg(all(target_arch = "x86_64", unix))]
type Level = (&'static str, fn() -> bool);

/// The levels a variant may be built for, best first (x86-64 psABI levels 3 and 4).
#[cfg(all(target_arch = "x86_64", unix))]
const LEVELS: [Level; 2] = [("x86-64-v4", has_v4), ("x86-64-v3", has_v3)];

/// Whether this CPU runs x86-64-v3 code.
#[cfg(all(target_arch = "x86_64", unix))]
fn has_v3() -> bool {
    pathlab_mc::simd::runs_x86_64_v3()
}

/// Whether this CPU runs x86-64-v4 code, and AVX-512 is not turned off.
#[cfg(all(target_arch = "x86_64", unix))]
fn has_v4() -> bool {
    std::env::var_os("PATHLAB_NO_AVX512").is_none() && pathlab_mc::simd::runs_x86_64_v4()
}

/// The level this binary was built for: `baseline`, or the variant's level.
pub const BUILD_LEVEL: &str = if cfg!(all(target_arch = "x86_64", target_feature = "avx512f")) {
    "x86-64-v4"
} else if cfg!(all(target_arch = "x86_64", target_feature = "avx2")) {
    "x86-64-v3"
} else {
    "baseline"
};

/// `pathlab --version`: the package's version and the build's level.
pub const VERSION: &str = if cfg!(all(target_arch = "x86_64", target_feature = "avx512f")) {
    concat!(env!("CARGO_PKG_VERSION"), " (x86-64-v4)")
} else if cfg!(all(target_arch = "x86_64", target_feature = "avx2")) {
    concat!(env!("CARGO_PKG_VERSION"), " (x86-64-v3)")
} else {
    concat!(env!("CARGO_PKG_VERSION"), " (baseline)")
};

/// Runs the best variant beside this binary in its place, if there is one this CPU can run;
/// returns (and this binary goes on) where there is none, or where starting it failed (said
/// on stderr).
pub fn exec_best() {
    #[cfg(all(target_arch = "x86_64", unix))]
    if BUILD_LEVEL == "baseline" && std::env::var_os("PATHLAB_NO_VARIANT").is_none() {
        if let Some(path) = best_beside_this() {
            use std::os::unix::process::CommandExt;
            let mut args = std::env::args_os();
            let mut command = std::process::Command::new(&path);
            if let Some(arg0) = args.next() {
                command.arg0(arg0);
            }
            // `exec` returns only on failure.
            let error = command.args(args).exec();
            eprintln!(
                "warning: could not start {} ({error}); running the baseline build",
                path.display()
            );
        }
    }
}

/// The best variant beside this binary that this CPU runs and that is not older than it.
/// A better one that is older (a build left from before `pathlab` was rebuilt) is named on
/// stderr where that is a terminal: scripts and tests that read stderr see nothing extra.
#[cfg(all(target_arch = "x86_64", unix))]
fn best_beside_this() -> Option<std::path::PathBuf> {
    let this = std::env::current_exe().ok()?;
    let name = this.file_name()?.to_str()?.to_owned();
    let built = std::fs::metadata(&this).and_then(|m| m.modified()).ok()?;
    let mut stale = None;
    let best = LEVELS.iter().find_map(|(level, runs)| {
        let path = this.with_file_name(format!("{name}-{level}"));
        let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok()?;
        if !runs() {
            return None;
        }
        if modified < built {
            stale.get_or_insert(path);
            return None;
        }
        Some(path)
    });
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr());
    if let (Some(stale), None, true) = (&stale, &best, terminal) {
        eprintln!(
            "note: {} is older than {name} and is not used; rebuild it with \
             deploy/build-variants.sh (or set PATHLAB_NO_VARIANT=1)",
            stale.display()
        );
    }
    best
}
