//! Programs written with splines against lines and arcs, in one run
//! (issue #31), each build as `lensc build` builds it (planned, fitted or
//! optimised, written, read back, simulated, judged), the faster of
//! `LENSC_BENCH_RUNS` runs (default 3) each way:
//!
//! - seed 000's six scraped microlenses (`examples/lin2022_scraping.lens`)
//!   in `fanuc_0i_mill`, with lines and arcs (the dialect's default) and
//!   with `interpolation: spline` (G06.2 NURBS); then the same in a copy
//!   of the dialect without arcs (splines against straight lines alone);
//! - seed 004's profile (`examples/lei2021_cylinder_array.lens`) in
//!   `siemens_840d_lathe` (the ultra-precision lathe's dialect with a
//!   spline, BSPLINE), both ways;
//! - seed 002's rollers and seed 003's array asked for splines in every
//!   dialect their machines offer: what lensc answers (E0182: the servo's
//!   programs are positions at its sample rate, and no dialect of these
//!   machines has a spline lensc writes).
//!
//! Per job: the program's lines and bytes both ways and their ratios, the
//! planned moves' blocks (from the spline program's header), and the
//! build's time both ways, by the wall clock and in processor time (the
//! fitting's cost; goal: at most 1.3×; on a busy shared machine the
//! processor time is the steadier). The
//! simulated form of the two programs is compared by `tests/it/splines.rs`
//! (and `lensc build` prints it; the README's figures).
//!
//! Run: cargo bench -p lensc-build --bench splines
//! (`--profile dev` reuses the debug build: the line, byte and form
//! figures are the same, the times a debug build's.)

use std::path::Path;
use std::time::Instant;

use lensc_build::job::Limits;
use lensc_build::output::Destination;
use lensc_runtime::post::Provenance;

struct Figures {
    lines: usize,
    bytes: u64,
    seconds: f64,
    /// Processor time (all the process's threads: the read-back's too),
    /// which a busy shared machine disturbs less than the wall clock.
    cpu: f64,
    header: String,
}

/// The process's processor time so far (s), user and system.
#[cfg(unix)]
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes only into the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

#[cfg(not(unix))]
fn cpu_seconds() -> f64 {
    f64::NAN
}

fn runs() -> usize {
    std::env::var("LENSC_BENCH_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3)
        .max(1)
}

/// Builds job `job` of `checked` in `dialect` `runs()` times; the
/// fastest run's time.
fn build(checked: &lensc_lang::Checked, job: usize, dir: &Path, dialect: &str) -> Figures {
    let job = &checked.checked.jobs[job];
    let prov = Provenance {
        source: "bench.lens".into(),
        source_hash: 0,
        lensc_version: "bench".into(),
    };
    let mut seconds = f64::INFINITY;
    let mut cpu = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs() {
        let t = Instant::now();
        let c = cpu_seconds();
        let (spec, _) = lensc_build::pipeline::lower(job, Some(dialect), &Limits::default())
            .unwrap_or_else(|e| panic!("{} lowers: {e:?}", job.name.name));
        let built =
            lensc_build::pipeline::build_and_read_back(job, &spec, &prov, Destination::Spool(dir))
                .unwrap_or_else(|_| panic!("{} builds and reads back", job.name.name));
        seconds = seconds.min(t.elapsed().as_secs_f64());
        cpu = cpu.min(cpu_seconds() - c);
        last = Some(built);
    }
    let built = last.expect("one run");
    let (lines, bytes) = (built.program.lines(), built.program.bytes());
    let text = built.program.text().expect("program text");
    // The interpolation's header line, unfolded (Fanuc's `(…)` continues
    // a line with `(  `, Siemens' `;` with `;   `).
    let all: Vec<&str> = text.lines().collect();
    let strip = |l: &str| {
        l.trim_start_matches(['(', ';'])
            .trim_end_matches(')')
            .trim()
            .to_string()
    };
    let header = all
        .iter()
        .position(|l| strip(l).starts_with("interpolation"))
        .map(|i| {
            std::iter::once(strip(all[i]))
                .chain(
                    all[i + 1..]
                        .iter()
                        .take_while(|l| l.starts_with("(  ") || l.starts_with(";   "))
                        .map(|l| strip(l)),
                )
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_default();
    Figures {
        lines,
        bytes,
        seconds,
        cpu,
        header,
    }
}

/// `source` with `interpolation: spline` in every job (one line each).
fn splined(source: &str) -> String {
    source
        .lines()
        .map(
            |l| match l.strip_prefix("job ").and_then(|r| r.split_once(" { ")) {
                Some((name, rest)) => format!("job {name} {{ interpolation: spline, {rest}\n"),
                None => format!("{l}\n"),
            },
        )
        .collect()
}

fn check(fs: &lensc_lang::loader::RealFs, source: &str) -> lensc_lang::Checked {
    let c = lensc_lang::check_text(fs, "bench.lens", source.as_bytes());
    assert!(!c.has_errors(), "the example checks");
    c
}

/// Both ways, job by job; returns the build times summed (lines, spline),
/// wall clock and processor.
fn compare(
    title: &str,
    plain: &lensc_lang::Checked,
    splined: &lensc_lang::Checked,
    dialect: &str,
    dir: &Path,
) -> ((f64, f64), (f64, f64)) {
    println!("{title}:");
    println!(
        "{:<24} {:>8} {:>8} {:>6} {:>9} {:>9} {:>6} {:>7} {:>7} {:>6} {:>7} {:>7} {:>6}",
        "job",
        "lines",
        "spline",
        "ratio",
        "bytes",
        "spline",
        "ratio",
        "build s",
        "spline",
        "ratio",
        "cpu s",
        "spline",
        "ratio"
    );
    let (mut lines, mut bytes, mut time, mut cpu) = ((0, 0), (0, 0), (0.0, 0.0), (0.0, 0.0));
    for i in 0..plain.checked.jobs.len() {
        let name = &plain.checked.jobs[i].name.name;
        let a = build(plain, i, dir, dialect);
        let s = build(splined, i, dir, dialect);
        lines = (lines.0 + a.lines, lines.1 + s.lines);
        bytes = (bytes.0 + a.bytes, bytes.1 + s.bytes);
        time = (time.0 + a.seconds, time.1 + s.seconds);
        cpu = (cpu.0 + a.cpu, cpu.1 + s.cpu);
        println!(
            "{:<24} {:>8} {:>8} {:>6.2} {:>9} {:>9} {:>6.2} {:>7.2} {:>7.2} {:>6.2} {:>7.2} {:>7.2} {:>6.2}",
            name,
            a.lines,
            s.lines,
            a.lines as f64 / s.lines as f64,
            a.bytes,
            s.bytes,
            a.bytes as f64 / s.bytes as f64,
            a.seconds,
            s.seconds,
            s.seconds / a.seconds,
            a.cpu,
            s.cpu,
            s.cpu / a.cpu,
        );
        println!("    {}", s.header);
    }
    println!(
        "all: lines {} / {} = {:.2}x, bytes {} / {} = {:.2}x; build {:.2} s / {:.2} s = {:.2}x with splines, processor {:.2} s / {:.2} s = {:.2}x (goal <= 1.3x)",
        lines.0,
        lines.1,
        lines.0 as f64 / lines.1 as f64,
        bytes.0,
        bytes.1,
        bytes.0 as f64 / bytes.1 as f64,
        time.1,
        time.0,
        time.1 / time.0,
        cpu.1,
        cpu.0,
        cpu.1 / cpu.0
    );
    (time, cpu)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let read = |p: &str| std::fs::read_to_string(root.join(p)).expect("example");
    let fs = lensc_lang::loader::RealFs;
    let dir = tempfile::tempdir_in(root.join("target")).expect("temporary directory");
    println!("best of {} runs each way", runs());

    // Seed 000: the raster.
    let source = read("examples/lin2022_scraping.lens");
    let no_arcs = |s: &str| {
        format!(
            "dialect fanuc_lines = fanuc_0i_mill {{ arc_planes: [] }}\nmachine mill = generic_3axis_mill {{ dialect: fanuc_lines }}\n{}",
            s.replace("machine: generic_3axis_mill", "machine: mill")
        )
    };
    let (mut total, mut total_cpu) = ((0.0, 0.0), (0.0, 0.0));
    for (title, dialect, text) in [
        (
            "seed 000, fanuc_0i_mill, lines and arcs against NURBS",
            "fanuc_0i_mill",
            source.clone(),
        ),
        (
            "seed 000, fanuc_0i_mill without arcs, lines against NURBS",
            "fanuc_lines",
            no_arcs(&source),
        ),
    ] {
        let (t, c) = compare(
            title,
            &check(&fs, &text),
            &check(&fs, &splined(&text)),
            dialect,
            dir.path(),
        );
        total = (total.0 + t.0, total.1 + t.1);
        total_cpu = (total_cpu.0 + c.0, total_cpu.1 + c.1);
    }

    // Seed 004: the profile.
    let source = read("examples/lei2021_cylinder_array.lens");
    let (t, c) = compare(
        "seed 004, siemens_840d_lathe, lines and arcs against BSPLINE",
        &check(&fs, &source),
        &check(&fs, &splined(&source)),
        "siemens_840d_lathe",
        dir.path(),
    );
    total = (total.0 + t.0, total.1 + t.1);
    total_cpu = (total_cpu.0 + c.0, total_cpu.1 + c.1);
    println!(
        "seeds 000 and 004: build {:.2} s with splines / {:.2} s without = {:.2}x, processor {:.2} s / {:.2} s = {:.2}x (goal <= 1.3x)",
        total.1,
        total.0,
        total.1 / total.0,
        total_cpu.1,
        total_cpu.0,
        total_cpu.1 / total_cpu.0
    );

    // Seeds 002 and 003: the servo's programs.
    for example in [
        "examples/liu_roller_pattern.lens",
        "examples/liu_roller_microlens.lens",
        "examples/hashimoto2025_lens_array.lens",
    ] {
        let c = check(&fs, &splined(&read(example)));
        for job in &c.checked.jobs {
            for dialect in lensc_lang::lower::offered_dialects(job) {
                let answer = match lensc_build::pipeline::lower(
                    job,
                    Some(dialect.as_str()),
                    &Limits::default(),
                ) {
                    Ok(_) => "lowers with splines".to_string(),
                    Err(ds) => ds
                        .iter()
                        .map(|d| format!("{}: {}", d.code, d.message))
                        .collect::<Vec<_>>()
                        .join("; "),
                };
                println!("{example} {} in {dialect}: {answer}", job.name.name);
            }
        }
    }
}
