//! The README's tour, run as a new user runs it: every `pathlab ...` line of its `sh` blocks, in
//! order, from a folder that sees the repository's files where the README says they are. To keep
//! the suite fast, sample counts are lowered (`-s` to 4, `--max-spp` to 4, `-n` to at most
//! 10^6); every flag, file and subcommand is as written.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Splits a command line as a shell would for the README's examples: words separated by
/// spaces, double quotes grouping, a `#` after a space starting a comment.
fn words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let (mut quoted, mut any) = (false, false);
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                any = true;
            }
            '#' if !quoted && !any => break,
            ' ' if !quoted => {
                if any {
                    out.push(std::mem::take(&mut word));
                    any = false;
                }
            }
            _ => {
                word.push(c);
                any = true;
            }
        }
    }
    if any {
        out.push(word);
    }
    out
}

/// The `pathlab` command lines of the README's `sh` blocks, in order.
fn tour(readme: &str) -> Vec<Vec<String>> {
    let mut in_sh = false;
    let mut lines = Vec::new();
    for line in readme.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_sh = !in_sh && t == "```sh";
            continue;
        }
        if in_sh && t.starts_with("pathlab ") {
            lines.push(words(t));
        }
    }
    lines
}

/// The command with its sample counts lowered.
fn cheaper(mut args: Vec<String>) -> Vec<String> {
    for i in 1..args.len() {
        let value = match args[i - 1].as_str() {
            "-s" | "--spp" => Some("4".to_string()),
            "--max-spp" => Some("4".to_string()),
            "-n" => args[i]
                .parse::<u64>()
                .ok()
                .map(|n| n.min(1_000_000).to_string()),
            _ => None,
        };
        if let Some(v) = value {
            args[i] = v;
        }
    }
    args
}

#[test]
fn every_command_of_the_readme_tour_runs_as_written() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let commands = tour(&readme);
    assert!(commands.len() >= 15, "found {} commands", commands.len());
    // A scratch folder in which the repository's folders appear where the README names them,
    // so that the images the tour writes land there and not in the repository.
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("readme-tour");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for folder in ["crates", "examples", "tests"] {
        std::os::unix::fs::symlink(root.join(folder).canonicalize().unwrap(), dir.join(folder))
            .unwrap();
    }
    for command in commands {
        let args = cheaper(command[1..].to_vec());
        let out = Command::new(env!("CARGO_BIN_EXE_pathlab"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "README: `{}` failed: {}",
            command.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert!(Path::new(&dir.join("cornell.exr")).exists());
}

#[test]
fn the_tour_parser_reads_quotes_and_comments() {
    assert_eq!(
        words(r#"pathlab integrate "exp(-(x^2))" --domain -3,3   # a comment"#),
        ["pathlab", "integrate", "exp(-(x^2))", "--domain", "-3,3"]
    );
    assert_eq!(
        cheaper(words("pathlab render -s 256 -n 5000000")),
        ["pathlab", "render", "-s", "4", "-n", "1000000"]
    );
}
