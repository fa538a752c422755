//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

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

/// Whether a file a build wrote is a program: not its report, its
/// set-up sheet or a servo table.
pub fn is_program(name: &str) -> bool {
    !(name.ends_with(".json") || name.ends_with(".fts") || name.ends_with(".setup.txt"))
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

/// The words of `said` between the first `before` and the next `after`
/// (a figure a message names: "down to 2.662 rpm"), or `None`.
pub fn between<'a>(said: &'a str, before: &str, after: &str) -> Option<&'a str> {
    said.split_once(before)?.1.split(after).next()
}

/// The figure of `said` between `before` and `after`, parsed; the test
/// fails, showing `said`, where there is none.
pub fn figure(said: &str, before: &str, after: &str) -> f64 {
    between(said, before, after)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no figure between {before:?} and {after:?} in {said}"))
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

/// Files up to this size are kept whole by [`built_examples`]: every
/// program but the three of tens of millions of points (rs274 takes about
/// 15 µs a line, so these are the ones it reads too).
pub const KEPT_WHOLE_LIMIT: usize = 8 << 20;

/// A file `lensc build` wrote.
pub enum Written {
    /// Up to [`KEPT_WHOLE_LIMIT`]: every byte.
    Whole(Vec<u8>),
    /// A larger program: its snapshot form (see [`abridged`]) only.
    Abridged(String),
}

impl Written {
    /// The file as its program snapshot holds it.
    pub fn snapshot(&self) -> String {
        match self {
            Written::Whole(bytes) if bytes.len() > WHOLE_SNAPSHOT_LIMIT => abridged(&text(bytes)),
            Written::Whole(bytes) => text(bytes),
            Written::Abridged(shown) => shown.clone(),
        }
    }
}

/// One example as `lensc build` made it, with the machine's number of
/// threads, into an empty directory.
pub struct Built {
    /// The example, relative to the repository root (`examples/….lens`).
    pub example: String,
    /// What lensc printed on stderr: its warnings.
    pub stderr: String,
    /// Every file written (programs and reports), by name.
    pub files: BTreeMap<String, Written>,
    /// The codes `lensc verify` found in each program too large to keep
    /// whole, read from the file as the build wrote it.
    pub abridged_findings: BTreeMap<String, std::collections::BTreeSet<String>>,
}

impl Built {
    /// The report of `job`.
    pub fn report(&self, job: &str) -> serde_json::Value {
        match self.files.get(&format!("{job}.report.json")) {
            Some(Written::Whole(bytes)) => serde_json::from_slice(bytes).expect("json"),
            _ => panic!("{}: no report of {job}", self.example),
        }
    }

    /// Every report, in the order of their file names.
    pub fn reports(&self) -> Vec<serde_json::Value> {
        self.files
            .iter()
            .filter(|(name, _)| name.ends_with(".report.json"))
            .map(|(name, file)| match file {
                Written::Whole(bytes) => serde_json::from_slice(bytes).expect("json"),
                Written::Abridged(_) => panic!("{name} is too large"),
            })
            .collect()
    }
}

/// Builds `file` (relative to the repository root) into a new directory
/// with `RAYON_NUM_THREADS` as given (the parallel planners' threads) or
/// unset; the exit status must be 0. Returns what lensc wrote and printed.
pub fn build_into(file: &str, threads: Option<&str>) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().expect("tmp");
    let mut c = Command::new(env!("CARGO_BIN_EXE_lensc"));
    c.current_dir(root())
        .args(["build", file, "--out"])
        .arg(dir.path())
        .env("NO_COLOR", "1");
    match threads {
        Some(n) => c.env("RAYON_NUM_THREADS", n),
        None => c.env_remove("RAYON_NUM_THREADS"),
    };
    let out = c.output().expect("run lensc");
    assert_eq!(out.status.code(), Some(0), "{file}: {}", text(&out.stderr));
    (dir, text(&out.stderr))
}

/// Every buildable example, built once for the whole test run (its largest
/// programs take tens of seconds and hundreds of megabytes each): the
/// program snapshots, rs274, the paper figures and the determinism check
/// all read these. The files are read back and their directories removed.
pub fn built_examples() -> &'static [Built] {
    static BUILT: OnceLock<Vec<Built>> = OnceLock::new();
    BUILT.get_or_init(|| {
        buildable_examples()
            .iter()
            .map(|path| {
                let example = path
                    .strip_prefix(root())
                    .expect("inside repo")
                    .to_str()
                    .expect("utf8")
                    .to_string();
                let (dir, stderr) = build_into(&example, None);
                let files = read_written(dir.path());
                let abridged_findings = files
                    .iter()
                    .filter(|(_, f)| matches!(f, Written::Abridged(_)))
                    .filter(|(name, _)| is_program(name))
                    .map(|(name, _)| (name.clone(), verify_codes(&dir.path().join(name))))
                    .collect();
                Built {
                    example,
                    stderr,
                    files,
                    abridged_findings,
                }
            })
            .collect()
    })
}

/// The codes `lensc verify` finds in the program at `path` (exit status
/// 1 exactly when it finds any).
pub fn verify_codes(path: &Path) -> std::collections::BTreeSet<String> {
    let out = lensc(
        &root(),
        &[
            "--message-format",
            "json",
            "verify",
            path.to_str().expect("utf8"),
        ],
    );
    // Errors only: the header's source check warns (W0023, W0024)
    // without failing.
    let found: std::collections::BTreeSet<String> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("json line"))
        .filter(|v| v["severity"] == "error")
        .map(|v| v["code"].as_str().expect("code").to_string())
        .collect();
    let expected = if found.is_empty() { 0 } else { 1 };
    assert_eq!(
        out.status.code(),
        Some(expected),
        "{}: {}",
        path.display(),
        text(&out.stderr)
    );
    found
}

/// The build of one example (`examples/….lens`) from [`built_examples`].
pub fn built(example: &str) -> &'static Built {
    built_examples()
        .iter()
        .find(|b| b.example == example)
        .unwrap_or_else(|| panic!("{example} is not a buildable example"))
}

/// Every file in `dir`, by name: whole up to [`KEPT_WHOLE_LIMIT`],
/// abridged past it.
pub fn read_written(dir: &Path) -> BTreeMap<String, Written> {
    std::fs::read_dir(dir)
        .expect("out")
        .map(|e| {
            let path = e.expect("entry").path();
            let name = path
                .file_name()
                .expect("name")
                .to_string_lossy()
                .into_owned();
            let bytes = std::fs::read(&path).expect("read");
            // Reports are kept whole whatever their size: the tests read
            // them (a roller of 5,760 lenslets reports each one).
            let file = if bytes.len() > KEPT_WHOLE_LIMIT && !name.ends_with(".report.json") {
                Written::Abridged(abridged(std::str::from_utf8(&bytes).expect("utf-8")))
            } else {
                Written::Whole(bytes)
            };
            (name, file)
        })
        .collect()
}

/// `Ok` where a report's acceptance was the gate's, over the whole part,
/// with every criterion and every lenslet met; else what is not.
pub fn judged_whole_and_passed(report: &serde_json::Value) -> Result<(), String> {
    let a = &report["acceptance"];
    if a["mode"] != "gate" {
        return Err(format!("accepted in mode {}, not by the gate", a["mode"]));
    }
    if a["judged"]["area"] != "whole_part" {
        return Err(format!("judged on {}, not the whole part", a["judged"]));
    }
    let criteria = a["criteria"].as_array().ok_or("no criteria")?;
    if criteria.is_empty() {
        return Err("no criterion judged".into());
    }
    let missed: Vec<String> = criteria
        .iter()
        .chain(a["lenslets"].as_array().into_iter().flatten())
        .filter(|c| c["passed"] != true)
        .map(|c| c.to_string())
        .collect();
    if !missed.is_empty() || a["passed"] != true {
        return Err(format!("missed: {missed:?}"));
    }
    Ok(())
}
