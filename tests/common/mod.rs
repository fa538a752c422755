//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .expect("repo root")
}

/// Runs the real `lensc` binary in `cwd`.
pub fn lensc(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lensc"))
        .current_dir(cwd)
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("run lensc")
}

/// Every `.lens` file in examples/.
pub fn examples() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("examples"))
        .expect("examples/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    v.sort();
    v
}

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Whether a job file declares at least one job (files without one are
/// libraries of surfaces and the like: checked and sampled, not built).
pub fn has_job(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .expect("read")
        .lines()
        .any(|l| l.starts_with("job "))
}

/// Examples that declare a job.
pub fn buildable_examples() -> Vec<PathBuf> {
    examples().into_iter().filter(|p| has_job(p)).collect()
}

/// Names of the surfaces a file declares at the start of a line.
pub fn surface_names(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .expect("read")
        .lines()
        .filter_map(|l| l.strip_prefix("surface "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}
