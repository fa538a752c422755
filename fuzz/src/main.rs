//! `cargo run --release -p fuzz -- --seconds N [--seed S] [--build-every K]
//! [--target T]`: fuzzes lensc for N seconds. With the default target
//! (`mixed`, CI's fixed-seed minute) each input is a file from the
//! structure-aware generator (`generate`), a mutation of a real file
//! (`mutate`) or, every K-th, a small whole job (`small_jobs`) that is
//! built and written. Every input runs under the supervisor (`supervise`:
//! panics caught, hangs timed out) through the harness (`harness`: every
//! diagnostic coded and spanned). Failing inputs are saved in
//! fuzz/crashes/; the run ends with throughput and counts, and exits 1 if
//! anything failed. The other targets (`targets`, and `fuzz/campaign.sh`
//! that runs them all for an hour) take one path each: `check` (with size
//! limits drawn per input), `build` (small jobs in a dialect and to a
//! program size drawn per input), `verify` (mutated programs), `import`
//! (mutated prescriptions) and `lsp` (message sequences).

mod end_to_end;
mod generate;
mod harness;
mod measure;
mod mutate;
mod rng;
mod small_jobs;
mod supervise;
mod targets;

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use clap::Parser;

use harness::{Depth, MemFs};
use lensc_build::job::Limits;
use mutate::Corpus;
use rng::Rng;
use supervise::{Outcome, Supervisor};

#[derive(Parser)]
#[command(
    about = "Fuzz lensc: generated and mutated .lens files through check, lowering, build and writing"
)]
struct Cli {
    /// How long to run.
    #[arg(long, default_value_t = 60)]
    seconds: u64,
    /// The run's seed (default: from the clock); printed at the start.
    #[arg(long)]
    seed: Option<u64>,
    /// Every K-th input is a small whole job that is built and written.
    #[arg(long, default_value_t = 50)]
    build_every: u64,
    /// Stop after inputs 0..N of the seed even if time is left (CI runs a
    /// range of a fixed seed that a longer run has shown clean).
    #[arg(long, value_name = "N")]
    inputs: Option<u64>,
    /// Worker threads, each with its own share of the inputs.
    #[arg(long, default_value_t = 1)]
    jobs: u64,
    /// Seconds an input may take before it counts as a hang.
    #[arg(long, default_value_t = 10)]
    timeout: u64,
    /// Run only inputs A..B of the seed (or input A), naming each first:
    /// for an input that aborted the process.
    #[arg(long, value_name = "A[..B]")]
    replay: Option<String>,
    /// Print input I of the seed to stdout and stop.
    #[arg(long, value_name = "I")]
    print: Option<u64>,
    /// What the inputs go through.
    #[arg(long, value_enum, default_value_t = Target::Mixed)]
    target: Target,
    /// The `lensc` binary the `lsp` target starts; with it, one in 50
    /// `.lens` inputs of the other targets also runs through it end to end
    /// (`end_to_end`).
    #[arg(long, value_name = "PATH")]
    lensc: Option<PathBuf>,
}

/// What the inputs go through.
#[derive(Clone, Copy, PartialEq, Eq, Debug, clap::ValueEnum)]
enum Target {
    /// Check, one in eight lowered, one in `--build-every` a small job
    /// built and written (CI's minute).
    Mixed,
    /// Check as `lensc check` does (a clean file's jobs lowered), under
    /// size limits drawn per input; one in 50 also through the binary
    /// with `--lensc`.
    Check,
    /// Small jobs only, built in a dialect and to a program size drawn
    /// per input, and written.
    Build,
    /// `lensc verify` on mutated programs.
    Verify,
    /// `lensc import` on mutated `.zmx` and `.json` prescriptions.
    Import,
    /// `lensc lsp` on random message sequences (`--lensc` names the binary).
    Lsp,
    /// The measurement readers on mutated peer files (X3P mutated inside
    /// its archive too).
    Measure,
}

/// The mutation corpora: `.lens` files, programs and prescriptions.
struct Corpora {
    lens: Corpus,
    programs: Corpus,
    prescriptions: Corpus,
    measurements: Corpus,
}

/// Dialects a build may be asked for (a machine that does not offer one
/// refuses it with a coded error, which is also an input worth making).
const DIALECTS: &[&str] = &[
    "linuxcnc",
    "fanuc_0i_lathe",
    "fanuc_0i_mill",
    "siemens_840d_lathe",
    "siemens_840d_mill",
    "heidenhain_iso",
    "heidenhain_tnc_klartext",
    "ultra_precision_lathe_gcode",
];

/// Makes input `index` of `target` in the run seeded `seed`.
fn input_for(
    target: Target,
    seed: u64,
    index: u64,
    build_every: u64,
    corpora: &Corpora,
) -> (Source, Vec<u8>, Depth) {
    let mut rng = Rng::for_input(seed, index);
    match target {
        Target::Mixed => input(seed, index, build_every, &corpora.lens),
        Target::Check => {
            // Every input as `lensc check` takes it: a clean file's jobs
            // lowered, under size limits drawn per input.
            let (source, bytes, _) = input(seed, index, 0, &corpora.lens);
            let depth = Depth::LowerWithin(Limits {
                max_program_size: rng.log_uniform(1e3, 1e10) as u64,
                max_points: rng.log_uniform(10.0, 1e9) as u64,
            });
            (source, bytes, depth)
        }
        Target::Build => {
            let dialect = rng.chance(0.3).then(|| *rng.pick(DIALECTS));
            let max_program_size = rng.chance(0.15).then(|| rng.log_uniform(1e3, 1e8) as u64);
            (
                Source::SmallJob,
                small_jobs::file(&mut rng).into_bytes(),
                Depth::BuildAs {
                    dialect,
                    max_program_size,
                },
            )
        }
        Target::Verify => (
            Source::Program,
            mutate::mutant(&corpora.programs, &mut rng),
            Depth::Verify(rng.below(64)),
        ),
        Target::Import => {
            let bytes = mutate::mutant(&corpora.prescriptions, &mut rng);
            let json = bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
            (Source::Prescription, bytes, Depth::Import { json })
        }
        Target::Measure => {
            let (name, bytes) = measure::input(&corpora.measurements, &mut rng);
            (
                Source::Measurement,
                bytes,
                Depth::Measure {
                    ext: measure_ext(&name),
                },
            )
        }
        Target::Lsp => (
            Source::Session,
            targets::session(&corpora.lens, &mut rng),
            Depth::Lsp,
        ),
    }
}

/// Where an input came from.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Source {
    Generated,
    Mutated,
    SmallJob,
    Program,
    Prescription,
    Session,
    Measurement,
}

/// The extension a measurement input is read with (the text readers are
/// chosen by it).
fn measure_ext(name: &str) -> &'static str {
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    ["x3p", "sdf", "dat", "asc", "xyz", "csv", "txt", "prf"]
        .into_iter()
        .find(|e| ext.as_deref() == Some(*e))
        .unwrap_or("bin")
}

/// Makes input `index` of the run seeded `seed`.
fn input(seed: u64, index: u64, build_every: u64, corpus: &Corpus) -> (Source, Vec<u8>, Depth) {
    let mut rng = Rng::for_input(seed, index);
    // Drawn, not `index % K`: lanes take every J-th index, and a tier on a
    // fixed stride would fall to one lane.
    if build_every > 0 && rng.below(build_every as usize) == 0 {
        return (
            Source::SmallJob,
            small_jobs::file(&mut rng).into_bytes(),
            Depth::Build,
        );
    }
    // Lowering JIT-compiles every surface: one clean input in eight.
    let depth = if rng.below(8) == 0 {
        Depth::Lower
    } else {
        Depth::Check
    };
    if rng.chance(0.5) {
        (
            Source::Generated,
            generate::file(&mut rng).into_bytes(),
            depth,
        )
    } else {
        (Source::Mutated, mutate::mutant(corpus, &mut rng), depth)
    }
}

/// Seconds between lines of progress, and what they count: inputs run
/// and jobs built, over every lane.
const PROGRESS_EVERY: u64 = 30;
static PROGRESS_INPUTS: AtomicU64 = AtomicU64::new(0);
static PROGRESS_BUILT: AtomicU64 = AtomicU64::new(0);

/// Mixed into the seed for the draw of the inputs that also run end to
/// end (a stream of its own: the inputs stay those of the seed).
const END_TO_END: u64 = 0xE2E0_0E2E;

#[derive(Default)]
struct Counts {
    /// Inputs also run through the `lensc` binary, and those that failed.
    end_to_end: u64,
    end_to_end_failed: u64,
    inputs: HashMap<Source, u64>,
    checked: u64,
    clean: u64,
    lowered: u64,
    build_inputs: u64,
    built: u64,
    written: u64,
    unwritten: u64,
    panics: u64,
    hangs: u64,
    uncoded: u64,
    build_time: Duration,
    /// Builds and their time by strategy (as the job's file names it).
    by_strategy: HashMap<&'static str, (u64, Duration)>,
    slowest_build: Duration,
    slow_builds: u64,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let seed = cli.seed.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(1)
    });
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let corpora = Corpus::load(&root).and_then(|lens| {
        Ok(Corpora {
            lens,
            programs: targets::programs(&root)?,
            prescriptions: targets::prescriptions(&root)?,
            measurements: measure::corpus(&root)?,
        })
    });
    let corpora = match corpora {
        Ok(c) => c,
        Err(e) => {
            eprintln!("fuzz: cannot read the corpus under {}: {e}", root.display());
            return ExitCode::from(2);
        }
    };
    match &cli.lensc {
        Some(p) => {
            let _ = targets::LENSC.set(p.clone());
        }
        None if cli.target == Target::Lsp => {
            eprintln!("fuzz: the lsp target needs --lensc PATH (cargo build --release -p lensc)");
            return ExitCode::from(2);
        }
        None => {}
    }
    if let Some(i) = cli.print {
        let (_, bytes, _) = input_for(cli.target, seed, i, cli.build_every, &corpora);
        let _ = std::io::stdout().write_all(&bytes);
        return ExitCode::SUCCESS;
    }
    let out = match tempfile::tempdir() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("fuzz: cannot make a temporary output directory: {e}");
            return ExitCode::from(2);
        }
    };
    supervise::install_panic_hook();
    let (range, deadline) = match cli.replay.as_deref().map(parse_range) {
        Some(Some(r)) => (r, None),
        Some(None) => {
            eprintln!("fuzz: --replay takes A or A..B");
            return ExitCode::from(2);
        }
        None => (
            0..cli.inputs.unwrap_or(u64::MAX),
            Some(Duration::from_secs(cli.seconds)),
        ),
    };
    let jobs = if cli.replay.is_some() {
        1
    } else {
        cli.jobs.max(1)
    };
    eprintln!(
        "fuzz: target {:?}, seed {seed}, build every {}th input, {} s, {jobs} worker(s)",
        cli.target, cli.build_every, cli.seconds
    );
    let run = Run {
        cli: &cli,
        seed,
        corpora: &corpora,
        fs: std::sync::Arc::new(MemFs::new(&corpora.lens.files)),
        out: out.path(),
        crashes: Path::new(env!("CARGO_MANIFEST_DIR")).join("crashes"),
        seen: Mutex::new(HashMap::new()),
        start: Instant::now(),
        deadline,
    };
    let done = AtomicBool::new(false);
    let totals = std::thread::scope(|scope| {
        // A line of progress now and then: what a run that aborts (an
        // allocation that fails, a stack overflow) had reached, for
        // `fuzz/campaign.sh`, which starts it again with a new seed.
        scope.spawn(|| {
            let every = Duration::from_secs(PROGRESS_EVERY);
            let mut next = every;
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(200));
                if run.start.elapsed() >= next {
                    next += every;
                    let _ = writeln!(
                        std::io::stderr(),
                        "fuzz: progress {:.0} s: {} inputs, {} built",
                        run.start.elapsed().as_secs_f64(),
                        PROGRESS_INPUTS.load(Ordering::Relaxed),
                        PROGRESS_BUILT.load(Ordering::Relaxed)
                    );
                }
            }
        });
        let lanes: Vec<_> = (0..jobs)
            .map(|lane| {
                let run = &run;
                let range = range.clone();
                scope.spawn(move || run.lane(range.skip(lane as usize).step_by(jobs as usize)))
            })
            .collect();
        let mut totals = Counts::default();
        for lane in lanes {
            match lane.join() {
                Ok(c) => totals.add(c),
                Err(_) => totals.panics += 1,
            }
        }
        done.store(true, Ordering::Relaxed);
        totals
    });
    let distinct = run.seen.lock().map(|s| s.len()).unwrap_or(0);
    summary(&totals, run.start.elapsed(), distinct, jobs);
    if totals.panics + totals.hangs + totals.uncoded + totals.end_to_end_failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// What every lane of a run shares.
struct Run<'a> {
    cli: &'a Cli,
    seed: u64,
    corpora: &'a Corpora,
    fs: std::sync::Arc<MemFs>,
    out: &'a Path,
    crashes: PathBuf,
    /// Failure messages seen so far and how often.
    seen: Mutex<HashMap<String, u32>>,
    start: Instant,
    deadline: Option<Duration>,
}

impl Run<'_> {
    /// Runs these inputs (one lane's share) until the deadline.
    fn lane(&self, indices: impl Iterator<Item = u64>) -> Counts {
        let cli = self.cli;
        let mut counts = Counts::default();
        let mut sup = None;
        let mut project = None;
        for index in indices {
            if self.deadline.is_some_and(|d| self.start.elapsed() >= d) {
                break;
            }
            if cli.replay.is_some() {
                eprintln!("fuzz: input {index}");
            }
            // Each lane builds into a directory of its own.
            let sup = sup.get_or_insert_with(|| {
                let dir = self.out.join(format!("lane-{index}"));
                let _ = std::fs::create_dir_all(&dir);
                Supervisor::new(
                    self.seed,
                    std::sync::Arc::clone(&self.fs),
                    dir,
                    Duration::from_secs(cli.timeout),
                )
            });
            let (source, bytes, depth) =
                input_for(cli.target, self.seed, index, cli.build_every, self.corpora);
            *counts.inputs.entry(source).or_default() += 1;
            let began = Instant::now();
            let outcome = sup.run(index, bytes.clone(), depth);
            let took = began.elapsed();
            if matches!(depth, Depth::Build | Depth::BuildAs { .. }) {
                let e = counts.by_strategy.entry(strategy_of(&bytes)).or_default();
                e.0 += 1;
                e.1 += took;
            }
            PROGRESS_INPUTS.fetch_add(1, Ordering::Relaxed);
            if let Outcome::Done(Ok(r)) = &outcome {
                PROGRESS_BUILT.fetch_add(r.built as u64, Ordering::Relaxed);
            }
            if let Some((what, message)) = counts.record(outcome, depth, took, cli.timeout) {
                self.failed(what, &message, index, source, &bytes);
            }
            if let Some(lensc) = &cli.lensc
                && depth.is_lens()
                && Rng::for_input(self.seed ^ END_TO_END, index).below(end_to_end::SHARE) == 0
            {
                let project = project.get_or_insert_with(|| {
                    let dir = self.out.join(format!("project-{index}"));
                    end_to_end::Project::new(lensc, dir, self.fs.files())
                });
                counts.end_to_end += 1;
                if let Err(message) = project.run(&bytes, depth) {
                    counts.end_to_end_failed += 1;
                    self.failed("end-to-end", &message, index, source, &bytes);
                }
            }
        }
        counts
    }

    /// Reports a failure and saves its input (the first three of each
    /// message).
    fn failed(&self, what: &str, message: &str, index: u64, source: Source, bytes: &[u8]) {
        let n = {
            let Ok(mut seen) = self.seen.lock() else {
                return;
            };
            let n = seen.entry(message.to_string()).or_default();
            *n += 1;
            *n
        };
        if n <= 3 {
            let saved = save(
                &self.crashes,
                (what, self.cli.target, source),
                self.seed,
                index,
                bytes,
                message,
            );
            // Not `eprintln!`, which panics if stderr cannot be written.
            let _ = writeln!(
                std::io::stderr(),
                "fuzz: {what} on input {index} ({source:?}): {message}\n      saved as {saved}"
            );
        }
    }
}

impl Counts {
    /// Counts one input's outcome; returns what failed, if anything.
    fn record(
        &mut self,
        outcome: Outcome,
        depth: Depth,
        took: Duration,
        timeout: u64,
    ) -> Option<(&'static str, String)> {
        match outcome {
            Outcome::Done(Ok(r)) => {
                self.checked += 1;
                self.clean += u64::from(r.clean);
                self.lowered += r.lowered as u64;
                self.built += r.built as u64;
                self.written += r.written as u64;
                self.unwritten += r.unwritten as u64;
                if matches!(depth, Depth::Build | Depth::BuildAs { .. }) {
                    self.build_inputs += 1;
                    self.build_time += took;
                    self.slowest_build = self.slowest_build.max(took);
                    self.slow_builds += u64::from(took > Duration::from_secs(1));
                }
                None
            }
            Outcome::Done(Err(fault)) => {
                self.checked += 1;
                self.uncoded += 1;
                Some(("uncoded", fault))
            }
            Outcome::Panicked(m) => {
                self.panics += 1;
                Some(("panic", m))
            }
            Outcome::Hung => {
                self.hangs += 1;
                Some(("hang", format!("no answer in {timeout} s")))
            }
        }
    }

    fn add(&mut self, o: Counts) {
        for (k, v) in o.inputs {
            *self.inputs.entry(k).or_default() += v;
        }
        self.checked += o.checked;
        self.clean += o.clean;
        self.lowered += o.lowered;
        self.build_inputs += o.build_inputs;
        self.built += o.built;
        self.written += o.written;
        self.unwritten += o.unwritten;
        self.panics += o.panics;
        self.end_to_end += o.end_to_end;
        self.end_to_end_failed += o.end_to_end_failed;
        self.hangs += o.hangs;
        self.uncoded += o.uncoded;
        self.build_time += o.build_time;
        for (k, (n, t)) in o.by_strategy {
            let e = self.by_strategy.entry(k).or_default();
            e.0 += n;
            e.1 += t;
        }
        self.slowest_build = self.slowest_build.max(o.slowest_build);
        self.slow_builds += o.slow_builds;
    }
}

/// The strategy a small job's file uses.
fn strategy_of(bytes: &[u8]) -> &'static str {
    let text = String::from_utf8_lossy(bytes);
    [
        "profile_turning",
        "profile_grinding",
        "raster",
        "spiral_turning",
        "fts_spiral",
        "roller_helix",
    ]
    .into_iter()
    .find(|s| text.contains(&format!("= {s} {{")))
    .unwrap_or("other")
}

fn parse_range(s: &str) -> Option<std::ops::Range<u64>> {
    match s.split_once("..") {
        Some((a, b)) => Some(a.parse().ok()?..b.parse().ok()?),
        None => {
            let a: u64 = s.parse().ok()?;
            Some(a..a + 1)
        }
    }
}

/// Saves a failing input (as bytes, named for what it is) and what went
/// wrong beside it, with the command that replays it.
fn save(
    dir: &Path,
    (what, target, source): (&str, Target, Source),
    seed: u64,
    index: u64,
    bytes: &[u8],
    message: &str,
) -> String {
    let ext = match source {
        Source::Program => "ngc",
        Source::Prescription => "zmx",
        Source::Session => "lsp",
        Source::Measurement => "measurement",
        _ => "lens",
    };
    let target_name = format!("{target:?}").to_lowercase();
    let path: PathBuf = dir.join(format!("{what}-{target_name}-{seed}-{index}.{ext}"));
    let note = format!(
        "{what}: {message}\nreplay: cargo run --release -p fuzz -- --target {target_name} --seed {seed} --replay {index}\n"
    );
    let written = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&path, bytes))
        .and_then(|()| std::fs::write(path.with_extension("txt"), note));
    match written {
        Ok(()) => path.display().to_string(),
        Err(e) => format!("(not saved: {e})"),
    }
}

/// The run's figures, on stdout (a full disk or a closed pipe loses them
/// quietly rather than panicking).
fn summary(c: &Counts, elapsed: Duration, distinct: usize, lanes: u64) {
    let secs = elapsed.as_secs_f64().max(1e-9);
    // Lanes run side by side: their build time is shared out among them.
    let check_secs = (elapsed.saturating_sub(c.build_time / lanes as u32))
        .as_secs_f64()
        .max(1e-9);
    let check_only = c.checked.saturating_sub(c.build_inputs);
    let get = |s| c.inputs.get(&s).copied().unwrap_or(0);
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "fuzz: {secs:.1} s, {lanes} lane(s)");
    let _ = writeln!(
        out,
        "  inputs            {} ({} generated, {} mutated, {} small jobs, {} programs, {} prescriptions, {} sessions, {} measurements), {:.0}/s",
        c.inputs.values().sum::<u64>(),
        get(Source::Generated),
        get(Source::Mutated),
        get(Source::SmallJob),
        get(Source::Program),
        get(Source::Prescription),
        get(Source::Session),
        get(Source::Measurement),
        c.checked as f64 / secs
    );
    let _ = writeln!(
        out,
        "  through check     {} ({} clean), {:.0} inputs/s outside builds",
        c.checked,
        c.clean,
        check_only as f64 / check_secs
    );
    let _ = writeln!(out, "  jobs lowered      {}", c.lowered);
    let _ = writeln!(
        out,
        "  through build     {} jobs built and {} written ({} not written: I/O) from {} small-job inputs, {:.2} builds/s over the run, {:.1} builds/s per lane while building, slowest {:.2} s, {} over 1 s",
        c.built,
        c.written,
        c.unwritten,
        c.build_inputs,
        c.built as f64 / secs,
        c.built as f64 * lanes as f64 / c.build_time.as_secs_f64().max(1e-9),
        c.slowest_build.as_secs_f64(),
        c.slow_builds
    );
    let _ = writeln!(
        out,
        "  end to end        {} through the lensc binary, {} failed",
        c.end_to_end, c.end_to_end_failed
    );
    let mut kinds: Vec<_> = c.by_strategy.iter().collect();
    kinds.sort();
    for (kind, (n, t)) in kinds {
        let _ = writeln!(
            out,
            "    {kind:<18} {n} jobs, {:.1} ms each on average",
            t.as_secs_f64() * 1e3 / (*n).max(1) as f64
        );
    }
    let rate = c.checked as f64 / secs;
    let _ = writeln!(
        out,
        "  an hour at this rate: {:.2e} inputs, {:.2e} builds",
        rate * 3600.0,
        c.built as f64 / secs * 3600.0
    );
    let _ = writeln!(
        out,
        "  panics {}, hangs {}, uncoded rejections {} ({} distinct)",
        c.panics, c.hangs, c.uncoded, distinct
    );
}
