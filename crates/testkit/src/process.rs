//! Running a binary as a user does, reading what it printed, and scratch paths.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The JSON a successful run printed on stdout (`--json`); fails the test with the run's
/// stderr when it failed.
pub fn json_of(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "the program failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("--json prints valid JSON")
}

/// Asserts a failed run with exactly one line on stderr: an `error: ` naming `expected`, and
/// no panic.
pub fn assert_one_line_error(out: &Output, expected: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected a failure, got success");
    assert_eq!(stderr.trim_end().lines().count(), 1, "stderr: {stderr}");
    assert!(stderr.starts_with("error: "), "stderr: {stderr}");
    assert!(
        stderr.contains(expected),
        "stderr lacks '{expected}': {stderr}"
    );
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
}

/// A path `name` in the folder `group` of the test's scratch folder `tmp` (a test passes
/// `env!("CARGO_TARGET_TMPDIR")`), the folder made and any file left there by an earlier run
/// removed.
pub fn scratch(tmp: &str, group: &str, name: &str) -> PathBuf {
    let dir = Path::new(tmp).join(group);
    std::fs::create_dir_all(&dir).expect("the scratch folder can be made");
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}
