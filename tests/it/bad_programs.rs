//! The bad-program corpus (tests/bad_programs/): hand-written programs in
//! every dialect, each breaking one rule of the reader, read by `lensc
//! verify` as a user runs it. Each is refused (exit 1) with the code its
//! file name starts with (`e0316_…` → E0316) first, and its rendered
//! diagnostics are snapshot; the programs in `clean/` (each corpus file is
//! one of them with one change) read clean (exit 0).

use std::path::PathBuf;

use crate::common::{lensc, root, text};

fn files(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .expect("tests/bad_programs")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

#[test]
fn every_bad_program_is_refused_with_its_code() {
    let corpus = files("tests/bad_programs");
    assert!(corpus.len() >= 30, "{} bad programs", corpus.len());
    for path in corpus {
        let rel = path.strip_prefix(root()).expect("inside repo");
        let name = path
            .file_name()
            .expect("name")
            .to_string_lossy()
            .into_owned();
        let out = lensc(&root(), &["verify", rel.to_str().expect("utf8")]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        let code = name[..5].to_uppercase();
        let first = stderr.lines().next().unwrap_or("");
        assert!(
            first.starts_with(&format!("[{code}]")),
            "{name}: the first finding is not {code}: {stderr}"
        );
        insta::with_settings!({ snapshot_path => "../snapshots/bad_programs", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, stderr);
        });
    }
}

#[test]
fn the_programs_they_were_made_from_read_clean() {
    let clean = files("tests/bad_programs/clean");
    assert_eq!(clean.len(), 6, "one per controller");
    for path in clean {
        let rel = path.strip_prefix(root()).expect("inside repo");
        let out = lensc(&root(), &["verify", rel.to_str().expect("utf8")]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            rel.display(),
            text(&out.stderr)
        );
    }
}

#[test]
fn a_program_without_a_header_is_read_by_the_machine_and_dialect_given() {
    let dir = tempfile::tempdir().expect("tmp");
    let clean = std::fs::read_to_string(root().join("tests/bad_programs/clean/fanuc_base.nc"))
        .expect("read");
    let bare: String = clean
        .lines()
        .filter(|l| !l.starts_with("(machine "))
        .map(|l| format!("{l}\n"))
        .collect();
    let path = dir.path().join("bare.nc");
    std::fs::write(&path, bare).expect("write");
    let p = path.to_str().expect("utf8");
    let out = lensc(&root(), &["verify", p]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("give --machine and --dialect"));
    let args = [
        "verify",
        p,
        "--machine",
        "linuxcnc_lathe",
        "--dialect",
        "fanuc_0i_lathe",
    ];
    let out = lensc(&root(), &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // Read as LinuxCNC, the Fanuc program's diameters and O word are wrong.
    let args = [
        "verify",
        p,
        "--machine",
        "linuxcnc_lathe",
        "--dialect",
        "linuxcnc",
    ];
    assert_eq!(lensc(&root(), &args).status.code(), Some(1));
    let args = [
        "verify",
        p,
        "--machine",
        "no_such_machine",
        "--dialect",
        "linuxcnc",
    ];
    let out = lensc(&root(), &args);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("no machine `no_such_machine`"));
}
