//! `pathlab`: the command-line front end of the pathlab renderer and Monte Carlo toolkit.

mod compare_cmd;
mod converge_cmd;
mod export_cmd;
mod farm;
mod flags;
mod image_cmd;
mod info_cmd;
mod integrate;
mod render_cmd;
mod sample;
mod variant;
mod view_cmd;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// pathlab: a physically based Monte Carlo renderer and Monte Carlo toolkit.
#[derive(Parser, Debug)]
#[command(name = "pathlab", version = variant::VERSION, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene (default: the built-in Cornell box).
    Render(Box<render_cmd::RenderArgs>),
    /// Render a scene with several strategies side by side, with variance, RMSE and efficiency.
    Compare(compare_cmd::CompareArgs),
    /// Plot the error against a reference as samples and time grow, for several samplers.
    Converge(converge_cmd::ConvergeArgs),
    /// Show what a scene contains (shapes, materials, lights, camera, bounds, warnings).
    Info(info_cmd::InfoArgs),
    /// Write a scene (any format pathlab reads) as Mitsuba 3 XML, its meshes as PLY beside it.
    Export(export_cmd::ExportArgs),
    /// Draw samples from a distribution or warp and compare them with its exact pdf.
    Sample(sample::SampleArgs),
    /// Estimate an integral over a box by Monte Carlo, with its error.
    Integrate(integrate::IntegrateArgs),
    /// Re-encode an image: EXR to PNG with exposure and tone map, or any readable image to EXR.
    Convert(image_cmd::ConvertArgs),
    /// Compare two images of one size: RMSE, relative MSE, and a difference image.
    Diff(image_cmd::DiffArgs),
    /// Add the films of a render's shards (`render --shard I/N -o PART.plf`) into its image.
    Merge(farm::MergeArgs),
    /// Watch a scene render in the browser, switching estimators live (a local web server).
    View(view_cmd::ViewArgs),
}

fn main() -> ExitCode {
    // A build for this CPU's instruction set, where one lies beside this binary, runs instead.
    variant::exec_best();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return argument_error(e),
    };
    let result = match &cli.command {
        Command::Render(args) => match render_cmd::run(args) {
            Ok(0) => Ok(()),
            Ok(code) => return ExitCode::from(code),
            Err(e) => Err(e),
        },
        Command::Merge(args) => farm::run_merge(args),
        Command::View(args) => view_cmd::run(args),
        Command::Info(args) => info_cmd::run(args),
        Command::Export(args) => export_cmd::run(args),
        Command::Compare(args) => compare_cmd::run(args),
        Command::Converge(args) => converge_cmd::run(args),
        Command::Sample(args) => sample::run(args),
        Command::Integrate(args) => integrate::run(args),
        Command::Convert(args) => image_cmd::run_convert(args),
        Command::Diff(args) => image_cmd::run_diff(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line: the error and its causes, outermost first.
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::FAILURE
        }
    }
}

/// The first paragraph of clap's message as one line: "the following required arguments were
/// not provided:" keeps the arguments listed under it.
fn first_paragraph(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .skip_while(|l| l.trim().is_empty())
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    if lines.is_empty() {
        "error: invalid arguments".to_string()
    } else {
        lines.join(" ")
    }
}

/// A command line clap refused: help and version as clap prints them; any other error as one
/// line (its first), as every other error is.
fn argument_error(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            eprintln!("{} (see --help)", first_paragraph(&e.to_string()));
            ExitCode::from(2)
        }
    }
}
