//! Programs written with the controller's splines (`interpolation:
//! spline`, issue #31): one raster job built with Fanuc's NURBS (G06.2)
//! and with lines and arcs cuts the same form, as each program's text is
//! read back and simulated; the spline program is read clean by `lensc
//! verify`, says what it needs in its header and set-up sheet, and takes a
//! fraction of the planned moves' blocks; a dialect without a spline
//! refuses the job (E0182) and writes nothing.

use crate::common::{lensc, text};

/// Seed 000's hyperboloid (Lin 2022) scraped on the generic mill, at a
/// 20 µm stepover to keep the test short: once with splines, once not,
/// in a Fanuc mill dialect without arcs (with them, every pass of this
/// conic is an arc or two, shorter than any spline: `benches/splines`).
const JOBS: &str = "use std::machines::generic_3axis_mill
use std::tools::microshaper_r85um
dialect fanuc_lines = fanuc_0i_mill { arc_planes: [] }
machine mill = generic_3axis_mill { dialect: fanuc_lines }
surface hyperboloid = conic { radius: 1 mm, conic: -20, sense: convex, aperture: circle(diameter: 1.6 mm) }
strategy scrape = raster { along: x, direction: one_way, stepover: 20 um, chord_tolerance: 200 nm, lin_angle: 5 deg, feed: 100 mm/min, retract: 0.05 mm }
job with_splines { surface: hyperboloid, tool: microshaper_r85um, machine: mill, strategy: scrape, interpolation: spline, accept: { form_pv: 300 nm, form_rms: 50 nm, max_gouge: 150 nm, uncut_area: 0 } }
job with_lines { surface: hyperboloid, tool: microshaper_r85um, machine: mill, strategy: scrape, accept: { form_pv: 300 nm, form_rms: 50 nm, max_gouge: 150 nm, uncut_area: 0 } }
";

fn measured(dir: &std::path::Path, job: &str, criterion: &str) -> f64 {
    let report =
        std::fs::read_to_string(dir.join(format!("out/{job}.report.json"))).expect("report");
    let r: serde_json::Value = serde_json::from_str(&report).expect("json");
    r["acceptance"]["criteria"]
        .as_array()
        .expect("criteria")
        .iter()
        .find(|c| c["criterion"] == criterion)
        .and_then(|c| c["measured"].as_f64())
        .expect("measured")
}

#[test]
fn a_spline_program_cuts_the_form_its_lines_program_cuts() {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("jobs.lens"), JOBS).expect("write");
    let out = lensc(dir.path(), &["build", "jobs.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let program = std::fs::read_to_string(dir.path().join("out/with_splines.nc")).expect("nc");
    let lines = std::fs::read_to_string(dir.path().join("out/with_lines.nc")).expect("nc");
    assert!(program.contains("\nG06.2 P4 K0. "), "no NURBS block");
    assert!(!lines.contains("G06.2"));
    // The header's line, folded over comment lines (`(  ` continues one).
    let all: Vec<&str> = program.lines().collect();
    let i = all
        .iter()
        .position(|l| l.starts_with("(interpolation: NURBS"))
        .expect("the header names the interpolation");
    let header: String = std::iter::once(all[i])
        .chain(
            all[i + 1..]
                .iter()
                .copied()
                .take_while(|l| l.starts_with("(  ")),
        )
        .map(|l| l.trim_start_matches('(').trim_end_matches(')').trim())
        .collect::<Vec<_>>()
        .join(" ");
    assert!(header.contains("needs the control"), "{header}");
    let sheet =
        std::fs::read_to_string(dir.path().join("out/with_splines.setup.txt")).expect("sheet");
    assert!(sheet.contains("interpolation  NURBS"), "{sheet}");
    // The spline program as the control reads it: clean.
    let verify = lensc(dir.path(), &["verify", "out/with_splines.nc"]);
    assert_eq!(verify.status.code(), Some(0), "{}", text(&verify.stderr));
    // The same form within what the fit may move the path: its share of
    // the tolerance (30 nm) and the rounding of three axes to 0.1 um.
    let limit = 30.0 + 0.05 * 3f64.sqrt() * 1e3;
    for c in ["form_pv", "form_rms", "max_gouge"] {
        let (s, l) = (
            measured(dir.path(), "with_splines", c),
            measured(dir.path(), "with_lines", c),
        );
        assert!(
            (s - l).abs() <= limit,
            "{c}: {s} nm with splines, {l} with lines"
        );
    }
    // Fewer blocks than the planned moves': the header counts both.
    let number_before = |words: &str| -> usize {
        let head = &header[..header.find(words).expect(words)];
        let digits: String = head
            .chars()
            .rev()
            .skip_while(|c| *c == ' ')
            .take_while(|c| c.is_ascii_digit())
            .collect();
        digits
            .chars()
            .rev()
            .collect::<String>()
            .parse()
            .expect("a count")
    };
    let (after, before) = (number_before(" blocks of moves"), number_before(" planned"));
    assert!(after * 4 <= before, "{after} blocks of {before}: {header}");
    // A fraction of the lines program's blocks.
    let blocks = |p: &str| p.lines().filter(|l| !l.starts_with('(')).count();
    assert!(
        blocks(&program) <= blocks(&lines),
        "{} > {}",
        blocks(&program),
        blocks(&lines)
    );
}

#[test]
fn a_dialect_without_a_spline_refuses_it_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("jobs.lens"), JOBS).expect("write");
    // The generic mill's own dialect, LinuxCNC: G5.2 is in XY only.
    let jobs = JOBS.replace("machine: mill", "machine: generic_3axis_mill");
    std::fs::write(dir.path().join("jobs.lens"), jobs).expect("write");
    let out = lensc(dir.path(), &["build", "jobs.lens"]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("[E0182]"), "{err}");
    // The help names the machine's own dialects that have one, as flags.
    assert!(
        err.contains("`lensc build --dialect fanuc_0i_mill`")
            && err.contains("`lensc build --dialect siemens_840d_mill`"),
        "{err}"
    );
    assert!(!dir.path().join("out/with_splines.ngc").exists());
}

/// The same hyperboloid in Siemens' dialect without arcs: BSPLINE blocks
/// with one knot spacing PL in every block, read clean by `lensc
/// verify`, the same form as the lines program within what the fit may
/// move the path, and under a third of its blocks. A PL changed in one
/// block is refused by the reader (E0340) at that word.
#[test]
fn a_siemens_b_spline_program_reads_clean_and_cuts_the_lines_form() {
    let dir = tempfile::tempdir().expect("tmp");
    let jobs = JOBS
        .replace(
            "dialect fanuc_lines = fanuc_0i_mill",
            "dialect sie_lines = siemens_840d_mill",
        )
        .replace("{ dialect: fanuc_lines }", "{ dialect: sie_lines }");
    std::fs::write(dir.path().join("jobs.lens"), jobs).expect("write");
    let out = lensc(dir.path(), &["build", "jobs.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let program = std::fs::read_to_string(dir.path().join("out/with_splines.MPF")).expect("MPF");
    let lines = std::fs::read_to_string(dir.path().join("out/with_lines.MPF")).expect("MPF");
    assert!(program.contains("\nBSPLINE SD=3 PL="), "no B spline block");
    assert!(!lines.contains("BSPLINE"));
    assert!(program.contains("; interpolation: B spline"), "header");
    let verify = lensc(dir.path(), &["verify", "out/with_splines.MPF"]);
    assert_eq!(verify.status.code(), Some(0), "{}", text(&verify.stderr));
    let limit = 30.0 + 0.05 * 3f64.sqrt() * 1e3;
    for c in ["form_pv", "form_rms", "max_gouge"] {
        let (s, l) = (
            measured(dir.path(), "with_splines", c),
            measured(dir.path(), "with_lines", c),
        );
        assert!(
            (s - l).abs() <= limit,
            "{c}: {s} nm with splines, {l} with lines"
        );
    }
    let blocks = |p: &str| p.lines().filter(|l| !l.starts_with(';')).count();
    assert!(
        blocks(&program) * 3 <= blocks(&lines),
        "{} vs {}",
        blocks(&program),
        blocks(&lines)
    );
    // One block's PL changed: the curve's spacing is no longer one.
    let i = program.find("\nPL=").expect("a second block") + 4;
    let bad = format!("{}9{}", &program[..i], &program[i..]);
    std::fs::write(dir.path().join("bad.MPF"), bad).expect("write");
    let verify = lensc(dir.path(), &["verify", "bad.MPF"]);
    assert_eq!(verify.status.code(), Some(1));
    let err = text(&verify.stderr);
    assert!(
        err.contains("[E0340]") && err.contains("one spacing"),
        "{err}"
    );
}

/// A build reads its program's text once, for the simulation and the
/// read-back both (the reader's findings by the job's machine kept from
/// the simulation's reading): the spline program's NURBS blocks, sampled
/// finely, were read twice.
#[test]
fn a_raster_build_reads_its_program_once() {
    let c = lensc_lang::check_text(&lensc_lang::loader::RealFs, "jobs.lens", JOBS.as_bytes());
    assert!(!c.has_errors());
    let prov = lensc_runtime::post::Provenance {
        source: "jobs.lens".into(),
        source_hash: 0,
        lensc_version: "test".into(),
    };
    for job in &c.checked.jobs {
        let limits = lensc_build::job::Limits::default();
        let (spec, _) = lensc_build::pipeline::lower(job, None, &limits).expect("lowers");
        let before = lensc_runtime::reader::reads_on_this_thread();
        let built = lensc_build::pipeline::build_and_read_back(
            job,
            &spec,
            &prov,
            lensc_build::output::Destination::Memory,
        )
        .unwrap_or_else(|_| panic!("{} builds", job.name.name));
        let reads = lensc_runtime::reader::reads_on_this_thread() - before;
        assert_eq!(
            reads, 1,
            "{}: its program read {reads} times",
            job.name.name
        );
        // What it read is what the controller's reader finds: nothing.
        let text = built.program.text().expect("text");
        let machine = lensc_lang::lower::read_back::job_machine(job);
        let dialect = &spec.head().dialect;
        assert_eq!(
            lensc_runtime::reader::read(&text, dialect, &machine),
            vec![]
        );
    }
}
