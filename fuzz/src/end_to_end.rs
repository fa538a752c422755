//! A share of the `.lens` inputs through the real `lensc` binary, end to
//! end, as a user runs it: the file written into a project directory (the
//! corpus's imported files beside it, read through the sandbox's root
//! rules from disk), `lensc check` or `lensc build` run on it, and the
//! edges the in-process harness cannot see held: the exit code is 0 or 1
//! (never a panic's 101 or a signal), nothing says "panicked", every JSON
//! line on stdout is a coded diagnostic, and a build leaves its output
//! directory whole: every file a job's report names beside it after exit
//! 0, nothing at all after exit 1, and no `.lensc-*.tmp` either way.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::harness::{Depth, Fault};

/// One in this many `.lens` inputs also runs through the binary.
pub const SHARE: u64 = 50;

/// How long one run of the binary may take.
const RUN: Duration = Duration::from_secs(30);

/// A lane's project directory: the corpus's files written once, then each
/// input as `fuzz.lens` beside them.
pub struct Project {
    lensc: PathBuf,
    dir: PathBuf,
}

impl Project {
    /// Writes `files` (name, bytes) into `dir` for `use` to find.
    pub fn new<'a>(
        lensc: &Path,
        dir: PathBuf,
        files: impl Iterator<Item = (&'a String, &'a Vec<u8>)>,
    ) -> Project {
        let _ = std::fs::create_dir_all(&dir);
        for (name, bytes) in files {
            let name = Path::new(name).file_name().map(PathBuf::from);
            if let Some(name) = name {
                let _ = std::fs::write(dir.join(name), bytes);
            }
        }
        Project {
            lensc: lensc.to_path_buf(),
            dir,
        }
    }

    /// Runs `bytes` through `lensc check` or `lensc build` as `depth` asks
    /// (check for every depth but a build's).
    pub fn run(&self, bytes: &[u8], depth: Depth) -> Result<(), Fault> {
        let file = self.dir.join("fuzz.lens");
        let out = self.dir.join("out");
        let _ = std::fs::remove_dir_all(&out);
        std::fs::write(&file, bytes).map_err(|e| format!("cannot write the input: {e}"))?;
        let mut cmd = Command::new(&self.lensc);
        cmd.arg("--message-format")
            .arg("json")
            .arg("--root")
            .arg(&self.dir);
        let building = matches!(depth, Depth::Build | Depth::BuildAs { .. });
        match depth {
            Depth::Build | Depth::BuildAs { .. } => {
                cmd.arg("build").arg("--quiet").arg("--out").arg(&out);
                if let Depth::BuildAs {
                    dialect,
                    max_program_size,
                    accept_warn,
                } = depth
                {
                    if accept_warn {
                        cmd.arg("--accept").arg("warn");
                    }
                    if let Some(d) = dialect {
                        cmd.arg("--dialect").arg(d);
                    }
                    if let Some(m) = max_program_size {
                        cmd.arg("--max-program-size").arg(m.to_string());
                    }
                }
            }
            Depth::LowerWithin(limits) => {
                cmd.arg("check")
                    .arg("--max-program-size")
                    .arg(limits.max_program_size.to_string());
            }
            _ => {
                cmd.arg("check");
            }
        }
        cmd.arg(&file);
        let (code, stdout, stderr) = run(cmd)?;
        let what = if building {
            "lensc build"
        } else {
            "lensc check"
        };
        if stderr.contains("panicked") {
            return Err(format!(
                "{what} panicked: {}",
                first_line_with(&stderr, "panicked")
            ));
        }
        match code {
            Some(0 | 1) => {}
            other => {
                return Err(format!(
                    "{what} ended with {other:?}: {}",
                    stderr.lines().next().unwrap_or("")
                ));
            }
        }
        for line in stdout.lines().filter(|l| !l.trim().is_empty()) {
            let coded = line.contains("\"code\":\"E") || line.contains("\"code\":\"W");
            if !line.starts_with('{') || !coded {
                return Err(format!(
                    "{what} printed a line that is not a coded diagnostic: {}",
                    cut(line)
                ));
            }
        }
        if building {
            whole(&out, code == Some(0))?;
        }
        Ok(())
    }
}

/// An output directory as a finished build leaves it: no temporary file;
/// after a failure nothing; after a success at least one report, and
/// every program a report names present.
fn whole(out: &Path, succeeded: bool) -> Result<(), Fault> {
    let names: Vec<String> = match std::fs::read_dir(out) {
        Ok(entries) => entries
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect(),
        Err(_) => Vec::new(),
    };
    if let Some(t) = names.iter().find(|n| n.starts_with(".lensc-")) {
        return Err(format!("lensc build left a temporary file {t}"));
    }
    if !succeeded {
        return match names.first() {
            Some(n) => Err(format!("lensc build failed (exit 1) but wrote {n}")),
            None => Ok(()),
        };
    }
    let reports: Vec<&String> = names
        .iter()
        .filter(|n| n.ends_with(".report.json"))
        .collect();
    if reports.is_empty() {
        return Err(format!(
            "lensc build succeeded but wrote no report ({names:?})"
        ));
    }
    for r in reports {
        let stem = r.trim_end_matches(".report.json");
        if !names.iter().any(|n| n != r && n.starts_with(stem)) {
            return Err(format!(
                "lensc build wrote the report {r} without its program"
            ));
        }
    }
    Ok(())
}

/// Runs `cmd` to its end (killed after `RUN`): its exit code (`None`: a
/// signal), stdout and stderr.
fn run(mut cmd: Command) -> Result<(Option<i32>, String, String), Fault> {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start lensc: {e}"))?;
    let mut stdout = child.stdout.take().ok_or("no stdout")?;
    let mut stderr = child.stderr.take().ok_or("no stderr")?;
    let out = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = stdout.read_to_end(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = stderr.read_to_end(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| format!("wait: {e}"))? {
            break s;
        }
        if start.elapsed() > RUN {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("lensc did not finish within {RUN:?}"));
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    let text = |v: Vec<u8>| String::from_utf8_lossy(&v).into_owned();
    Ok((
        status.code(),
        text(out.join().unwrap_or_default()),
        text(err.join().unwrap_or_default()),
    ))
}

fn first_line_with<'a>(text: &'a str, needle: &str) -> &'a str {
    text.lines().find(|l| l.contains(needle)).unwrap_or("")
}

/// At most 200 bytes of `line`, on a character boundary.
fn cut(line: &str) -> &str {
    let mut n = line.len().min(200);
    while !line.is_char_boundary(n) {
        n -= 1;
    }
    &line[..n]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// A stand-in `lensc` that prints `stdout`, `stderr` and exits `code`.
    fn fake_lensc(dir: &Path, stdout: &str, stderr: &str, code: i32) -> PathBuf {
        let path = dir.join("lensc");
        let script = format!("#!/bin/sh\necho '{stdout}'\necho '{stderr}' >&2\nexit {code}\n");
        std::fs::write(&path, script).expect("script");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("mode");
        path
    }

    fn run_with(stdout: &str, stderr: &str, code: i32) -> Result<(), Fault> {
        let dir = tempfile::tempdir().expect("temp dir");
        let lensc = fake_lensc(dir.path(), stdout, stderr, code);
        let files: Vec<(String, Vec<u8>)> = vec![("part.lens".into(), b"let a = 1 mm\n".to_vec())];
        let project = Project::new(
            &lensc,
            dir.path().join("project"),
            files.iter().map(|(n, b)| (n, b)),
        );
        assert!(dir.path().join("project/part.lens").is_file());
        project.run(b"let b = 2 mm\n", Depth::Check)
    }

    #[test]
    fn a_panic_a_signal_or_an_uncoded_line_from_the_binary_is_a_fault() {
        let coded = r#"{"code":"E0101","message":"x"}"#;
        assert!(run_with(coded, "", 1).is_ok());
        assert!(run_with("", "", 0).is_ok());
        let panicked = run_with("", "thread 'main' panicked at src/x.rs:1:1", 101);
        assert!(panicked.is_err_and(|e| e.contains("panicked")));
        assert!(run_with("", "", 101).is_err_and(|e| e.contains("Some(101)")));
        assert!(run_with("", "", 2).is_err());
        assert!(run_with("not json", "", 1).is_err_and(|e| e.contains("not a coded")));
    }

    #[test]
    fn a_build_leaves_both_files_of_a_job_or_nothing_and_no_temporary_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path();
        assert!(whole(out, false).is_ok(), "nothing after a failure");
        assert!(whole(out, true).is_err(), "a success that wrote nothing");
        std::fs::write(out.join("j.report.json"), "{}").expect("report");
        assert!(whole(out, true).is_err(), "a report without its program");
        assert!(whole(out, false).is_err(), "a report after a failure");
        std::fs::write(out.join("j.ngc"), "%").expect("program");
        assert!(whole(out, true).is_ok());
        std::fs::write(out.join(".lensc-1-abc.tmp"), "").expect("temp");
        assert!(whole(out, true).is_err_and(|e| e.contains("temporary")));
    }
}
