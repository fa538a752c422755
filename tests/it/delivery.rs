//! Delivery (issue 31, item 3): a program larger than its machine's
//! `delivery` allows is split into parts a main program calls, and the set
//! reads back as the whole: `lensc verify` follows the calls and finds
//! nothing, the moves read back from the set are those of the unsplit
//! build, and LinuxCNC's own interpreter makes the same canonical moves.

use std::path::Path;

use crate::common::{lensc, text};
use lensc_runtime::dialect::{Dialect, PartCalls};
use lensc_runtime::reader::{self, MachineLimits};

/// Lin's oblate scraped on the generic mill (LinuxCNC), with `delivery`.
fn job(delivery: &str) -> String {
    format!(
        "use std::machines::generic_3axis_mill\n\
         use std::tools::microshaper_r85um\n\
         machine m = generic_3axis_mill {{ {delivery} }}\n\
         surface s = conic {{ radius: 3 mm, conic: 10, sense: convex, aperture: circle(diameter: 1.6 mm) }}\n\
         strategy scrape = raster {{ along: x, direction: one_way, stepover: 10 um, chord_tolerance: 200 nm, lin_angle: 5 deg, feed: 100 mm/min, retract: 0.5 mm }}\n\
         job sp {{ surface: s, tool: microshaper_r85um, machine: m, strategy: scrape, accept: none }}\n"
    )
}

fn build(dir: &Path, delivery: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("job.lens"), job(delivery)).expect("write");
    let out = lensc(dir, &["build", "job.lens", "--out", "out"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    dir.join("out")
}

/// LinuxCNC's part calls as `stdlib/dialects.lens` states them.
fn linuxcnc() -> Dialect {
    Dialect {
        parts: Some(PartCalls {
            call: "O<{part}> call".into(),
            name: "{job}_{k}".into(),
            extension: "ngc".into(),
            start: vec!["O<{part}> sub".into()],
            end: vec!["O<{part}> endsub".into(), "M2".into()],
            continuous: true,
        }),
        ..Dialect::linuxcnc()
    }
}

const MILL: MachineLimits = MachineLimits {
    lathe: false,
    travel: [None; 4],
    max_feed: None,
    max_spindle_rpm: None,
};

#[test]
fn a_split_program_reads_back_as_the_whole() {
    let split_dir = tempfile::tempdir().expect("tmp");
    let whole_dir = tempfile::tempdir().expect("tmp");
    let limit = 20_000;
    let split = build(
        split_dir.path(),
        &format!("delivery: {{ link: data_server, file_limit: {limit}, rate: 1000000 }}"),
    );
    let whole = build(whole_dir.path(), "delivery: { link: disk }");
    let whole_text = std::fs::read_to_string(whole.join("sp.ngc")).expect("whole program");
    assert!(whole_text.len() > 3 * limit, "{} bytes", whole_text.len());
    let main = std::fs::read_to_string(split.join("sp.ngc")).expect("main program");
    let d = linuxcnc();
    let parts = reader::parts::part_files(&main, &d, "sp");
    assert!(parts.len() >= 3, "{} parts:\n{main}", parts.len());
    for p in &parts {
        let bytes = std::fs::metadata(split.join(p)).expect("a part").len();
        assert!(bytes <= limit as u64, "{p}: {bytes} bytes");
    }
    // The report names the parts.
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(split.join("sp.report.json")).expect("report"),
    )
    .expect("json");
    let listed = report["program"]["delivery"]["parts"]
        .as_array()
        .expect("parts listed")
        .len();
    assert_eq!(listed, parts.len());
    // `lensc verify` reads the set as one program and finds nothing.
    let v = lensc(split_dir.path(), &["verify", "out/sp.ngc"]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v.stderr));
    assert!(
        text(&v.stderr).contains("nothing found"),
        "{}",
        text(&v.stderr)
    );
    // The moves read back from the set are the whole program's.
    let mut load = |n: &str| std::fs::read_to_string(split.join(n)).map_err(|e| e.to_string());
    let assembled = reader::parts::assemble(&main, &d, "sp", &mut load).expect("assembles");
    let (found, moves) = reader::read_moves(&assembled, &d, &MILL);
    let (_, whole_moves) = reader::read_moves(&whole_text, &d, &MILL);
    assert!(found.is_empty(), "{found:?}");
    assert!(whole_moves.len() > 2000);
    assert_eq!(moves, whole_moves);
    // A part removed: verify refuses the set.
    std::fs::remove_file(split.join(&parts[1])).expect("remove");
    let v = lensc(split_dir.path(), &["verify", "out/sp.ngc"]);
    assert_eq!(v.status.code(), Some(1), "{}", text(&v.stderr));
}

/// LinuxCNC's interpreter (`rs274`, where installed) follows the O-word
/// calls from the main program's directory and makes the same canonical
/// moves as from the whole program.
#[test]
fn rs274_runs_the_split_set_as_the_whole() {
    if std::process::Command::new("rs274")
        .arg("-h")
        .output()
        .is_err()
    {
        eprintln!("rs274 not installed: skipped");
        return;
    }
    let split_dir = tempfile::tempdir().expect("tmp");
    let whole_dir = tempfile::tempdir().expect("tmp");
    let split = build(
        split_dir.path(),
        "delivery: { link: data_server, file_limit: 20000, rate: 1000000 }",
    );
    let whole = build(whole_dir.path(), "delivery: { link: disk }");
    let canonical = |dir: &Path| -> Vec<String> {
        let out = std::process::Command::new("rs274")
            .current_dir(dir)
            .args(["-g", "sp.ngc"])
            .output()
            .expect("rs274");
        assert!(out.status.success(), "{}", text(&out.stdout));
        text(&out.stdout)
            .lines()
            .filter(|l| l.contains("STRAIGHT_") || l.contains("ARC_FEED"))
            .map(|l| l.split_once("N..... ").map_or(l, |(_, m)| m).to_string())
            .collect()
    };
    let (a, b) = (canonical(&split), canonical(&whole));
    assert!(b.len() > 2000);
    assert_eq!(a, b);
}
