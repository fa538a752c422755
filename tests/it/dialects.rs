//! Every example job built in every dialect its machine offers besides its
//! own (the own dialect's programs are `examples.rs`'s snapshots): each
//! program is snapshot (abridged past 256 KB, with counts and a hash), and
//! each obeys its dialect's rules as written in `stdlib/dialects.lens`.

use crate::common;

use crate::common::{abridged, buildable_examples, root};
use lensc_build::driver::{Request, check_path, plan_and_emit};
use lensc_lang::loader::RealFs;

/// The rules a reader of each dialect would check first.
fn obeys(dialect: &str, program: &str) -> Result<(), String> {
    let lines: Vec<&str> = program.lines().collect();
    let code = |l: &&&str| !l.starts_with('(') && !l.starts_with(';') && !l.contains(" ; ");
    match dialect {
        "fanuc_0i_lathe" | "fanuc_0i_mill" => {
            if lines.first() != Some(&"%") || lines.last() != Some(&"%") {
                return Err("a Fanuc program starts and ends with %".into());
            }
            if !lines[1].starts_with('O') {
                return Err("the O number follows the first %".into());
            }
            for l in lines.iter().filter(code) {
                for w in l.split_whitespace() {
                    let digits = w[1..].bytes().filter(u8::is_ascii_digit).count();
                    if digits > 8 {
                        return Err(format!("more than 8 digits: {l}"));
                    }
                }
            }
        }
        "siemens_840d_lathe" | "siemens_840d_mill" => {
            if !lines[0].starts_with("%_N_") || !lines[0].ends_with("_MPF") {
                return Err(format!("not a Sinumerik main program name: {}", lines[0]));
            }
            // Parentheses only in a cycle call (`CYCLE832(…)`).
            if lines
                .iter()
                .any(|l| l.contains('(') && !l.starts_with("CYCLE832("))
            {
                return Err("Sinumerik comments are `;`".into());
            }
            if lines.last() != Some(&"M30") {
                return Err("a Sinumerik main program ends with M30".into());
            }
        }
        "heidenhain_iso" => {
            let body = &lines[1..lines.len() - 1];
            let mut last = 0u64;
            for l in body {
                let Some(n) = l
                    .strip_prefix('N')
                    .and_then(|r| r.split(' ').next())
                    .and_then(|n| n.parse::<u64>().ok())
                else {
                    return Err(format!("an unnumbered block: {l}"));
                };
                if n <= last && n != 1 {
                    return Err(format!("block numbers go back: {l}"));
                }
                last = n;
                if !l.ends_with(" *") {
                    return Err(format!("a block without its end: {l}"));
                }
            }
            heidenhain_start_and_end(body, "T", "G30 G17 ", "G31 G90 ", "G00 Z0 M91 *")?;
            if body.iter().any(|l| l.contains(" M19 ")) {
                return Err("M19 is the machine builder's: the TNC orients by G36".into());
            }
        }
        "heidenhain_tnc_klartext" => {
            let name = lines[0]
                .strip_prefix("0 BEGIN PGM ")
                .and_then(|r| r.strip_suffix(" MM"))
                .ok_or_else(|| format!("not a Klartext program start: {}", lines[0]))?;
            let last = lines.last().copied().unwrap_or("");
            if !last.ends_with(&format!(" END PGM {name} MM")) {
                return Err(format!("not closed by END PGM {name} MM: {last}"));
            }
            for (i, l) in lines.iter().enumerate() {
                let (n, rest) = l.split_once(' ').unwrap_or((l, ""));
                if n.parse::<usize>() != Ok(i) {
                    return Err(format!("block {i} numbered otherwise: {l}"));
                }
                if rest.starts_with('G') || rest.starts_with('N') || rest.contains(" G0") {
                    return Err(format!("G-code in Klartext: {l}"));
                }
                if rest.starts_with("L ") && !rest.contains(" R0") {
                    return Err(format!("an L block without R0: {l}"));
                }
            }
            heidenhain_start_and_end(
                &lines,
                "TOOL CALL",
                "BLK FORM 0.1 Z ",
                "BLK FORM 0.2 ",
                "L Z+0 R0 FMAX M91",
            )?;
        }
        "ultra_precision_lathe_gcode" => {
            if lines.iter().any(|l| l.contains("G8") || l.contains("G64")) {
                return Err("LinuxCNC words in an ultra-precision lathe program".into());
            }
        }
        other => return Err(format!("no rules for {other}")),
    }
    Ok(())
}

/// A TNC program's start and end (both languages): one tool call (its
/// block's first word `call`), the blank's least (`min`) and greatest
/// (`max`) corner before it, and the retract to the top of Z in machine
/// coordinates (`home`) before the program's end.
fn heidenhain_start_and_end(
    lines: &[&str],
    call: &str,
    min: &str,
    max: &str,
    home: &str,
) -> Result<(), String> {
    // A block's words after its number.
    let words = |l: &str| l.split_once(' ').map_or("", |(_, r)| r).to_string();
    let at = |head: &str| lines.iter().position(|l| words(l).starts_with(head));
    // Only one call names a tool (Klartext may restate the speed as
    // `TOOL CALL Z S…`).
    let naming = |l: &&&str| {
        words(l)
            .strip_prefix(call)
            .is_some_and(|r| r.trim_start().starts_with(|c: char| c.is_ascii_digit()))
    };
    let named = lines.iter().filter(naming).count();
    if named != 1 {
        return Err(format!("{named} tool calls naming a tool"));
    }
    let tool = lines
        .iter()
        .position(|l| naming(&l))
        .ok_or("no tool call")?;
    match (at(min), at(max)) {
        (Some(a), Some(b)) if a < b && b < tool => {}
        _ => return Err(format!("no blank ({min}then {max}) before the tool call")),
    }
    let end = lines
        .iter()
        .rposition(|l| words(l).starts_with("M30"))
        .ok_or("no M30")?;
    if !lines[..end].iter().any(|l| l.ends_with(home)) {
        return Err(format!("no `{home}` before the program's end"));
    }
    Ok(())
}

#[test]
fn every_example_builds_in_every_dialect_its_machine_offers() {
    let spool = tempfile::tempdir().expect("tmp");
    let mut built = 0;
    for ex in buildable_examples() {
        let rel = ex.strip_prefix(root()).expect("inside repo").to_path_buf();
        let checked = check_path(&RealFs, &ex).expect("readable");
        assert!(!checked.has_errors(), "{}", rel.display());
        for job in &checked.checked.jobs {
            for dialect in lensc_lang::lower::offered_dialects(job).iter().skip(1) {
                let request = Request {
                    job: Some(&job.name.name),
                    dialect: Some(dialect),
                    ..Request::default()
                };
                let (programs, diags) = plan_and_emit(
                    &checked,
                    request,
                    &rel.display().to_string(),
                    Some(spool.path()),
                );
                assert!(
                    !diags.iter().any(|d| d.is_error()),
                    "{} {} in {dialect}: {diags:?}",
                    rel.display(),
                    job.name.name
                );
                for p in programs {
                    let text = p.program.text().expect("program text");
                    obeys(dialect, &text)
                        .unwrap_or_else(|e| panic!("{} in {dialect}: {e}", p.program_name));
                    crate::complete_programs::complete(dialect, &text)
                        .unwrap_or_else(|e| panic!("{} in {dialect}: {e}", p.program_name));
                    assert_eq!(p.report.program.dialect, dialect.as_str());
                    let shown = if text.len() > common::WHOLE_SNAPSHOT_LIMIT {
                        abridged(&text)
                    } else {
                        text
                    };
                    let name = format!("{dialect}__{}", p.program_name);
                    insta::with_settings!({ snapshot_path => "../snapshots/dialects", prepend_module_to_snapshot => false, omit_expression => true }, {
                        insta::assert_snapshot!(name, shown);
                    });
                    built += 1;
                }
            }
        }
    }
    assert!(built >= 10, "only {built} programs in other dialects");
}

#[test]
fn a_dialect_the_machine_does_not_offer_is_refused_with_what_it_offers() {
    let ex = root().join("examples/lin2022_scraping.lens");
    let checked = check_path(&RealFs, &ex).expect("readable");
    let (programs, diags) = plan_and_emit(
        &checked,
        Request {
            job: Some("lin_oblate"),
            dialect: Some("fanuc_0i_lathe"),
            ..Request::default()
        },
        "x.lens",
        None,
    );
    assert!(programs.is_empty());
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, "E0148");
    let help = format!("{:?}", diags[0]);
    assert!(help.contains("heidenhain_iso"), "{help}");
}

#[test]
fn a_fanuc_lathe_program_is_in_diameter_with_radius_arc_centres() {
    // No example's machine runs a Fanuc 0i lathe (their resolutions are
    // finer than its 0.1 um): a mould insert on the 0.1 um stock lathe.
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("fanuc_lathe.lens");
    std::fs::write(
        &file,
        "use std::machines::linuxcnc_lathe\n\
         use std::tools::diamond_r496um\n\
         surface insert = conic { radius: 12 mm, conic: -0.6, sense: concave, aperture: circle(radius: 3 mm) }\n\
         strategy finish = profile_turning { feed: 2 um/rev, spindle_speed: 1000 rpm, chord_tolerance: 150 nm }\n\
         tool nose = diamond_r496um { control_point: tool_centre }\n\
         job fanuc_insert { surface: insert, tool: nose, machine: linuxcnc_lathe, strategy: finish }\n",
    )
    .expect("write");
    let checked = check_path(&RealFs, &file).expect("readable");
    assert!(!checked.has_errors());
    let (programs, diags) = plan_and_emit(
        &checked,
        Request {
            job: None,
            dialect: Some("fanuc_0i_lathe"),
            ..Request::default()
        },
        "fanuc_lathe.lens",
        None,
    );
    assert!(diags.is_empty(), "{diags:?}");
    let text = programs[0].program.text().expect("text");
    obeys("fanuc_0i_lathe", &text).expect("Fanuc rules");
    // X is the diameter: the first position is twice the nose centre's
    // radius at the rim (the tool is set to its centre here); the arcs' I stays a radius (the centre of the
    // last arc, which ends on the axis, is within its radius of it).
    let first_x: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("G0 X"))
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .expect("a rapid to X");
    assert!(first_x > 2.0 * 2.8 && first_x < 2.0 * 3.0, "{first_x}");
    // G-code system A (the 0i-TF's default): G99 feed per revolution, the
    // setup without G90 or G94 (turning cycles in system A).
    assert!(text.contains("\nG99 G1 "), "{text}");
    assert!(!text.contains("G90") && !text.contains("G94"), "{text}");
    assert!(text.contains("\nG3 X0. "), "{text}");
    insta::with_settings!({ snapshot_path => "../snapshots/dialects", prepend_module_to_snapshot => false, omit_expression => true }, {
        insta::assert_snapshot!("fanuc_0i_lathe__fanuc_insert.nc", text);
    });
}

/// Every word of a program's motion blocks, modal: (X, Z, C) after each
/// block that moves at a feed (G1), in the order written.
fn modal_feeds(program: &str) -> Vec<[f64; 3]> {
    let mut at = [f64::NAN; 3];
    let mut feeding = false;
    let mut out = Vec::new();
    for line in program.lines().filter(|l| !l.starts_with('(')) {
        let mut moved = false;
        for w in line.split_whitespace() {
            match w {
                "G0" => feeding = false,
                "G1" => feeding = true,
                _ => {}
            }
            for (k, letter) in ['X', 'Z', 'C'].into_iter().enumerate() {
                if let Some(v) = w.strip_prefix(letter) {
                    at[k] = v.parse().expect("number");
                    moved = true;
                }
            }
        }
        if moved && feeding {
            out.push(at);
        }
    }
    out
}

/// `modal_feeds` of a program whose fast tool servo is written on W
/// beside the Z slide: X, the tool tip Z + W (W at 0 until stated), C.
fn modal_tip_feeds(program: &str) -> Vec<[f64; 3]> {
    let mut at = [f64::NAN, f64::NAN, f64::NAN, 0.0];
    let mut feeding = false;
    let mut out = Vec::new();
    for line in program.lines().filter(|l| !l.starts_with('(')) {
        let mut moved = false;
        for w in line.split_whitespace() {
            match w {
                "G0" => feeding = false,
                "G1" => feeding = true,
                _ => {}
            }
            for (k, letter) in ['X', 'Z', 'C', 'W'].into_iter().enumerate() {
                if let Some(v) = w.strip_prefix(letter) {
                    at[k] = v.parse().expect("number");
                    moved = true;
                }
            }
        }
        if moved && feeding {
            // (The slide at 0 under the cut: the tip is W as printed.)
            out.push([at[0], at[1] + at[3], at[2]]);
        }
    }
    out
}

#[test]
fn a_fast_tool_servo_table_holds_the_same_points_as_the_linuxcnc_program() {
    let file = root().join("tests/jobs/fts_small_array.lens");
    let checked = check_path(&RealFs, &file).expect("readable");
    let build = |dialect: &str| {
        let (mut programs, diags) = plan_and_emit(
            &checked,
            Request {
                job: None,
                dialect: Some(dialect),
                ..Request::default()
            },
            "fts_small_array.lens",
            None,
        );
        assert!(diags.is_empty(), "{diags:?}");
        programs.remove(0)
    };
    let linuxcnc = build("linuxcnc");
    let table_built = build("ultra_precision_lathe_gcode");
    // Beside each program its set-up sheet; beside the table dialect's,
    // the table first.
    let names = |b: &lensc_build::output::Built| {
        b.beside.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>()
    };
    assert_eq!(names(&linuxcnc), ["corner_fts.setup.txt"]);
    assert_eq!(
        names(&table_built),
        ["corner_fts.fts", "corner_fts.setup.txt"]
    );
    let (name, table) = &table_built.beside[0];
    assert_eq!(name, "corner_fts.fts");
    let table = table.text().expect("table");
    let rows: Vec<[f64; 3]> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split(' ').map(|v| v.parse().expect("number")).collect();
            assert_eq!(v.len(), 3, "{l}");
            [v[0], v[1], v[2]]
        })
        .collect();
    // LinuxCNC's program carries the servo on W, the Z slide at 0: after
    // its plunge, the same points as the table's rows, X (Z + W) C
    // against C X W.
    let lin = modal_tip_feeds(&linuxcnc.program.text().expect("text"));
    let points = linuxcnc.report.to_json()["toolpath"]["cut_points"]
        .as_u64()
        .expect("n") as usize;
    assert_eq!(rows.len(), points);
    assert_eq!(lin.len(), points, "the plunge and a move per later point");
    assert_eq!(
        table_built.report.program.fts_table.map(|t| t.rows),
        Some(points)
    );
    for (row, m) in rows.iter().zip(&lin).skip(1) {
        assert_eq!([row[1], row[2], row[0]], *m);
    }
    // The table's program moves X and C a revolution a block and the table
    // has a row at each end.
    let program = table_built.program.text().expect("text");
    obeys("ultra_precision_lathe_gcode", &program).expect("rules");
    assert!(
        program.contains("\nM70 (FTS TABLE corner_fts.fts)\nG93 G1 Z0. F60.\n"),
        "{program}"
    );
    let blocks = modal_feeds(&program);
    let revolutions = (rows[rows.len() - 1][0] / 360.0).ceil() as usize;
    assert_eq!(
        blocks.len(),
        revolutions + 1,
        "the plunge, then a block per turn"
    );
    for b in &blocks[1..] {
        assert!(
            rows.iter().any(|r| r[0] == b[2] && r[1] == b[0]),
            "block X{} C{} is not a table row",
            b[0],
            b[2]
        );
    }
}
