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
            // The snapshot's own header: insta's metadata between two `---`
            // lines (source, and sometimes its assertion line).
            let program: String = all
                .split_inclusive('\n')
                .skip_while(|l| l.trim_end() != "---")
                .skip(1)
                .skip_while(|l| l.trim_end() != "---")
                .skip(1)
                .collect();
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
            if !crate::common::is_program(name) {
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

/// The machine and dialect `program`'s header names, declared in its
/// source (relative to the repository) or the standard library, as
/// `lensc verify` finds them.
fn machine_and_dialect(
    program: &str,
) -> Option<(
    lensc_runtime::reader::MachineLimits,
    lensc_runtime::dialect::Dialect,
)> {
    use lensc_lang::loader::RealFs;
    use lensc_lang::lower::read_back::{dialect_named, machine_named};
    use lensc_runtime::reader::{header_names, header_source};
    let names = header_names(program)?;
    let mut declarations = std::collections::HashMap::new();
    if let Some(source) = header_source(program)
        && let Ok(c) = lensc_lang::check_path(&RealFs, &root().join(source))
        && !c.has_errors()
    {
        declarations = c.checked.declarations;
    }
    for (module, name) in [("machines", &names.machine), ("dialects", &names.dialect)] {
        if !declarations.contains_key(name) {
            let uses = format!("use std::{module}::{name}\n");
            let c = lensc_lang::check_text(&RealFs, "<standard library>", uses.as_bytes());
            declarations.extend(c.checked.declarations);
        }
    }
    let (limits, _) = machine_named(&declarations, &names.machine)?;
    Some((limits, dialect_named(&declarations, &names.dialect)?))
}

/// `program` with every 37th line changed by one byte (a digit doubled,
/// a letter lowered, a space dropped, in turn): lines the fast path must
/// refuse or read as the whole path does.
fn damaged(program: &str) -> String {
    program
        .split_inclusive('\n')
        .enumerate()
        .map(|(n, line)| {
            if n % 37 != 36 {
                return line.to_string();
            }
            let at = line.len() / 2;
            let mut b = line.as_bytes().to_vec();
            if at < b.len() && b[at].is_ascii() {
                match n % 3 {
                    0 => b.insert(at, b[at]),
                    1 => b[at] = b[at].to_ascii_lowercase(),
                    _ => {
                        b.remove(at);
                    }
                }
            }
            String::from_utf8_lossy(&b).into_owned()
        })
        .collect()
}

/// Every program lensc writes — each snapshot (programs and dialects)
/// and each example's own — reads with the same findings and the same
/// moves with the common block read in one pass as read whole; so does
/// each with lines damaged, and each on a machine of a tenth of the feed
/// and half the travel (findings on many lines).
#[test]
fn every_program_reads_the_same_on_the_fast_path() {
    use lensc_runtime::reader::read_moves_by;
    let mut programs: Vec<(String, String)> = Vec::new();
    for dir in ["programs", "dialects"] {
        for e in std::fs::read_dir(root().join("tests/snapshots").join(dir)).expect("snapshots") {
            let path = e.expect("entry").path();
            if path.extension().is_some_and(|e| e == "snap") {
                let all = std::fs::read_to_string(&path).expect("read");
                let program: String = all.split_inclusive('\n').skip(3).collect();
                programs.push((path.display().to_string(), program));
            }
        }
    }
    for b in built_examples() {
        for (name, file) in &b.files {
            if let Written::Whole(bytes) = file
                && crate::common::is_program(name)
            {
                programs.push((format!("{} {name}", b.example), text(bytes)));
            }
        }
    }
    programs.sort();
    let (mut read, mut found) = (0, 0);
    for (name, program) in &programs {
        let Some((machine, dialect)) = machine_and_dialect(program) else {
            continue;
        };
        let mut tight = machine.clone();
        tight.max_feed = tight.max_feed.map(|f| f / 10.0);
        for t in &mut tight.travel {
            *t = t.map(|(lo, hi)| (lo / 2.0, hi / 2.0));
        }
        for (what, text, m) in [
            ("as written", program.clone(), &machine),
            ("damaged", damaged(program), &machine),
            ("on a tight machine", program.clone(), &tight),
        ] {
            let fast = read_moves_by(&text, &dialect, m, true);
            let whole = read_moves_by(&text, &dialect, m, false);
            assert_eq!(fast.0, whole.0, "{name} {what}: the findings");
            found += fast.0.len();
            assert_eq!(fast.1.len(), whole.1.len(), "{name} {what}: the moves");
            for (k, (a, b)) in fast.1.iter().zip(&whole.1).enumerate() {
                assert_eq!(
                    format!("{a:?}"),
                    format!("{b:?}"),
                    "{name} {what}: move {k}"
                );
            }
        }
        read += 1;
    }
    assert!(read >= 60, "{read} of {} programs read", programs.len());
    // The damaged programs and the tight machine are refused, often.
    assert!(found >= 2 * read, "{found} findings in {read} programs");
}
