//! `pathlab` runs a build for this CPU's instruction set in its place where one lies beside it
//! (`deploy/build-variants.sh`), and only a fresh one this CPU can run.
#![cfg(all(target_arch = "x86_64", unix))]

mod common;

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, MutexGuard};

use pathlab_mc::simd::{runs_x86_64_v3, runs_x86_64_v4};

/// Held by each test for its whole run. The tests write scripts and run programs: one
/// test's child, between its fork and its exec, holds open whatever file another test is
/// writing, and a script held open for writing cannot be run ("text file busy"), so
/// `pathlab` would fall back to the baseline build and a test fail at random.
fn one_at_a_time() -> MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A folder holding `pathlab` (a link to the built binary) and nothing else.
fn folder(name: &str) -> PathBuf {
    let dir = common::scratch(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("pathlab");
    if std::fs::hard_link(env!("CARGO_BIN_EXE_pathlab"), &exe).is_err() {
        std::fs::copy(env!("CARGO_BIN_EXE_pathlab"), &exe).unwrap();
    }
    dir
}

/// A stand-in for a variant: a script that says which it is and what it was given.
fn fake_variant(dir: &Path, level: &str) -> PathBuf {
    let path = dir.join(format!("pathlab-{level}"));
    std::fs::write(&path, format!("#!/bin/sh\necho \"variant {level}: $*\"\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

fn version(dir: &Path, env: &[(&str, &str)]) -> String {
    let out = Command::new(dir.join("pathlab"))
        .arg("--version")
        .env_remove("PATHLAB_NO_VARIANT")
        .env_remove("PATHLAB_NO_AVX512")
        .envs(env.iter().copied())
        .output()
        .expect("pathlab runs");
    assert!(out.status.success());
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

#[test]
fn the_baseline_build_says_so() {
    let _one = one_at_a_time();
    let dir = folder("variant-none");
    assert!(version(&dir, &[]).ends_with("(baseline)"));
}

#[test]
fn a_variant_beside_pathlab_runs_in_its_place_with_the_same_arguments() {
    let _one = one_at_a_time();
    let dir = folder("variant-v3");
    fake_variant(&dir, "x86-64-v3");
    let v = version(&dir, &[]);
    if runs_x86_64_v3() {
        assert_eq!(v, "variant x86-64-v3: --version");
    } else {
        assert!(v.ends_with("(baseline)"), "{v}");
    }
    // Turned off: the baseline runs.
    assert!(version(&dir, &[("PATHLAB_NO_VARIANT", "1")]).ends_with("(baseline)"));
}

#[test]
fn a_variant_older_than_pathlab_is_taken_for_a_stale_build_and_not_run() {
    let _one = one_at_a_time();
    let dir = folder("variant-stale");
    let fake = fake_variant(&dir, "x86-64-v3");
    let built = std::fs::metadata(dir.join("pathlab"))
        .and_then(|m| m.modified())
        .unwrap();
    std::fs::File::options()
        .write(true)
        .open(&fake)
        .unwrap()
        .set_modified(built - std::time::Duration::from_secs(60))
        .unwrap();
    assert!(version(&dir, &[]).ends_with("(baseline)"));
}

#[test]
fn the_avx512_variant_stands_aside_when_avx512_is_turned_off() {
    let _one = one_at_a_time();
    let dir = folder("variant-v4");
    fake_variant(&dir, "x86-64-v4");
    fake_variant(&dir, "x86-64-v3");
    let off = version(&dir, &[("PATHLAB_NO_AVX512", "1")]);
    if runs_x86_64_v3() {
        assert_eq!(off, "variant x86-64-v3: --version");
    }
    let on = version(&dir, &[]);
    if runs_x86_64_v4() {
        assert_eq!(on, "variant x86-64-v4: --version");
    }
}
