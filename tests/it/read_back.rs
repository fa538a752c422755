//! Every program lensc writes, read back by `lensc verify` as a user runs
//! it: each program snapshot (tests/snapshots/programs and dialects; of an
//! abridged one, the head it keeps, whose end is not there to read) and
//! every example's own program in full as the build wrote it (up to
//! `common::KEPT_WHOLE_LIMIT` from memory, the larger ones from their
//! files).

use std::collections::BTreeSet;

use crate::common::{Written, built_examples, root, text, verify_codes};

/// The codes `lensc verify` finds in `program` (named `name`).
fn codes(name: &str, program: &str) -> BTreeSet<String> {
    let dir = tempfile::tempdir().expect("tmp");
    let path = dir.path().join(name);
    std::fs::write(&path, program).expect("write");
    verify_codes(&path)
}

/// Every code found: no program lensc writes may break any rule.
fn unexpected(found: BTreeSet<String>) -> Vec<String> {
    found.into_iter().collect()
}

#[test]
fn every_program_snapshot_reads_back() {
    let mut read = 0;
    for dir in ["programs", "dialects"] {
        let mut files: Vec<_> = std::fs::read_dir(root().join("tests/snapshots").join(dir))
            .expect("snapshots")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "snap"))
            .collect();
        files.sort();
        for snap in files {
            let all = std::fs::read_to_string(&snap).expect("read");
            // The snapshot's own header is three lines (`---`, source, `---`).
            let program: String = all.split_inclusive('\n').skip(3).collect();
            let abridged = program
                .lines()
                .any(|l| l.starts_with("… ") && l.contains(" lines, "));
            let program = if abridged {
                program.split_inclusive('\n').take(40).collect()
            } else {
                program
            };
            let name = snap
                .file_stem()
                .expect("name")
                .to_string_lossy()
                .into_owned();
            let mut found = unexpected(codes(&name, &program));
            if abridged {
                // Its end is not in the snapshot.
                found.retain(|c| c != "E0328" && c != "E0332");
            }
            assert!(found.is_empty(), "{}: {found:?}", snap.display());
            read += 1;
        }
    }
    assert!(read >= 60, "{read} snapshots");
}

#[test]
fn every_example_program_reads_back_whole() {
    let mut read = 0;
    for b in built_examples() {
        for (name, file) in &b.files {
            let Written::Whole(bytes) = file else {
                continue;
            };
            if name.ends_with(".json") || name.ends_with(".fts") {
                continue;
            }
            let found = unexpected(codes(name, &text(bytes)));
            assert!(found.is_empty(), "{} {name}: {found:?}", b.example);
            read += 1;
        }
    }
    assert!(read >= 15, "{read} programs");
}

/// The programs of tens of millions of points, read from the files the
/// build wrote (among them the roller helix whose steps across the seam
/// once fed X at twice the machine's limit: E0314).
#[test]
fn every_large_example_program_reads_back() {
    let mut read = 0;
    for b in built_examples() {
        for (name, found) in &b.abridged_findings {
            let found = unexpected(found.clone());
            assert!(found.is_empty(), "{} {name}: {found:?}", b.example);
            read += 1;
        }
    }
    assert!(read >= 3, "{read} programs");
}

/// With the read-back on, a build writes a program only if it reads
/// clean; a job whose program the reader refuses fails with the reader's
/// code at the job and leaves no program behind.
#[test]
fn a_build_reading_back_writes_only_what_reads_clean() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lensc"))
        .current_dir(root())
        .args(["build", "examples/even_asphere_turning.lens", "--out"])
        .arg(dir.path())
        .env("NO_COLOR", "1")
        .env("LENSC_READ_BACK", "1")
        .output()
        .expect("run lensc");
    let stderr = text(&out.stderr);
    for job in ["insert_finish", "insert_finish_css"] {
        let program = dir.path().join(format!("{job}.ngc"));
        let refused = stderr.contains(&format!("{job}.ngc, line "));
        assert_ne!(program.exists(), refused, "{job}: {stderr}");
        if refused {
            assert_eq!(out.status.code(), Some(1));
            assert!(stderr.contains("[E03"), "{stderr}");
        } else {
            let text = std::fs::read_to_string(&program).expect("read");
            assert!(codes(&format!("{job}.ngc"), &text).is_empty());
        }
    }
}
