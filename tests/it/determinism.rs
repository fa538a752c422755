//! The same input gives the same bytes: every example is built twice, once
//! on one thread and once on as many as the machine has (`RAYON_NUM_THREADS`,
//! which the parallel planners use), and every program and report must be
//! byte-identical.

use std::process::Command;

use crate::common::{buildable_examples, root, text};

fn build_all(threads: Option<&str>) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    for ex in buildable_examples() {
        let mut c = Command::new(env!("CARGO_BIN_EXE_lensc"));
        c.current_dir(root())
            .args(["build", ex.to_str().expect("utf-8"), "--out"])
            .arg(dir.path())
            .env("NO_COLOR", "1");
        match threads {
            Some(n) => c.env("RAYON_NUM_THREADS", n),
            None => c.env_remove("RAYON_NUM_THREADS"),
        };
        let out = c.output().expect("run lensc");
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            ex.display(),
            text(&out.stderr)
        );
    }
    dir
}

#[test]
fn one_thread_and_many_build_the_same_bytes() {
    let one = build_all(Some("1"));
    let many = build_all(None);
    let mut names: Vec<_> = std::fs::read_dir(one.path())
        .expect("out")
        .map(|e| e.expect("entry").file_name())
        .collect();
    names.sort();
    assert!(names.len() >= 20, "{} files", names.len());
    for name in names {
        let (a, b) = (one.path().join(&name), many.path().join(&name));
        let (a, b) = (
            std::fs::read(&a).expect("one"),
            std::fs::read(&b).expect("many"),
        );
        assert!(
            a == b,
            "{} differs between 1 thread and many",
            name.to_string_lossy()
        );
    }
}
