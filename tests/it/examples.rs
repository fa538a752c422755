//! Every example checks clean (no errors, no warnings) and builds.

use crate::common::{
    Written, built_examples, examples, judged_whole_and_passed, lensc, root, surface_names, text,
};

#[test]
fn every_example_checks_clean() {
    let list = examples();
    assert!(!list.is_empty());
    for ex in list {
        let out = lensc(&root(), &["check", ex.to_str().expect("utf8")]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            ex.display(),
            text(&out.stderr)
        );
        assert!(
            out.stderr.is_empty(),
            "{} has warnings: {}",
            ex.display(),
            text(&out.stderr)
        );
    }
}

/// Builds every example (they must all build) and compares each program
/// with its reviewed snapshot; programs above `WHOLE_SNAPSHOT_LIMIT` are
/// snapshot abridged (see `common::abridged`). Every report written must
/// validate against the committed schema, `docs/report.schema.json`.
#[test]
fn example_programs_match_their_snapshots() {
    reports_follow_the_schema();
    let mut programs: Vec<(&String, &Written)> = built_examples()
        .iter()
        .flat_map(|b| &b.files)
        .filter(|(name, _)| name.ends_with(".ngc"))
        .collect();
    programs.sort_by_key(|(name, _)| *name);
    assert!(programs.len() >= 20, "{} programs", programs.len());
    for (name, file) in programs {
        let (name, program) = (name.clone(), file.snapshot());
        insta::with_settings!({ snapshot_path => "../snapshots/programs", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, program);
        });
    }
}

/// Validates every `*.report.json` in `dir` against the committed schema.
fn reports_follow_the_schema() {
    let schema_path = root().join("docs/report.schema.json");
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&schema_path).expect("schema"))
            .expect("the schema is JSON");
    let mut schemas = boon::Schemas::new();
    let mut compiler = boon::Compiler::new();
    compiler
        .add_resource("report.schema.json", schema)
        .expect("schema resource");
    let index = compiler
        .compile("report.schema.json", &mut schemas)
        .unwrap_or_else(|e| panic!("the report schema compiles: {e}"));
    let mut checked = 0;
    let reports = built_examples().iter().flat_map(|b| {
        let names = b.files.keys().filter(|n| n.ends_with(".report.json"));
        names.cloned().zip(b.reports())
    });
    for (name, report) in reports {
        if let Err(e) = schemas.validate(&report, index) {
            panic!("{name} does not follow the schema: {e:#}");
        }
        // The schema bites: a report with a key it does not document, or
        // without one it requires, fails.
        if checked == 0 {
            let mut extra = report.clone();
            extra["toolpath"]["undocumented"] = serde_json::json!(1);
            assert!(schemas.validate(&extra, index).is_err());
            let mut missing = report.clone();
            missing.as_object_mut().expect("object").remove("job");
            assert!(schemas.validate(&missing, index).is_err());
        }
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} reports");
}

/// The first 40 lines, the number of lines and bytes with the FNV-1a 64
/// hash of the whole text, and the last 3 lines.
#[test]
fn every_surface_of_every_example_samples() {
    for ex in examples() {
        for name in surface_names(&ex) {
            let out = lensc(
                &root(),
                &[
                    "sample",
                    ex.to_str().expect("utf8"),
                    "--surface",
                    &name,
                    "--grid",
                    "5",
                ],
            );
            assert_eq!(
                out.status.code(),
                Some(0),
                "{} {name}: {}",
                ex.display(),
                text(&out.stderr)
            );
            let csv = text(&out.stdout);
            let mut lines = csv.lines();
            assert_eq!(
                lines.next(),
                Some("x,y,z,dzdx,dzdy,curvature_x,curvature_y")
            );
            let rows: Vec<Vec<f64>> = lines
                .map(|l| l.split(',').map(|c| c.parse().expect("number")).collect())
                .collect();
            assert!(!rows.is_empty(), "{} {name}: no points", ex.display());
            assert!(
                rows.iter().flatten().all(|v| v.is_finite()),
                "{} {name}: {csv}",
                ex.display()
            );
        }
    }
}

/// Every program has its set-up sheet beside it, stating the control
/// point; one sheet per strategy family (the first example job of each,
/// by the report's `strategy` tag) is a reviewed snapshot.
#[test]
fn every_program_has_a_set_up_sheet_and_one_per_strategy_is_snapshot() {
    let mut first = std::collections::BTreeMap::new();
    let mut sheets = 0;
    for b in built_examples() {
        for name in b.files.keys().filter(|n| crate::common::is_program(n)) {
            let job = name.rsplit_once('.').map_or(name.as_str(), |(j, _)| j);
            let sheet = match b.files.get(&format!("{job}.setup.txt")) {
                Some(Written::Whole(bytes)) => text(bytes),
                _ => panic!("{}: {name} has no set-up sheet beside it", b.example),
            };
            assert!(
                sheet.contains("\ncontrol point  ") && sheet.contains("\nwork offset    "),
                "{}: {job}'s sheet states no control point or work offset:\n{sheet}",
                b.example
            );
            sheets += 1;
            let strategy = b.report(job)["toolpath"]["strategy"]
                .as_str()
                .expect("strategy tag")
                .to_string();
            first.entry(strategy).or_insert(sheet);
        }
    }
    assert!(sheets >= 20, "{sheets} sheets");
    assert!(first.len() >= 5, "strategies: {:?}", first.keys());
    for (strategy, sheet) in first {
        insta::with_settings!({ snapshot_path => "../snapshots/setup_sheets", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(strategy, sheet);
        });
    }
}

/// Issue #29's promise, audited: a green build means a good part. Every
/// example job is judged by the gate over its whole part (no window, no
/// `accept: none`, no criterion or lenslet missed, nothing left
/// unmeasured), so none passes while its whole part misses its limits.
#[test]
fn every_example_passes_on_its_whole_part() {
    let mut judged = 0;
    for b in built_examples() {
        for report in b.reports() {
            if let Err(why) = judged_whole_and_passed(&report) {
                panic!("{}: {}: {why}", b.example, report["job"]);
            }
            judged += 1;
        }
    }
    assert!(judged >= 20, "only {judged} jobs");
}

/// The audit bites: a report judged on a window, or with a criterion or a
/// lenslet missed, or not by the gate, is named.
#[test]
fn the_whole_part_audit_names_what_it_finds() {
    let good = serde_json::json!({
        "job": "j",
        "acceptance": {
            "mode": "gate",
            "passed": true,
            "judged": { "area": "whole_part", "words": "the whole part" },
            "criteria": [{ "criterion": "form_pv", "passed": true }],
            "lenslets": [{ "criterion": "form_pv", "passed": true }],
        }
    });
    assert_eq!(judged_whole_and_passed(&good), Ok(()));
    let with = |path: &[&str], v: serde_json::Value| {
        let mut r = good.clone();
        let mut at = &mut r["acceptance"];
        for p in path {
            at = if let Ok(i) = p.parse::<usize>() {
                &mut at[i]
            } else {
                &mut at[*p]
            };
        }
        *at = v;
        r
    };
    for bad in [
        with(&["mode"], "warn".into()),
        with(&["mode"], "none".into()),
        with(&["judged", "area"], "window".into()),
        with(&["criteria"], serde_json::json!([])),
        with(&["criteria", "0", "passed"], false.into()),
        with(&["lenslets", "0", "passed"], false.into()),
        with(&["passed"], false.into()),
    ] {
        assert!(judged_whole_and_passed(&bad).is_err(), "{bad}");
    }
}

/// A program that states its blank (Heidenhain ISO's G30/G31) has it on
/// its set-up sheet as the stock, not "the job states none" (issue #28).
#[test]
fn a_set_up_sheet_states_the_blank_its_program_states() {
    let dir = tempfile::tempdir().expect("tmp");
    let src = crate::common::root().join("examples/lin2022_scraping.lens");
    let out = crate::common::lensc(
        dir.path(),
        &[
            "build",
            src.to_str().expect("utf8"),
            "--job",
            "lin_imaging_sphere",
            "--dialect",
            "heidenhain_iso",
            "--out",
            "out",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let program =
        std::fs::read_to_string(dir.path().join("out/lin_imaging_sphere.I")).expect("program");
    let sheet = std::fs::read_to_string(dir.path().join("out/lin_imaging_sphere.setup.txt"))
        .expect("sheet");
    let g30 = program
        .lines()
        .find(|l| l.contains(" G30 "))
        .expect("the program states its blank");
    let stock = sheet
        .lines()
        .find(|l| l.starts_with("stock "))
        .expect("a stock line");
    assert!(stock.contains("blank form (G30/G31)"), "{stock}");
    // The least corner's Z, as the program prints it.
    let z = g30
        .split_whitespace()
        .find_map(|w| w.strip_prefix('Z'))
        .expect("Z")
        .trim_end_matches('.');
    assert!(stock.contains(&format!("Z {z} .. ")), "{g30} / {stock}");
}
