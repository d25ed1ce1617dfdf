//! What the command line's test files share: running the binary, reading its output and
//! files, and scratch paths. (Each test file uses a part of it.)
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

pub fn pathlab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .output()
        .expect("the pathlab binary runs")
}

pub fn pathlab_with_threads(args: &[&str], threads: usize) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("the pathlab binary runs")
}

#[allow(unused_imports)] // each test file uses a part
pub use pathlab_testkit::process::{assert_one_line_error, json_of};

pub fn scratch(name: &str) -> PathBuf {
    pathlab_testkit::process::scratch(env!("CARGO_TARGET_TMPDIR"), "cli-tests", name)
}

pub fn assert_image(path: &PathBuf, png: bool) {
    assert_image_at_least(path, png, 10_000);
}

pub fn assert_image_at_least(path: &PathBuf, png: bool, min_bytes: usize) {
    let bytes = std::fs::read(path).expect("image written");
    if png {
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
        assert!(bytes.len() > min_bytes, "suspiciously small PNG");
    } else {
        let text = String::from_utf8(bytes).unwrap();
        assert!(
            text.contains("<svg") && text.contains("<text"),
            "not an SVG with text"
        );
    }
}

pub fn scratch_exists(name: &str) -> bool {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli-tests")
        .join(name)
        .exists()
}

pub fn course_scene(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cs184")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

/// Asserts a one-line error that reads as a sentence: no Rust debug text in it.
pub fn assert_plain_error(out: &Output, expected: &str) {
    assert_one_line_error(out, expected);
    let stderr = String::from_utf8_lossy(&out.stderr);
    for debug in [
        "Os {",
        "Error(",
        "ParseError",
        "{ ",
        "`.\"",
        ":0:0:",
        "wlog",
    ] {
        assert!(!stderr.contains(debug), "debug text '{debug}' in: {stderr}");
    }
}

pub const PNG: &[u8] = b"\x89PNG\r\n\x1a\n";

pub const EXR: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Asserts the file exists and starts with its format's magic number.
pub fn assert_magic(path: &PathBuf, magic: &[u8]) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(bytes.starts_with(magic), "{}: wrong format", path.display());
}

#[cfg(unix)]
pub fn interrupt(args: &[&str], signal: &str, after: std::time::Duration) -> std::process::Output {
    let child = Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    child.wait_with_output().unwrap()
}

/// One channel of an EXR file, by name.
pub fn read_exr_layer(path: &PathBuf, name: &str) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    let ch = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == name)
        .unwrap_or_else(|| panic!("no channel {name}"));
    match &ch.sample_data {
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
        FlatSamples::U32(v) => v.iter().map(|&x| x as f32).collect(),
    }
}
