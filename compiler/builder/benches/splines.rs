//! Programs written with splines against lines and arcs, in one run
//! (issue #31): seed 000's six scraped microlenses
//! (`examples/lin2022_scraping.lens`) built in `fanuc_0i_mill`, once with
//! lines and arcs (the dialect's default) and once with `interpolation:
//! spline` (G06.2 NURBS), each built as `lensc build` builds it (planned,
//! fitted or optimised, written, read back, simulated, judged). Per job:
//! the program's lines and bytes both ways and their ratios, the planned
//! moves' blocks (what the fit started from, from the spline program's
//! header), and the build's wall time both ways (the fitting's cost; goal:
//! at most 1.3×). Then the same in a copy of the dialect without arcs
//! (splines against straight lines alone). The simulated form of the two
//! programs is compared by `tests/it/splines.rs`.
//!
//! Seed 004's profile (`examples/lei2021_cylinder_array.lens`) is a
//! profile-turning job: lensc fits no turning program yet (E0182), so it is
//! not measured here.
//!
//! Run: cargo bench -p lensc-build --bench splines
//! (`--profile dev` reuses the debug build: the line and byte figures are
//! the same, the times a debug build's.)

use std::path::Path;
use std::time::Instant;

use lensc_build::job::Limits;
use lensc_build::output::Destination;
use lensc_runtime::post::Provenance;

const EXAMPLE: &str = "examples/lin2022_scraping.lens";
const DIALECT: &str = "fanuc_0i_mill";
const DIALECT_LINES: &str = "fanuc_lines";

struct Figures {
    lines: usize,
    bytes: u64,
    seconds: f64,
    header: String,
}

fn build(checked: &lensc_lang::Checked, job: usize, dir: &Path, dialect: &str) -> Figures {
    let job = &checked.checked.jobs[job];
    let t = Instant::now();
    let (spec, _) = lensc_build::pipeline::lower(job, Some(dialect), &Limits::default())
        .unwrap_or_else(|_| panic!("{} lowers", job.name.name));
    let prov = Provenance {
        source: "bench.lens".into(),
        source_hash: 0,
        lensc_version: "bench".into(),
    };
    let built =
        lensc_build::pipeline::build_and_read_back(job, &spec, &prov, Destination::Spool(dir))
            .unwrap_or_else(|_| panic!("{} builds and reads back", job.name.name));
    let seconds = t.elapsed().as_secs_f64();
    let (lines, bytes) = (built.program.lines(), built.program.bytes());
    let path = dir.join(&built.program_name);
    built.program.write_to(&path).expect("program written");
    let text = std::fs::read_to_string(&path).expect("program read");
    std::fs::remove_file(&path).expect("program removed");
    // The interpolation's header line, unfolded.
    let all: Vec<&str> = text.lines().collect();
    let header = all
        .iter()
        .position(|l| l.starts_with("(interpolation"))
        .map(|i| {
            std::iter::once(all[i])
                .chain(
                    all[i + 1..]
                        .iter()
                        .copied()
                        .take_while(|l| l.starts_with("(  ")),
                )
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_default();
    Figures {
        lines,
        bytes,
        seconds,
        header,
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let source = std::fs::read_to_string(root.join(EXAMPLE)).expect("example");
    let fs = lensc_lang::loader::RealFs;
    let plain = lensc_lang::check_text(&fs, "lin2022.lens", source.as_bytes());
    let splined_source = source.replace(
        "strategy: scrape,",
        "strategy: scrape, interpolation: spline,",
    );
    assert_ne!(splined_source, source);
    let splined = lensc_lang::check_text(&fs, "lin2022.lens", splined_source.as_bytes());
    // The same in a copy of the dialect without arcs: splines against
    // straight lines alone.
    let no_arcs = |s: &str| {
        format!(
            "dialect fanuc_lines = fanuc_0i_mill {{ arc_planes: [] }}\nmachine mill = generic_3axis_mill {{ dialect: fanuc_lines }}\n{}",
            s.replace("machine: generic_3axis_mill", "machine: mill")
        )
    };
    let plain_lines = lensc_lang::check_text(&fs, "lin2022.lens", no_arcs(&source).as_bytes());
    let splined_lines =
        lensc_lang::check_text(&fs, "lin2022.lens", no_arcs(&splined_source).as_bytes());
    assert!(
        [&plain, &splined, &plain_lines, &splined_lines]
            .iter()
            .all(|c| !c.has_errors()),
        "the example checks"
    );
    let dir = tempfile::tempdir_in(root.join("target")).expect("temporary directory");
    for (label, dialect, plain, splined) in [
        ("lines and arcs", DIALECT, &plain, &splined),
        (
            "lines only (no arcs)",
            DIALECT_LINES,
            &plain_lines,
            &splined_lines,
        ),
    ] {
        println!("{DIALECT}, {label}:");
        println!(
            "{:<24} {:>9} {:>9} {:>6} {:>10} {:>10} {:>6} {:>8} {:>6}",
            "job", "lines", "spline", "ratio", "bytes", "spline", "ratio", "build s", "ratio"
        );
        let (mut total_lines, mut total_bytes) = ((0, 0), (0, 0));
        for i in 0..plain.checked.jobs.len() {
            let name = &plain.checked.jobs[i].name.name;
            let a = build(plain, i, dir.path(), dialect);
            let s = build(splined, i, dir.path(), dialect);
            total_lines = (total_lines.0 + a.lines, total_lines.1 + s.lines);
            total_bytes = (total_bytes.0 + a.bytes, total_bytes.1 + s.bytes);
            println!(
                "{:<24} {:>9} {:>9} {:>6.2} {:>10} {:>10} {:>6.2} {:>8.2} {:>6.2}",
                name,
                a.lines,
                s.lines,
                a.lines as f64 / s.lines as f64,
                a.bytes,
                s.bytes,
                a.bytes as f64 / s.bytes as f64,
                a.seconds,
                s.seconds / a.seconds,
            );
            println!("    {}", s.header);
        }
        println!(
            "all six: lines {} / {} = {:.2}x, bytes {} / {} = {:.2}x ({label} / splines)",
            total_lines.0,
            total_lines.1,
            total_lines.0 as f64 / total_lines.1 as f64,
            total_bytes.0,
            total_bytes.1,
            total_bytes.0 as f64 / total_bytes.1 as f64
        );
    }
}
