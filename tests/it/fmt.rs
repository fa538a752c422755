//! `lensc fmt`: every example, standard-library file and file of the
//! bad-input corpora that parses formats to a file that checks to the
//! same values (every declaration, job field, diagnostic and lowering
//! outcome, spans aside), and formatting it again changes nothing; the
//! layout of awkward comments is snapshotted (tests/fmt/*.lens); random
//! programs with comments and line breaks anywhere keep both properties;
//! and the command rewrites only what changes, `--check` writes nothing.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use lensc_lang::Checked;
use lensc_lang::format::format_source;
use lensc_lang::loader::{FileSystem, RealFs, Root};
use lensc_lang::sandbox::ReadError;
use lensc_lang::value::{Field, Value};
use proptest::prelude::*;

use crate::common::{lensc, root, text};

fn lens_files(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .expect(dir)
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    v.sort();
    v
}

/// The real file system, but one file reads as other text: the formatted
/// file is checked where the original lies, with its neighbours for `use`.
struct Overlay {
    path: PathBuf,
    text: String,
}

impl FileSystem for Overlay {
    fn read(&self, root: &Root, path: &Path) -> Result<Vec<u8>, ReadError> {
        if RealFs.canonical(path) == self.path {
            Ok(self.text.clone().into_bytes())
        } else {
            RealFs.read(root, path)
        }
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        RealFs.canonical(path)
    }
}

/// Everything a checked file means, without where it was written: its
/// diagnostics, its declarations and jobs with every value, and each job
/// lowered as `lensc check` lowers it.
fn meaning(c: &Checked) -> String {
    let mut s = String::new();
    for d in c.diags() {
        let labels: Vec<&str> = d.labels.iter().map(|l| l.message.as_str()).collect();
        writeln!(
            s,
            "{} {}: {} {labels:?} {:?}",
            d.severity.as_str(),
            d.code,
            d.message,
            d.help
        )
        .unwrap();
    }
    let mut names: Vec<&String> = c.checked.declarations.keys().collect();
    names.sort();
    for n in names {
        write!(s, "declaration {n} = ").unwrap();
        value(&mut s, &Value::Object(c.checked.declarations[n].clone()), 1);
    }
    let limits = lensc_build::job::Limits::default();
    for j in &c.checked.jobs {
        let mut parts: Vec<_> = j.part_names.iter().collect();
        parts.sort();
        writeln!(s, "job {} {parts:?}", j.name.name).unwrap();
        fields(&mut s, &j.fields, 1);
        // Lowered as `lensc check` does: once the file checks.
        if c.has_errors() {
            continue;
        }
        match lensc_build::pipeline::lower(j, None, &limits) {
            Ok((_, estimate)) => writeln!(s, "  lowers: {estimate:?}").unwrap(),
            Err(diags) => {
                for d in diags {
                    writeln!(s, "  refused {}: {} {:?}", d.code, d.message, d.help).unwrap();
                }
            }
        }
    }
    s
}

fn fields(s: &mut String, fs: &[Field], depth: usize) {
    for f in fs {
        write!(s, "{:w$}{}: ", "", f.name, w = 2 * depth).unwrap();
        value(s, &f.value, depth + 1);
    }
}

fn value(s: &mut String, v: &Value, depth: usize) {
    match v {
        Value::Object(o) => {
            writeln!(s, "{} {:?}", o.kind.name, o.name).unwrap();
            fields(s, &o.fields, depth);
        }
        Value::Block(b) => {
            writeln!(s, "block").unwrap();
            fields(s, b, depth);
        }
        Value::List(items) => {
            writeln!(s, "list of {}", items.len()).unwrap();
            for (item, _) in items {
                write!(s, "{:w$}- ", "", w = 2 * depth).unwrap();
                value(s, item, depth + 1);
            }
        }
        Value::Formula(f) => {
            let mut constants: Vec<_> = f.constants.iter().collect();
            constants.sort_by(|a, b| a.0.cmp(b.0));
            writeln!(
                s,
                "formula {:?} -> {:?} = {} with {constants:?}",
                f.params,
                f.result,
                without_spans(&format!("{:?}", f.body))
            )
            .unwrap();
        }
        Value::Num(x, d) => writeln!(s, "{x:?} {d:?}").unwrap(),
        Value::Range(a, b, d) => writeln!(s, "{a:?} .. {b:?} {d:?}").unwrap(),
        Value::Str(t) => writeln!(s, "{t:?}").unwrap(),
        Value::Word(w) => writeln!(s, "word {w}").unwrap(),
        Value::Function(f) => writeln!(s, "function {f}").unwrap(),
        Value::Kind(k) => writeln!(s, "kind {}", k.name).unwrap(),
        Value::Error => writeln!(s, "error").unwrap(),
    }
}

/// A syntax tree's debug text with its byte spans taken out.
fn without_spans(debug: &str) -> String {
    let mut out = String::new();
    let mut rest = debug;
    while let Some(i) = rest.find("Span {") {
        out.push_str(&rest[..i]);
        let close = rest[i..].find('}').expect("span closes");
        rest = &rest[i + close + 1..];
    }
    out.push_str(rest);
    out
}

#[test]
fn every_corpus_file_that_parses_formats_to_the_same_meaning() {
    let mut files = Vec::new();
    for dir in ["examples", "stdlib", "tests/bad", "tests/bad_builds"] {
        files.extend(lens_files(dir));
    }
    let (mut formatted, mut refused) = (0, 0);
    for path in &files {
        let rel = path
            .strip_prefix(root())
            .unwrap_or(path)
            .display()
            .to_string();
        let Ok(original) = std::fs::read_to_string(path) else {
            refused += 1; // not UTF-8: the loader's refusal, tested elsewhere
            continue;
        };
        let once = match format_source(&original) {
            Ok(once) => once,
            Err(diags) => {
                assert!(
                    diags.iter().all(|d| d.code.starts_with("E000")),
                    "{rel}: refused with more than syntax errors: {diags:?}"
                );
                refused += 1;
                continue;
            }
        };
        formatted += 1;
        let twice = format_source(&once).expect("formatted text formats");
        assert_eq!(once, twice, "{rel}: formatting twice changed it");
        let overlay = Overlay {
            path: RealFs.canonical(path),
            text: once,
        };
        let before = lensc_lang::check_path(&RealFs, path).expect("readable");
        let after = lensc_lang::check_path(&overlay, path).expect("readable");
        assert_eq!(
            meaning(&before),
            meaning(&after),
            "{rel}: formatting changed its meaning"
        );
    }
    eprintln!("{formatted} files formatted, {refused} refused (syntax errors)");
    assert!(
        formatted >= 97,
        "only {formatted} of {} files parsed",
        files.len()
    );
}

#[test]
fn examples_and_stdlib_are_in_the_canonical_layout() {
    for path in lens_files("examples")
        .into_iter()
        .chain(lens_files("stdlib"))
    {
        let text = std::fs::read_to_string(&path).expect("read");
        let formatted = format_source(&text).expect("formats");
        assert!(
            formatted == text,
            "{} is not formatted: run lensc fmt",
            path.display()
        );
    }
}

#[test]
fn awkward_layouts_format_as_snapshotted() {
    for path in lens_files("tests/fmt") {
        let text = std::fs::read_to_string(&path).expect("read");
        let formatted = format_source(&text).expect("formats");
        assert_eq!(format_source(&formatted).expect("formats again"), formatted);
        let name = path
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .to_string();
        insta::with_settings!({ snapshot_path => "../snapshots/fmt", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, formatted);
        });
    }
}

#[test]
fn fmt_rewrites_what_changes_and_check_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let messy = dir.path().join("messy.lens");
    let tidy = dir.path().join("tidy.lens");
    let broken = dir.path().join("broken.lens");
    let messy_text =
        "let  a=1 mm // a\nsurface s=sphere{radius:a,sense:convex,aperture:circle(radius:0.5mm)}\n";
    std::fs::write(&messy, messy_text).unwrap();
    std::fs::write(&tidy, "let a = 1 mm\n").unwrap();
    std::fs::write(&broken, "surface s = sphere {\n").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&messy, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    let names = ["messy.lens", "tidy.lens", "broken.lens"];

    let out = lensc(dir.path(), &[&["fmt", "--check"][..], &names].concat());
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(text(&out.stdout), "messy.lens\n");
    assert!(text(&out.stderr).contains("E0001"), "{}", text(&out.stderr));
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), messy_text);

    let out = lensc(dir.path(), &[&["fmt"][..], &names].concat());
    assert_eq!(out.status.code(), Some(1), "the broken file fails the run");
    assert!(text(&out.stderr).contains("E0001"));
    assert_eq!(
        std::fs::read_to_string(&messy).unwrap(),
        "let a = 1 mm // a\nsurface s = sphere { radius: a, sense: convex, aperture: circle(radius: 0.5 mm) }\n"
    );
    assert_eq!(
        std::fs::read_to_string(&broken).unwrap(),
        "surface s = sphere {\n"
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&messy).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640, "permissions kept");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 3, "no temporary file left behind");

    let out = lensc(dir.path(), &["fmt", "--check", "messy.lens", "tidy.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "");

    let out = lensc(dir.path(), &["fmt", "missing.lens"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("E0103"), "{}", text(&out.stderr));
}

// ---- random programs ----

/// Text the grammar skips between tokens: nothing, blanks, line breaks,
/// blank lines and comments of both kinds.
fn gap() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "",
        " ",
        " ",
        " ",
        "\n",
        "\n\n\n",
        " /* c */ ",
        "/*\n  b */",
        " // l\n",
        "\t",
    ])
}

fn name() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec!["a", "radius", "surface", "x", "sin", "conic", "tool"])
}

fn leaf() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "1", "2", "2.5e-3", "0.5 mm", "3 um/rev", "10°", "1 mm^-3", "s"
        ])
        .prop_map(str::to_string),
        prop::sample::select(vec!["x", "lens", "convex"]).prop_map(str::to_string),
        Just("\"a // b\"".to_string()),
    ]
}

/// An expression with gaps between its tokens (never inside a number and
/// its unit) and commas between entries, as the grammar allows.
fn expr() -> impl Strategy<Value = String> {
    leaf().prop_recursive(4, 24, 4, |inner| {
        let g = gap;
        prop_oneof![
            (inner.clone(), g(), op(), g(), inner.clone())
                .prop_map(|(a, g1, op, g2, b)| format!("{a}{g1} {op} {g2}{b}")),
            (g(), inner.clone(), g()).prop_map(|(g1, e, g2)| format!("({g1}{e}{g2})")),
            (g(), inner.clone()).prop_map(|(g1, e)| format!("-{g1}{e}")),
            prop::collection::vec((g(), inner.clone(), g()), 0..4).prop_map(|v| {
                let items: Vec<String> = v.iter().map(|(a, e, b)| format!("{a}{e}{b}")).collect();
                format!("[{}]", items.join(","))
            }),
            (
                name(),
                g(),
                prop::collection::vec((g(), name(), g(), inner.clone(), g()), 0..4)
            )
                .prop_map(|(f, g1, v)| {
                    let args: Vec<String> = v
                        .iter()
                        .map(|(a, n, b, e, c)| format!("{a}{n}{b}:{e}{c}"))
                        .collect();
                    format!("{f}{g1}({})", args.join(","))
                }),
            (
                name(),
                g(),
                prop::collection::vec((g(), name(), g(), inner, g()), 0..4)
            )
                .prop_map(|(base, g1, v)| {
                    let entries: Vec<String> = v
                        .iter()
                        .map(|(a, n, b, e, c)| format!("{a}{n}{b}:{e}{c}"))
                        .collect();
                    format!("{base}{g1}{{{}}}", entries.join(","))
                }),
        ]
    })
}

fn op() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec!["+", "-", "*", "/", "^", ".."])
}

fn item() -> impl Strategy<Value = String> {
    prop_oneof![
        // Two leaves and an operator: where a unit and an operator meet
        // (`2 mm ^ 2` is not `2 mm^2`, `1 mm / s` not `1 mm/s`).
        (leaf(), gap(), op(), gap(), leaf())
            .prop_map(|(a, g, op, h, b)| format!("let w = {a}{g} {op} {h}{b}")),
        (gap(), expr()).prop_map(|(g, e)| format!("let v ={g}{e}")),
        (gap(), expr()).prop_map(|(g, e)| format!("surface s{g}= {e}")),
        (gap(), name(), gap(), expr()).prop_map(|(g, n, h, e)| format!("job j {{{g}{n}:{h}{e}}}")),
        Just("use std::machines::linuxcnc_lathe".to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn random_programs_format_to_the_same_tree_and_stay_put(
        items in prop::collection::vec((item(), prop::sample::select(vec!["\n", "\n\n", "\n// c\n", "\n/* d */\n"])), 1..5)
    ) {
        let src: String = items.iter().map(|(i, sep)| format!("{i}{sep}")).collect();
        let (_, diags) = lensc_grammar::parse(&src, lensc_grammar::FileId(0));
        prop_assume!(!diags.iter().any(|d| d.is_error()));
        // `format_source` itself refuses (E0185) a layout that does not
        // parse back to the same tree with as many comments.
        let once = format_source(&src).map_err(|d| TestCaseError::fail(format!("{src:?}: {d:?}")))?;
        let twice = format_source(&once).map_err(|d| TestCaseError::fail(format!("{once:?}: {d:?}")))?;
        prop_assert_eq!(&once, &twice, "not idempotent for {:?}", src);
    }
}
