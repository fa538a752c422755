//! The plan-time checks fire on deliberately bad jobs: each file in
//! tests/bad_builds/ is built, and what `lensc build` says is compared with
//! its reviewed snapshot (tests/snapshots/bad_builds/). A file whose only
//! findings are warnings builds (exit 0); any error means exit 1 and no
//! program.

use crate::common::{lensc, root, text};

#[test]
fn every_bad_build_is_reported_and_snapshotted() {
    let mut files: Vec<_> = std::fs::read_dir(root().join("tests/bad_builds"))
        .expect("tests/bad_builds")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "the corpus has {} files", files.len());
    for path in files {
        let dir = tempfile::tempdir().expect("tmp");
        let rel = path
            .strip_prefix(root())
            .expect("inside the repo")
            .to_str()
            .expect("utf-8")
            .to_string();
        let out = lensc(
            &root(),
            &["build", &rel, "--out", dir.path().to_str().expect("utf-8")],
        );
        let stderr = text(&out.stderr).replace(dir.path().to_str().expect("utf-8"), "OUT");
        let has_error = stderr.lines().any(|l| l.starts_with("[E"));
        assert_eq!(
            out.status.code(),
            Some(if has_error { 1 } else { 0 }),
            "{rel}: {stderr}"
        );
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("[E") || l.starts_with("[W")),
            "{rel} reports nothing: {stderr}"
        );
        let written = std::fs::read_dir(dir.path()).map_or(0, |d| d.count());
        if has_error {
            assert_eq!(written, 0, "{rel}: output left behind");
        }
        let name = path
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .to_string();
        insta::with_settings!({ snapshot_path => "../snapshots/bad_builds", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, stderr);
        });
    }
}
