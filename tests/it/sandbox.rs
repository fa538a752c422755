//! What a job file may read and where lensc writes: a project root that
//! `use` cannot leave (E0107), only regular files (E0108) of at most 16 MiB
//! (E0109), nothing that can block or stream forever, no output over a
//! symlink. Every run is bounded in time: a hang fails the test instead of
//! stalling the suite.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{root, text};

const GOOD: &str = "examples/kim2008_convex_asphere.lens";

/// Runs `lensc` in `cwd`, killed (and the test failed) after 60 s.
fn lensc_bounded(cwd: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lensc"))
        .current_dir(cwd)
        .args(args)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run lensc");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return child.wait_with_output().expect("output");
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("lensc {args:?} still running after 60 s: it hangs");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A project: `proj/` inside a temporary directory, with `files` written
/// into it (name, text).
fn project(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::create_dir(dir.path().join("proj")).expect("proj");
    for (name, body) in files {
        std::fs::write(dir.path().join("proj").join(name), body).expect("write");
    }
    dir
}

/// Checks `proj/job.lens` (with `extra` arguments first) and expects exit
/// 1 with `code` in its JSON diagnostics; returns stdout and stderr.
fn refused(dir: &Path, extra: &[&str], code: &str) -> String {
    let mut args = vec!["check", "--message-format", "json"];
    args.extend_from_slice(extra);
    args.push("proj/job.lens");
    let out = lensc_bounded(dir, &args);
    let all = format!("{}{}", text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "{all}");
    let diag = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("JSON line"))
        .find(|v| v["code"] == code)
        .unwrap_or_else(|| panic!("no {code} in {all}"));
    // A span on the `use`'s path.
    assert!(diag["line"].as_u64() >= Some(1), "{diag}");
    assert!(
        diag["span"]["end"].as_u64() > diag["span"]["start"].as_u64(),
        "{diag}"
    );
    all
}

#[test]
fn an_absolute_path_outside_the_root_is_refused_unread() {
    let dir = project(&[("job.lens", "use \"/etc/passwd\"\n")]);
    let all = refused(dir.path(), &[], "E0107");
    assert!(
        all.contains("/etc/passwd") && all.contains("project root"),
        "{all}"
    );
    assert!(all.contains("--root"), "the hint names --root: {all}");
    // Nothing of the file is shown: it was never read.
    assert!(!all.contains("root:"), "{all}");
}

#[test]
fn dot_dot_out_of_the_root_is_refused() {
    let dir = project(&[("job.lens", "use \"../../x.lens\"\nuse \"../secret.lens\"\n")]);
    std::fs::write(dir.path().join("secret.lens"), "let SECRET_TEXT = (\n").expect("write");
    let all = refused(dir.path(), &[], "E0107");
    assert_eq!(all.matches("E0107").count(), 2, "{all}");
    assert!(!all.contains("SECRET_TEXT"), "{all}");
}

#[cfg(unix)]
#[test]
fn a_symlink_out_of_the_root_is_refused() {
    let dir = project(&[("job.lens", "use \"link.lens\"\n")]);
    std::fs::write(dir.path().join("secret.lens"), "let SECRET_TEXT = (\n").expect("write");
    std::os::unix::fs::symlink("../secret.lens", dir.path().join("proj/link.lens"))
        .expect("symlink");
    let all = refused(dir.path(), &[], "E0107");
    assert!(!all.contains("SECRET_TEXT"), "{all}");
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_blocking() {
    let dir = project(&[("job.lens", "use \"pipe.lens\"\n")]);
    let made = Command::new("mkfifo")
        .arg(dir.path().join("proj/pipe.lens"))
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let all = refused(dir.path(), &[], "E0108");
    assert!(all.contains("FIFO"), "{all}");
    // Nor does the FIFO block as the file given.
    let out = lensc_bounded(dir.path(), &["check", "proj/pipe.lens"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("E0108"), "{}", text(&out.stderr));
}

#[cfg(unix)]
#[test]
fn dev_zero_is_refused_outside_the_root_and_as_a_device_inside_it() {
    let dir = project(&[("job.lens", "use \"/dev/zero\"\n")]);
    refused(dir.path(), &[], "E0107");
    let all = refused(dir.path(), &["--root", "/"], "E0108");
    assert!(all.contains("a device"), "{all}");
}

#[test]
fn a_file_over_16_mib_is_refused() {
    let dir = project(&[("job.lens", "use \"big.lens\"\n")]);
    let big = "let a = 1 mm\n".repeat(17 * (1 << 20) / 13 + 1);
    assert!(big.len() > 17 << 20);
    std::fs::write(dir.path().join("proj/big.lens"), big).expect("write");
    let all = refused(dir.path(), &[], "E0109");
    assert!(all.contains("16 MiB"), "{all}");
    // The same for the file given.
    let out = lensc_bounded(dir.path(), &["check", "proj/big.lens"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("E0109"), "{}", text(&out.stderr));
}

#[test]
fn a_hard_link_to_a_file_outside_the_root_is_refused_unread() {
    let dir = project(&[("job.lens", "use \"common.lens\"\n")]);
    std::fs::write(
        dir.path().join("other.lens"),
        "let secret_of_another_job = 1\n",
    )
    .expect("outside");
    std::fs::hard_link(
        dir.path().join("other.lens"),
        dir.path().join("proj/common.lens"),
    )
    .expect("hard link");
    let all = refused(dir.path(), &[], "E0191");
    assert!(!all.contains("secret_of_another_job"), "{all}");
    assert!(all.contains("hard link"), "{all}");
}

#[test]
fn a_directory_is_refused() {
    let dir = project(&[("job.lens", "use \"sub\"\n")]);
    std::fs::create_dir(dir.path().join("proj/sub")).expect("dir");
    let all = refused(dir.path(), &[], "E0108");
    assert!(all.contains("a directory"), "{all}");
}

#[test]
fn root_widens_the_project() {
    let dir = project(&[(
        "job.lens",
        "use \"../common.lens\"\nlet twice = 2 * shared\n",
    )]);
    std::fs::write(dir.path().join("common.lens"), "let shared = 1 mm\n").expect("write");
    refused(dir.path(), &[], "E0107");
    let out = lensc_bounded(dir.path(), &["check", "--root", ".", "proj/job.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // A file given outside the root asked for is refused too.
    let out = lensc_bounded(dir.path(), &["check", "--root", "proj", "common.lens"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("E0107"), "{}", text(&out.stderr));
    // A root that is no directory is a usage error.
    let out = lensc_bounded(dir.path(), &["check", "--root", "nowhere", "proj/job.lens"]);
    assert_eq!(out.status.code(), Some(2));
}

#[cfg(unix)]
#[test]
fn no_output_is_written_over_a_symlink() {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(root().join(GOOD), dir.path().join("job.lens")).expect("copy");
    std::fs::create_dir(dir.path().join("out")).expect("out");
    std::fs::write(dir.path().join("victim.txt"), "untouched").expect("victim");
    std::os::unix::fs::symlink(
        "../victim.txt",
        dir.path().join("out/kim_convex.report.json"),
    )
    .expect("symlink");
    let out = lensc_bounded(dir.path(), &["build", "job.lens", "--out", "out"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("E0151"), "{}", text(&out.stderr));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("victim.txt")).expect("victim"),
        "untouched"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path().join("out"))
        .expect("out")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(left.len(), 1, "only the link is there: {left:?}");
}
