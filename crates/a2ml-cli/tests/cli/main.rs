//! End-to-end tests of the `a2ml` binary, one module per area: output,
//! files written and exit codes.

mod analyze;
mod batch;
mod bounds;
mod compare;
mod examples;
mod explain;
mod language;
mod outputs;
mod plan;
mod plot;
mod progress;
mod robot;

use std::fs;
use std::path::PathBuf;
use std::process::{Command, Output};

/// A file of the repository's `robots/`.
fn robot_path(name: &str) -> String {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "..", "robots", name].iter().collect();
    path.to_string_lossy().into_owned()
}

/// A file of the repository's `examples/`.
fn example_path(name: &str) -> String {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "..", "examples", name].iter().collect();
    path.to_string_lossy().into_owned()
}

/// A file of this crate's `tests/fixtures`, as the binary is given it.
fn fixture(name: &str) -> String {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "tests", "fixtures", name].iter().collect();
    path.to_string_lossy().into_owned()
}

/// A fresh, empty folder for one test's files, under `area` (the test's module).
fn scratch(area: &str, test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(area).join(test);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// Runs the binary.
fn a2ml(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_a2ml")).args(args).output().expect("the binary runs")
}

/// Runs the binary in the repository's root, so that a file named from there
/// (`examples/…`) prints the same on every machine, as a snapshot needs.
fn a2ml_in_repo(args: &[&str]) -> Output {
    let root: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", ".."].iter().collect();
    Command::new(env!("CARGO_BIN_EXE_a2ml"))
        .args(args)
        .current_dir(root)
        .output()
        .expect("the binary runs")
}

fn stdout(output: &Output) -> String {
    String::from_utf8(output.stdout.clone()).expect("UTF-8 stdout")
}

fn stderr(output: &Output) -> String {
    String::from_utf8(output.stderr.clone()).expect("UTF-8 stderr")
}

/// The keys of a JSON object, sorted.
fn keys(value: &serde_json::Value) -> Vec<&str> {
    let mut keys: Vec<&str> =
        value.as_object().expect("an object").keys().map(String::as_str).collect();
    keys.sort_unstable();
    keys
}

/// `k`, sorted (to compare with [`keys`]).
fn sorted(mut k: Vec<&str>) -> Vec<&str> {
    k.sort_unstable();
    k
}
