//! Property tests: random bytes and random token sequences never panic
//! the checker, never overflow its stack, always give well-formed
//! diagnostics, and through the real binary exit 1 exactly when an error
//! is reported (never 101).

use crate::common;

use lensc::render;
use lensc_build::driver::{self, Checked};
use lensc_lang::loader::RealFs;
use proptest::prelude::*;

fn check(bytes: &[u8]) -> Checked {
    driver::check_text(&RealFs, "fuzz.lens", bytes)
}

/// Every span lies inside its file on character boundaries, and both
/// renderers accept every diagnostic.
fn assert_well_formed(c: &Checked) {
    for d in c.diags() {
        assert!(!d.message.is_empty());
        for l in &d.labels {
            let text = &c.loaded.sources.get(l.file).text;
            assert!(
                l.span.start <= l.span.end && (l.span.end as usize) <= text.len(),
                "{:?} in {} bytes",
                l.span,
                text.len()
            );
            assert!(
                text.is_char_boundary(l.span.start as usize)
                    && text.is_char_boundary(l.span.end as usize)
            );
        }
    }
    let mut sink = Vec::new();
    render::human(c.diags(), &c.loaded.sources, false, &mut sink).expect("render");
    render::json_lines(c.diags(), &c.loaded.sources, &mut sink).expect("json");
}

const TOKENS: &[&str] = &[
    "surface",
    "tool",
    "machine",
    "strategy",
    "job",
    "let",
    "use",
    "s",
    "t",
    "m",
    "x",
    "y",
    "z",
    "r",
    "conic",
    "sphere",
    "asphere",
    "freeform",
    "circle",
    "rect",
    "round_nose",
    "lathe",
    "profile_turning",
    "radius",
    "sense",
    "convex",
    "aperture",
    "diameter",
    "nose_radius",
    "clearance",
    "sin",
    "sqrt",
    "atan2",
    "min",
    "std",
    "::",
    "machines",
    "linuxcnc_lathe",
    "1",
    "-20",
    "0.5",
    "1e3",
    "1e999",
    "85 um",
    "7 deg",
    "7°",
    "3 µm",
    "5 rad/mm",
    "2 um/rev",
    "1000 rpm",
    "25 g",
    "1 mm^-3",
    "=",
    ":",
    ",",
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    "+",
    "-",
    "*",
    "/",
    "^",
    "..",
    "\"a.lens\"",
    "\"",
    "\n",
    " ",
    "//c\n",
    "/*",
    "*/",
    "\\",
    ";",
    "é",
    "\u{0}",
];

fn tokens() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(TOKENS), 0..120).prop_map(|t| t.join(" "))
}

/// Fragments of valid files, recombined, reach deeper into the checker
/// than uniform tokens do.
fn fragments() -> impl Strategy<Value = String> {
    const F: &[&str] = &[
        "use std::machines::linuxcnc_lathe\n",
        "use std::strategies::finish_turning\n",
        "surface s = conic { radius: 22.405 mm, conic: 43.098, sense: convex, aperture: circle(radius: 1.6 mm) }\n",
        "surface f = freeform { z(x, y) = 0.02 mm * sin(5 rad/mm * x), domain: rect(x: 0 mm .. 1 mm, y: 0 mm .. 1 mm) }\n",
        "tool t = round_nose { nose_radius: 0.5 mm, clearance: 7 deg }\n",
        "machine m = linuxcnc_lathe { resolution: 10 nm }\n",
        "strategy g = profile_turning { feed: 2 um/rev, spindle_speed: 500 rpm }\n",
        "job j { surface: s, tool: t, machine: m, strategy: g }\n",
        "let a = b\n",
        "let b = a\n",
        "radius: -1 mm\n",
        "}\n",
        "{\n",
        "sense: ",
        "concave",
        "(",
        ")",
    ];
    prop::collection::vec(prop::sample::select(F), 0..12).prop_map(|t| t.concat())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let c = check(&bytes);
        assert_well_formed(&c);
        if std::str::from_utf8(&bytes).is_err() {
            prop_assert!(c.has_errors(), "invalid UTF-8 accepted");
        }
    }

    #[test]
    fn random_tokens_never_panic(src in tokens()) {
        let c = check(src.as_bytes());
        assert_well_formed(&c);
        // Whatever pest refuses must be reported.
        let (_, syntax) = lensc_grammar::parse(&src, lensc_grammar::FileId(0));
        if !syntax.is_empty() {
            prop_assert!(c.has_errors());
        }
    }

    #[test]
    fn recombined_fragments_never_panic(src in fragments()) {
        let c = check(src.as_bytes());
        assert_well_formed(&c);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    /// Through the binary: exit 1 exactly when an error is printed, 0
    /// otherwise, never an internal error, JSON on every stdout line.
    #[test]
    fn binary_exit_code_matches_diagnostics(src in prop_oneof![tokens(), fragments()]) {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("fuzz.lens");
        std::fs::write(&path, &src).expect("write");
        let out = common::lensc(dir.path(), &["check", "--message-format", "json", "fuzz.lens"]);
        let stdout = common::text(&out.stdout);
        let mut errors = 0;
        for line in stdout.lines() {
            let v: serde_json::Value = serde_json::from_str(line).expect("json line");
            if v["severity"] == "error" { errors += 1; }
        }
        let code = out.status.code();
        prop_assert!(code == Some(0) || code == Some(1), "exit {:?}: {}", code, common::text(&out.stderr));
        prop_assert_eq!(code == Some(1), errors > 0, "exit {:?} with {} errors", code, errors);
    }
}

#[test]
fn pathological_nesting_is_refused_without_overflow() {
    let deep = |open: &str, close: &str, n: usize| {
        format!("let a = {}1 mm{}\n", open.repeat(n), close.repeat(n))
    };
    for src in [
        deep("(", ")", 1_000_000),
        deep("[", "]", 100_000),
        deep("{", "}", 100_000),
        deep("-", "", 100_000),
        deep("sin(", ")", 100_000),
        format!("let a = 1 mm{}\n", " + 1 mm".repeat(200_000)),
        format!("let a = 2{}\n", " ^ 2".repeat(100_000)),
        format!("let a = b{}\n", "(1)".repeat(100_000)),
        format!("let a = 1{}\n", " * (2 + (3".repeat(30)),
    ] {
        let c = check(src.as_bytes());
        assert!(
            c.diags()
                .iter()
                .any(|d| d.code == "E0002" || d.code == "E0001"),
            "{}",
            &src[..60]
        );
        assert_well_formed(&c);
    }
}

#[test]
fn empty_and_whitespace_files_are_errors() {
    for src in ["", "   \n\n", "// only a comment\n"] {
        assert!(check(src.as_bytes()).has_errors(), "{src:?}");
    }
}

/// The inputs the fuzzer's `verify` target found (`tests/fuzz_crashes/`):
/// a byte that is not UTF-8 where a finding's span ends (read as `�`, the
/// span ended inside it and the renderer panicked: exit 101), and spans
/// that ran backwards (end before start). `lensc verify` reports each with
/// exit 1, in both formats, every span forwards.
#[test]
fn verify_survives_the_programs_the_fuzzer_found() {
    let dir = common::root().join("tests/fuzz_crashes");
    let mut programs: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/fuzz_crashes")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("verify_"))
        })
        .collect();
    programs.sort();
    assert!(programs.len() >= 3, "{programs:?}");
    for p in &programs {
        let path = p.display().to_string();
        let human = common::lensc(&common::root(), &["verify", &path]);
        let err = common::text(&human.stderr);
        assert_eq!(human.status.code(), Some(1), "{path}: {err}");
        assert!(!err.contains("panicked"), "{path}: {err}");
        let json = common::lensc(
            &common::root(),
            &["verify", "--message-format", "json", &path],
        );
        assert_eq!(json.status.code(), Some(1), "{path}");
        for line in common::text(&json.stdout).lines() {
            let v: serde_json::Value = serde_json::from_str(line).expect("a JSON line");
            let spans = std::iter::once(&v["span"]).chain(
                v["labels"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|l| &l["span"]),
            );
            for s in spans {
                assert!(s["start"].as_u64() <= s["end"].as_u64(), "{path}: {line}");
            }
        }
    }
}

/// The jobs the fuzzer's `check` target found (`tests/fuzz_crashes/`,
/// issue #33): a `simulate` window from -1e308 mm, whose grid's counts
/// overflowed and were counted out into 1.8e13 tiles (an abort on a
/// petabyte's allocation), refused as too many cells (E0149); and arrays
/// 4,300 km across (a pitch of 4,294,967,297 mm), whose rim search looped
/// for ever, refused as beyond the machine's X travel (E0141), naming
/// both. Each within a bound no finished check comes near (60 s; they
/// take a fraction of a second), the process killed past it.
#[test]
fn check_refuses_the_jobs_the_fuzzer_found() {
    let expected = [
        ("check_window_from_1e308_mm.lens", "E0149"),
        ("check_hex_array_4300_km.lens", "E0141"),
        ("check_grid_array_pitch_y_4300_km.lens", "E0141"),
        ("check_settled_array_4300_km_at_1e-9_rpm.lens", "E0141"),
    ];
    let dir = common::root().join("tests/fuzz_crashes");
    for (file, code) in expected {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_lensc"))
            .current_dir(&dir)
            .args(["check", "--message-format", "json", file])
            .env("NO_COLOR", "1")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run lensc");
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        while child.try_wait().expect("wait").is_none() {
            if std::time::Instant::now() > deadline {
                child.kill().expect("kill");
                child.wait().expect("reap");
                panic!("{file}: `lensc check` still running after 60 s");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let out = child.wait_with_output().expect("output");
        let stdout = common::text(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{file}: {}",
            common::text(&out.stderr)
        );
        let codes: Vec<String> = stdout
            .lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).expect("a JSON line");
                v["code"].as_str().unwrap_or("").to_string()
            })
            .collect();
        assert!(codes.iter().any(|c| c == code), "{file}: {stdout}");
        if code == "E0141" {
            assert!(
                stdout.contains("mm across") || stdout.contains("starts"),
                "{file}: {stdout}"
            );
            assert!(
                stdout.contains("X travel -10 .. 220 mm"),
                "{file}: {stdout}"
            );
        }
    }
}

/// The build input the campaign's build target reported as a hang (issue
/// #33): a roller helix whose pitch a number made extreme turned into
/// 1 nm (116,519 revolutions), which is no hang but a legitimately huge
/// job (23 s, a 110 MB program). Under the fuzzer's program ceiling of
/// 10 MB the size estimate refuses it before planning (E0161), in a
/// fraction of the time the build took, and nothing is written.
#[test]
fn a_roller_pitch_of_1_nm_is_refused_by_its_size_estimate() {
    refused_crash_input(
        "build_roller_pitch_1_nm.lens",
        &["--max-program-size", "10MB"],
        "E0161",
    );
}

/// `lensc build` of the kept fuzz input `file` (with `flags`), which must
/// be refused with `code` and write nothing; what it said.
fn refused_crash_input(file: &str, flags: &[&str], code: &str) -> String {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().to_str().expect("utf-8");
    let mut args = vec!["build", file, "--out", out];
    args.extend_from_slice(flags);
    let o = common::lensc(&common::root().join("tests/fuzz_crashes"), &args);
    let stderr = common::text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{file}: {stderr}");
    assert!(stderr.contains(&format!("[{code}]")), "{file}: {stderr}");
    let written = std::fs::read_dir(dir.path()).expect("out").count();
    assert_eq!(written, 0, "{file}: wrote {written} files");
    stderr
}

/// The two build inputs the campaign's second build leg reported as hangs
/// (issue #33; seed 1795953692975992825, inputs 2944 and 16804): fast
/// tool servo spirals over 2 × 2 lenslet arrays whose refusal (E0147)
/// took 9.9 and 11.9 s. Their acceleration does not fall with the spindle
/// speed (9.5× and 2× over the limit from the job's speed down to a
/// 380th of it), and the advice's search tried fourteen speeds down to
/// 0.136 and 0.254 rpm, simulating the servo at its data rate through
/// each refused trial's cut. The search now stops once a sixteenfold
/// slower spindle has not brought the excess down, and refuses a trial
/// without simulating the servo: the help names the lowest speed tried,
/// within 32× of the job's own (one step past the span).
#[test]
fn a_path_whose_acceleration_does_not_fall_with_the_speed_ends_its_search() {
    for (file, job_rpm) in [
        ("build_fts_grid_path_step_52_rpm.lens", 52.0),
        ("build_fts_hex_path_step_32_rpm.lens", 32.0),
    ] {
        let stderr = refused_crash_input(file, &[], "E0147");
        let lowest = common::figure(&stderr, "down to ", " rpm");
        assert!(
            lowest >= job_rpm / 32.0 && lowest < job_rpm,
            "{file}: searched down to {lowest} rpm from {job_rpm}"
        );
    }
}
