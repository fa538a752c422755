//! Every example program's header states its part exactly: the surface
//! line is parsed back from the program text and every number in it (radius,
//! conic, A-, Q- and Zernike terms, pitches, apertures, …), read through
//! its unit as a `.lens` file reads it, is bit for bit the f64 lowering
//! produced from the source; no number in it is `-0`.

use crate::common::{built_examples, root};
use lensc_build::driver::check_path;
use lensc_lang::loader::RealFs;
use lensc_lang::value::{Object, Value};

/// One `name value` of a header's surface words.
#[derive(Debug)]
enum Item {
    /// `name 1.5 mm`, `name -1.2e-17 1/mm^3`, `name a .. b unit`: the
    /// figures and the unit after them.
    Figures(String, Vec<String>, String),
    /// `name [kind, …]`.
    Nested(String, Vec<Item>),
    /// `name word`, or the kind alone.
    Word(String),
}

/// The program's header comments as one text per comment, folded lines
/// (`(…,)` then `(  …)`) joined.
fn header_comments(program: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for line in program.lines() {
        let Some(text) = line
            .strip_prefix('(')
            .and_then(|l| l.strip_suffix(')'))
            .or_else(|| line.strip_prefix("; "))
        else {
            if out.is_empty() {
                continue;
            }
            break;
        };
        match (out.last_mut(), text.strip_prefix("  ")) {
            (Some(last), Some(rest)) if last.ends_with(',') => {
                last.push(' ');
                last.push_str(rest);
            }
            _ => out.push(text.to_string()),
        }
    }
    out
}

/// Splits `s` at `, ` outside brackets.
fn split_top(s: &str) -> Vec<&str> {
    let (mut depth, mut start, mut out) = (0i32, 0, Vec::new());
    let bytes = s.as_bytes();
    for i in 0..bytes.len() {
        match bytes[i] {
            b'[' => depth += 1,
            b']' => depth -= 1,
            b',' if depth == 0 && bytes.get(i + 1) == Some(&b' ') => {
                out.push(&s[start..i]);
                start = i + 2;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out
}

fn is_figure(w: &str) -> bool {
    w.parse::<f64>().is_ok()
}

/// The items of a surface's words (`kind, name value unit, …`).
fn parse(words: &str) -> Vec<Item> {
    split_top(words)
        .into_iter()
        .map(|part| {
            if let Some(open) = part.find(" [") {
                let inner = part[open + 2..].strip_suffix(']').expect("closed bracket");
                return Item::Nested(part[..open].to_string(), parse(inner));
            }
            let tokens: Vec<&str> = part.split(' ').collect();
            match tokens.iter().position(|t| is_figure(t)) {
                None => Item::Word(part.to_string()),
                Some(k) => {
                    let rest = &tokens[k..];
                    let (figures, unit) = match rest {
                        [a, "..", b, unit @ ..] => (vec![a.to_string(), b.to_string()], unit),
                        [a, unit @ ..] => (vec![a.to_string()], unit),
                        [] => unreachable!(),
                    };
                    Item::Figures(tokens[..k].join(" "), figures, unit.join(" "))
                }
            }
        })
        .collect()
}

/// Reads `figure unit` back as a `.lens` file would, in base units.
fn read_back(figure: &str, unit: &str) -> f64 {
    let v: f64 = figure.parse().expect("a number");
    assert!(
        !(v == 0.0 && v.is_sign_negative()),
        "a negative zero: {figure}"
    );
    let size = if unit.is_empty() {
        1.0
    } else {
        lensc_lang::units::size_of(unit).unwrap_or_else(|| panic!("unit {unit}"))
    };
    v * size
}

fn same(a: f64, b: f64) -> bool {
    // A signed zero states the same part; every other value bit for bit.
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0)
}

/// Compares every number of `o` with the header's `items`; returns how many
/// figures were compared. `turned`: the lathe's form, where the aperture
/// is stated as `aperture radius R mm` (or `annular aperture a .. b mm`).
fn compare(o: &Object, items: &[Item], at: &str) -> usize {
    let find = |name: &str| {
        items.iter().find(|i| match i {
            Item::Figures(n, ..) | Item::Nested(n, _) => n == name,
            Item::Word(_) => false,
        })
    };
    let mut compared = 0;
    for f in &o.fields {
        let here = format!("{at}.{}", f.name);
        let expected: Vec<f64> = match &f.value {
            Value::Num(v, _) => vec![*v],
            Value::Range(a, b, _) => vec![*a, *b],
            Value::Object(inner) => {
                match find(&f.name) {
                    Some(Item::Nested(_, sub)) => compared += compare(inner, sub, &here),
                    _ if f.name == "aperture" => {
                        // The lathe's form: the aperture's radius as lowering takes it.
                        let r = lensc_lang::domain::aperture_radius(inner).expect("radius");
                        let inner_r = lensc_lang::domain::aperture_inner_radius(inner);
                        let (name, want) = if inner_r > 0.0 {
                            ("annular aperture", vec![inner_r, r])
                        } else {
                            ("aperture radius", vec![r])
                        };
                        let Some(Item::Figures(_, figs, unit)) = find(name) else {
                            panic!("{here}: no `{name}` in {items:?}");
                        };
                        for (fig, w) in figs.iter().zip(&want) {
                            assert!(
                                same(read_back(fig, unit), *w),
                                "{here}: {fig} {unit} vs {w:e}"
                            );
                        }
                        compared += want.len();
                    }
                    other => panic!("{here}: {other:?} in {items:?}"),
                }
                continue;
            }
            _ => continue,
        };
        if expected.iter().any(|v| v.is_nan()) {
            continue;
        }
        let Some(Item::Figures(_, figs, unit)) = find(&f.name) else {
            panic!("{here}: not stated in {items:?}");
        };
        assert_eq!(figs.len(), expected.len(), "{here}");
        for (fig, want) in figs.iter().zip(&expected) {
            let got = read_back(fig, unit);
            assert!(
                same(got, *want),
                "{here}: `{fig} {unit}` reads {got:e}, lowering has {want:e}"
            );
        }
        compared += expected.len();
    }
    compared
}

#[test]
fn every_example_header_states_its_surface_exactly() {
    let mut programs = 0;
    let mut figures = 0;
    for b in built_examples() {
        let c = check_path(&RealFs, &root().join(&b.example)).expect("read");
        for job in &c.checked.jobs {
            let name = &job.name.name;
            let (_, program) = b
                .files
                .iter()
                .find(|(f, _)| {
                    f.strip_prefix(name.as_str())
                        .is_some_and(|r| r.starts_with('.'))
                        && !f.ends_with(".report.json")
                })
                .unwrap_or_else(|| panic!("{}: no program of {name}", b.example));
            let comments = header_comments(&program.snapshot());
            let prefix = format!(
                "surface {}: ",
                job.part_names.get("surface").cloned().unwrap_or_default()
            );
            let line = comments
                .iter()
                .find_map(|l| {
                    l.strip_prefix("surface ")
                        .and_then(|l| l.split_once(": "))
                        .map(|(_, w)| w)
                })
                .unwrap_or_else(|| panic!("{name}: no surface line ({prefix}) in {comments:?}"));
            // The lathe's form ends in `; convex: …` or `; +Z out …`.
            let words = line.split("; ").next().expect("words");
            let items = parse(words);
            let Some(Value::Object(surface)) =
                lensc_lang::value::field(&job.fields, "surface").map(|f| &f.value)
            else {
                panic!("{name}: no surface");
            };
            let Some(Item::Word(kind)) = items.first() else {
                panic!("{name}: no kind in {words}");
            };
            assert_eq!(kind, surface.kind.name, "{name}");
            figures += compare(surface, &items[1..], name);
            programs += 1;
        }
    }
    assert!(programs >= 20, "only {programs} programs");
    assert!(figures >= 100, "only {figures} figures compared");
    println!("{programs} headers, {figures} figures read back bit for bit");
}

#[test]
fn a_header_states_small_high_order_terms_exactly() {
    // The lens: A10…A16 of order 1e-17 printed with 12 decimals
    // read `A10 -0`, `A12 0`. Now each reads back to its f64.
    let src = "surface s = asphere { radius: 8.5 mm, conic: -0.62, A4: 2.1e-4 mm^-3, A6: -3.4e-6 mm^-5, \
               A8: 1.234e-9 mm^-7, A10: -1.2e-17 mm^-9, A12: 3.4e-19 mm^-11, A14: 5e-21 mm^-13, \
               A16: -7.77e-23 mm^-15, sense: convex, aperture: circle(radius: 3 mm) }\n";
    let c = lensc_lang::check_text(&RealFs, "s.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let o = c.checked.declarations.get("s").expect("s");
    let words = lensc_lang::lower::describe(o);
    assert!(
        !words.contains(" -0,") && !words.contains(" 0 1/"),
        "{words}"
    );
    let items = parse(&words);
    assert_eq!(compare(o, &items[1..], "s"), 10, "{words}");
}

/// Builds `src` (written to a job file in a new directory) and returns the
/// program `NAME.EXT`'s text and the report's JSON.
fn build_text(src: &str, program: &str) -> (String, serde_json::Value) {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("job.lens");
    std::fs::write(&file, src).expect("write");
    let out = crate::common::lensc(
        dir.path(),
        &["build", file.to_str().expect("utf8"), "--out", "out"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        crate::common::text(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.path().join("out").join(program)).expect("program");
    let stem = program.rsplit_once('.').expect("extension").0;
    let report =
        std::fs::read_to_string(dir.path().join("out").join(format!("{stem}.report.json")))
            .expect("report");
    (text, serde_json::from_str(&report).expect("json"))
}

/// The header's `estimated cutting time` in seconds (`1 h 2 min 3 s`).
fn header_time(program: &str) -> f64 {
    let line = header_comments(program)
        .into_iter()
        .find_map(|c| {
            c.strip_prefix("estimated cutting time ")
                .map(str::to_string)
        })
        .unwrap_or_else(|| panic!("no estimated cutting time in\n{program}"));
    // The figure alone (a roller's goes on: "at the spindle's pace …").
    let figure = line.split(" at ").next().unwrap_or(&line);
    let words: Vec<&str> = figure.split(' ').collect();
    words
        .chunks(2)
        .map(|w| {
            let n: f64 = w[0].parse().expect("figure");
            n * match w[1] {
                "h" => 3600.0,
                "min" => 60.0,
                "s" => 1.0,
                u => panic!("unit {u}"),
            }
        })
        .sum()
}

#[test]
fn servo_and_raster_headers_state_the_cutting_time_of_the_report() {
    // Issue #29: only turning and grinding headers stated it.
    let servo =
        std::fs::read_to_string(root().join("tests/jobs/fts_small_array.lens")).expect("job");
    let raster = "use std::machines::generic_3axis_mill\nuse std::tools::microshaper_r85um\n\
        surface s = sphere { radius: 4 mm, sense: convex, aperture: circle(diameter: 0.4 mm) }\n\
        strategy scrape = raster { along: x, stepover: 20 um, feed: 200 mm/min, chord_tolerance: 400 nm }\n\
        job scraped { surface: s, tool: microshaper_r85um, machine: generic_3axis_mill, strategy: scrape }\n";
    for (src, program) in [(servo.as_str(), "corner_fts.ngc"), (raster, "scraped.ngc")] {
        let (text, report) = build_text(src, program);
        let stated = header_time(&text);
        let reported = report["toolpath"]["cutting_time_s"]
            .as_f64()
            .expect("cutting_time_s");
        assert!(
            (stated - reported).abs() <= 0.5 + 0.01 * reported,
            "{program}: header {stated} s, report {reported} s"
        );
    }
}

#[test]
fn a_roller_header_states_the_cutting_time_of_the_report() {
    // Issue #29: roller headers had none (the cycles of each pass come
    // from the design's survey, which now runs before the header).
    let roller = std::fs::read_to_string(root().join("tests/jobs/roller_small.lens")).expect("job");
    let (text, report) = build_text(&roller, "roller_small.ngc");
    let stated = header_time(&text);
    let reported = report["toolpath"]["cutting_time_s"]
        .as_f64()
        .expect("cutting_time_s");
    assert!(
        (stated - reported).abs() <= 0.5 + 0.01 * reported,
        "header {stated} s, report {reported} s"
    );
}

#[test]
fn a_header_prints_a_spindle_cap_and_a_tolerance_as_stated() {
    // Issue #29: `spindle_cap: 1000 rpm` printed `capped at 999 rpm`, and
    // a tolerance written in µm printed `200.00000000000003 nm`.
    let turning = "use std::machines::ultra_precision_lathe\nuse std::tools::diamond_r500um\n\
        surface s = sphere { radius: 20 mm, sense: convex, aperture: circle(diameter: 2 mm) }\n\
        strategy f = profile_turning { feed: 5 um/rev, surface_speed: 3 m/min, spindle_cap: 1000 rpm, chord_tolerance: 0.2 um }\n\
        job turned { surface: s, tool: diamond_r500um, machine: ultra_precision_lathe, strategy: f }\n";
    let (text, _) = build_text(turning, "turned.ngc");
    assert!(text.contains("capped at 1000 rpm"), "{text}");
    // The small array at a 0.2 µm tolerance states what that tolerance
    // allows (its own limits are for 50 nm: at 0.2 µm it measures 205 nm
    // PV, 13.6 nm RMS, 205 nm high and lags by 513 nm).
    let stated = "accept: { form_pv: 200 nm, form_rms: 10 nm, max_residual: 200 nm, max_following_error: 500 nm }";
    let servo =
        std::fs::read_to_string(root().join("tests/jobs/fts_small_array.lens")).expect("job");
    assert!(servo.contains(stated), "the small array states its limits");
    let servo = servo
        .replace("chord_tolerance: 50 nm", "chord_tolerance: 0.2 um")
        .replace(
            stated,
            "accept: { form_pv: 402 nm, form_rms: 100.5 nm, max_gouge: 201 nm, max_residual: 201 nm, max_following_error: 600 nm }",
        );
    let (text, _) = build_text(&servo, "corner_fts.ngc");
    let head = header_comments(&text).join("\n");
    assert!(head.contains("path tolerance 200 nm"), "{head}");
    assert!(!head.contains("00000000"), "{head}");
}
