//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
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

/// Programs longer than this are snapshot by their head, their tail, their
/// length and a hash of the whole (which still pins every byte): the raster
/// programs run to hundreds of kilobytes, the fast-tool-servo one to
/// hundreds of megabytes.
pub const WHOLE_SNAPSHOT_LIMIT: usize = 256 << 10;

/// A long program as its snapshot holds it: the first 40 lines, the
/// counts and an FNV-1a 64 hash of the whole, the last 3 lines.
pub fn abridged(program: &str) -> String {
    let lines: Vec<&str> = program.lines().collect();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in program.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    let mut out = lines[..40.min(lines.len())].join("\n");
    out.push_str(&format!(
        "\n… {} lines, {} bytes, fnv1a64 {h:016x} …\n",
        lines.len(),
        program.len()
    ));
    out.push_str(&lines[lines.len().saturating_sub(3)..].join("\n"));
    out.push('\n');
    out
}
