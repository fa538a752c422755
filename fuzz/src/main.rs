//! `cargo run --release -p fuzz -- --seconds N [--seed S] [--build-every K]
//! [--target T] [--jobs J]`: fuzzes lensc for N seconds. With the default
//! target (`mixed`, CI's fixed-seed minute) each input is a file from the
//! structure-aware generator (`generate`), a mutation of a real file
//! (`mutate`) or, every K-th, a small whole job (`small_jobs`) that is
//! built and written. Every input runs under the supervisor (`supervise`:
//! panics caught, hangs timed out) through the harness (`harness`: every
//! diagnostic coded and spanned). Each of the J lanes is a child process
//! (`lanes`: this binary again with `--worker`), so an abort (a failed
//! allocation, a stack overflow) loses one input, which is saved and
//! reported, not the run. Failing inputs are saved in fuzz/crashes/; the
//! run ends with throughput, where the time went by phase, counts and a
//! projection of the campaign's goals, and exits 1 if anything failed.
//! The other targets (`targets`, and `fuzz/campaign.sh` that runs them
//! all) take one path each: `check` (with size limits drawn per input),
//! `build` (small jobs in a dialect and to a program size drawn per
//! input), `verify` (mutated programs), `import` (mutated prescriptions),
//! `lsp` (message sequences) and `measure` (the measurement readers).

mod end_to_end;
mod generate;
mod harness;
mod lanes;
mod measure;
mod mutate;
mod record;
mod rng;
mod small_jobs;
mod supervise;
mod targets;

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::Parser;

use harness::{Depth, MemFs, PHASES, Phases};
use lensc_build::job::Limits;
use mutate::Corpus;
use record::{Kind, Record, STRATEGIES, Source};
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
    /// Stop once N jobs have been built (the campaign's build goal).
    #[arg(long, value_name = "N")]
    until_built: Option<u64>,
    /// Lanes: worker processes, each with its own share of the inputs.
    #[arg(long, default_value_t = 1)]
    jobs: u64,
    /// Seconds an input may take before it counts as a hang.
    #[arg(long, default_value_t = 10)]
    timeout: u64,
    /// Run only inputs A..B of the seed (or input A), naming each first,
    /// in this process: for an input that aborted a worker.
    #[arg(long, value_name = "A[..B]")]
    replay: Option<String>,
    /// Print input I of the seed to stdout and stop.
    #[arg(long, value_name = "I")]
    print: Option<u64>,
    /// What the inputs go through.
    #[arg(long, value_enum, default_value_t = Target::Mixed)]
    target: Target,
    /// The `lensc` binary the `lsp` target starts; with it, one in
    /// `--end-to-end-every` `.lens` inputs of the other targets also runs
    /// through it end to end (`end_to_end`).
    #[arg(long, value_name = "PATH")]
    lensc: Option<PathBuf>,
    /// With `--lensc`, one `.lens` input in N also runs through the binary
    /// (a process started each time: the campaign's check target, at
    /// thousands of inputs a second, runs one in 1,000).
    #[arg(long, value_name = "N", default_value_t = end_to_end::SHARE)]
    end_to_end_every: u64,
    /// Cores the summary's projection of the campaign assumes (default:
    /// the lanes).
    #[arg(long, value_name = "N")]
    cores: Option<u64>,
    /// (Internal) run as lane L's worker process: inputs from
    /// `--worker-from` in steps of `--jobs`, a record line for each on
    /// stdout.
    #[arg(long, hide = true, value_name = "L")]
    worker: Option<u64>,
    #[arg(long, hide = true, value_name = "I")]
    worker_from: Option<u64>,
    #[arg(long, hide = true, value_name = "DIR")]
    worker_dir: Option<PathBuf>,
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

impl Target {
    fn name(self) -> String {
        format!("{self:?}").to_lowercase()
    }
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

/// The campaign's goals (issue #33, item 7).
const GOAL_CHECKS: f64 = 10e6;
const GOAL_BUILDS: f64 = 100e3;

/// The largest program (bytes) a build input may write: 10 MB builds in
/// about 2 s on a quiet core, well inside the hang limit; the size
/// estimate refuses a larger one before planning (E0161).
const BUILD_PROGRAM_CEILING: u64 = 10_000_000;

/// Seconds between lines of progress.
const PROGRESS_EVERY: u64 = 30;

/// Mixed into the seed for the draw of the inputs that also run end to
/// end (a stream of its own: the inputs stay those of the seed).
const END_TO_END: u64 = 0xE2E0_0E2E;

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
            return ExitCode::from(lanes::EXIT_SETUP as u8);
        }
    };
    match &cli.lensc {
        Some(p) => {
            let _ = targets::LENSC.set(p.clone());
        }
        None if cli.target == Target::Lsp => {
            eprintln!("fuzz: the lsp target needs --lensc PATH (cargo build --release -p lensc)");
            return ExitCode::from(lanes::EXIT_SETUP as u8);
        }
        None => {}
    }
    if let Some(i) = cli.print {
        let (_, bytes, _) = input_for(cli.target, seed, i, cli.build_every, &corpora);
        let _ = std::io::stdout().write_all(&bytes);
        return ExitCode::SUCCESS;
    }
    let jobs = cli.jobs.max(1);
    let end = cli.inputs.unwrap_or(u64::MAX);
    let deadline = Instant::now() + Duration::from_secs(cli.seconds);
    let crashes = Path::new(env!("CARGO_MANIFEST_DIR")).join("crashes");
    if let Some(lane) = cli.worker {
        supervise::install_panic_hook();
        let Some(dir) = cli.worker_dir.clone() else {
            eprintln!("fuzz: a worker needs --worker-dir");
            return ExitCode::from(lanes::EXIT_SETUP as u8);
        };
        let from = cli.worker_from.unwrap_or(lane);
        let worker = Worker::new(&cli, seed, &corpora, dir);
        let out = std::io::stdout();
        let mut hung = false;
        worker.lane((from..end).step_by(jobs as usize), deadline, |r| {
            hung = r.kind == Kind::Hung;
            let mut out = out.lock();
            // A parent that is gone: nothing left to report to.
            writeln!(out, "{}", r.line())
                .and_then(|()| out.flush())
                .is_ok()
                && !hung
        });
        let _ = std::fs::remove_dir_all(&worker.out);
        return if hung {
            // Its stuck thread still runs: a fresh worker takes over.
            ExitCode::from(lanes::EXIT_AFTER_HANG as u8)
        } else {
            ExitCode::SUCCESS
        };
    }
    // Builds write and sync their files: in memory where the machine has
    // a tmpfs (the same writes, without a disk's sync in each build's
    // time: a third of a build input's wall time on /tmp here).
    let shm = Path::new("/dev/shm");
    let scratch = if shm.is_dir() {
        tempfile::Builder::new()
            .prefix("lensc-fuzz-")
            .tempdir_in(shm)
            .or_else(|_| tempfile::tempdir())
    } else {
        tempfile::tempdir()
    };
    let scratch = match scratch {
        Ok(d) => d,
        Err(e) => {
            eprintln!("fuzz: cannot make a temporary output directory: {e}");
            return ExitCode::from(lanes::EXIT_SETUP as u8);
        }
    };
    let mut tally = Tally {
        counts: Counts::default(),
        seen: HashMap::new(),
        crashes,
        seed,
        target: cli.target,
        build_every: cli.build_every,
        corpora: &corpora,
    };
    let start = Instant::now();
    let cpu_at_start = cpu_seconds();
    let lanes_run;
    if let Some(range) = cli.replay.as_deref() {
        let Some(range) = parse_range(range) else {
            eprintln!("fuzz: --replay takes A or A..B");
            return ExitCode::from(lanes::EXIT_SETUP as u8);
        };
        lanes_run = 1;
        eprintln!(
            "fuzz: target {:?}, seed {seed}, replaying {range:?}",
            cli.target
        );
        supervise::install_panic_hook();
        let worker = Worker::new(&cli, seed, &corpora, scratch.path().join("replay"));
        worker.lane(
            range,
            Instant::now() + Duration::from_secs(365 * 86_400),
            |r| {
                tally.take(r);
                true
            },
        );
    } else {
        lanes_run = jobs;
        eprintln!(
            "fuzz: target {:?}, seed {seed}, build every {}th input, {} s, {jobs} lane(s) in worker processes",
            cli.target, cli.build_every, cli.seconds
        );
        let plan = lanes::Plan {
            command: worker_command(&cli, seed),
            lanes: jobs,
            end,
            deadline,
            silence: Duration::from_secs(2 * cli.timeout + 60),
            scratch: scratch.path().to_path_buf(),
        };
        let mut next = Duration::from_secs(PROGRESS_EVERY);
        // The tally is shared by the three callbacks, one at a time.
        let tally = std::cell::RefCell::new(&mut tally);
        let restarts = lanes::run(
            &plan,
            |r| tally.borrow_mut().take(&r),
            |lost| tally.borrow_mut().lost(lost),
            || {
                let t = tally.borrow();
                if start.elapsed() >= next {
                    next += Duration::from_secs(PROGRESS_EVERY);
                    // A line the campaign reads if this process dies.
                    let _ = writeln!(
                        std::io::stderr(),
                        "fuzz: progress {:.0} s: {} inputs, {} built",
                        start.elapsed().as_secs_f64(),
                        t.counts.inputs.values().sum::<u64>() + t.counts.lost,
                        t.counts.built
                    );
                }
                cli.until_built.is_some_and(|n| t.counts.built >= n)
            },
        );
        tally.borrow_mut().counts.restarts = restarts;
    }
    let distinct = tally.seen.len();
    let c = &tally.counts;
    summary(
        c,
        start.elapsed(),
        cpu_seconds().map(|now| now - cpu_at_start.unwrap_or(0.0)),
        distinct,
        lanes_run,
        cli.cores.unwrap_or(lanes_run),
        cli.target,
    );
    if c.panics + c.hangs + c.uncoded + c.aborts + c.end_to_end_failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// This binary with the run's flags, as a worker is started (the lane's
/// own flags and its time left are added by `lanes`).
fn worker_command(cli: &Cli, seed: u64) -> Vec<String> {
    let exe = std::env::current_exe()
        .map(|p| p.display().to_string())
        .unwrap_or_else(|_| "fuzz".into());
    let mut c = vec![
        exe,
        "--target".into(),
        cli.target.name(),
        "--seed".into(),
        seed.to_string(),
        "--build-every".into(),
        cli.build_every.to_string(),
        "--jobs".into(),
        cli.jobs.max(1).to_string(),
        "--timeout".into(),
        cli.timeout.to_string(),
    ];
    if let Some(n) = cli.inputs {
        c.extend(["--inputs".into(), n.to_string()]);
    }
    if let Some(p) = &cli.lensc {
        c.extend(["--lensc".into(), p.display().to_string()]);
    }
    c.extend([
        "--end-to-end-every".into(),
        cli.end_to_end_every.to_string(),
    ]);
    c
}

/// What a lane runs its inputs with.
struct Worker<'a> {
    cli: &'a Cli,
    seed: u64,
    corpora: &'a Corpora,
    fs: std::sync::Arc<MemFs>,
    /// The lane's own directory (builds, the end-to-end project).
    out: PathBuf,
}

impl<'a> Worker<'a> {
    fn new(cli: &'a Cli, seed: u64, corpora: &'a Corpora, out: PathBuf) -> Worker<'a> {
        let _ = std::fs::create_dir_all(&out);
        Worker {
            cli,
            seed,
            corpora,
            fs: std::sync::Arc::new(MemFs::new(&corpora.lens.files)),
            out,
        }
    }

    /// Runs these inputs until the deadline, handing each one's record to
    /// `report`, which says whether to go on.
    fn lane(
        &self,
        indices: impl Iterator<Item = u64>,
        deadline: Instant,
        mut report: impl FnMut(&Record) -> bool,
    ) {
        let cli = self.cli;
        let build_dir = self.out.join("build");
        let _ = std::fs::create_dir_all(&build_dir);
        let mut sup = Supervisor::new(
            self.seed,
            std::sync::Arc::clone(&self.fs),
            build_dir,
            Duration::from_secs(cli.timeout),
        );
        let mut project = None;
        for index in indices {
            if Instant::now() >= deadline {
                break;
            }
            if cli.replay.is_some() {
                eprintln!("fuzz: input {index}");
            }
            let made = Instant::now();
            let (source, bytes, depth) =
                input_for(cli.target, self.seed, index, cli.build_every, self.corpora);
            let building = matches!(depth, Depth::Build | Depth::BuildAs { .. });
            let strategy = if building {
                strategy_of(&bytes)
            } else {
                "other"
            };
            let mut r = Record::new(index, source, building, strategy);
            r.made = made.elapsed();
            let began = Instant::now();
            let outcome = sup.run(index, bytes.clone(), depth);
            r.took = began.elapsed();
            match outcome {
                Outcome::Done(Ok(reached)) => r.reached(&reached),
                Outcome::Done(Err(fault)) => {
                    r.kind = Kind::Uncoded;
                    r.failures.push(("uncoded".into(), fault));
                }
                Outcome::Panicked(m) => {
                    r.kind = Kind::Panicked;
                    r.failures.push(("panic".into(), m));
                }
                Outcome::Hung => {
                    r.kind = Kind::Hung;
                    let m = format!("no answer in {} s", cli.timeout);
                    r.failures.push(("hang".into(), m));
                }
            }
            if let Some(lensc) = &cli.lensc
                && r.kind != Kind::Hung
                && depth.is_lens()
                && Rng::for_input(self.seed ^ END_TO_END, index)
                    .below(cli.end_to_end_every.max(1) as usize)
                    == 0
            {
                let project = project.get_or_insert_with(|| {
                    end_to_end::Project::new(lensc, self.out.join("project"), self.fs.files())
                });
                let ran = project.run(&bytes, depth);
                r.end_to_end = Some(ran.is_ok());
                if let Err(message) = ran {
                    r.failures.push(("end-to-end".into(), message));
                }
            }
            if !report(&r) {
                break;
            }
        }
    }
}

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
            let job = small_jobs::job(&mut rng);
            // Mostly a dialect the machine offers (its own, or another it
            // lists); now and then any dialect, which a machine that does
            // not offer it refuses with a coded error.
            let dialect = if rng.chance(0.35) {
                Some(*rng.pick(job.dialects))
            } else {
                rng.chance(0.04).then(|| *rng.pick(DIALECTS))
            };
            // A drawn size limit now and then; otherwise the fuzzer's own
            // ceiling, so that a number made extreme (a 1 nm pitch) meets
            // the size estimate's refusal rather than the hang limit: a
            // 110 MB program legitimately takes 23 s to build.
            let max_program_size = Some(if rng.chance(0.15) {
                rng.log_uniform(1e3, BUILD_PROGRAM_CEILING as f64) as u64
            } else {
                BUILD_PROGRAM_CEILING
            });
            (
                Source::SmallJob,
                job.text.into_bytes(),
                Depth::BuildAs {
                    dialect,
                    max_program_size,
                    accept_warn: rng.chance(0.15),
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

/// The parent's figures and the failures it has saved.
struct Tally<'a> {
    counts: Counts,
    /// Failure messages seen so far and how often.
    seen: HashMap<String, u32>,
    crashes: PathBuf,
    seed: u64,
    target: Target,
    build_every: u64,
    corpora: &'a Corpora,
}

impl Tally<'_> {
    /// Counts one input's record and saves what failed in it.
    fn take(&mut self, r: &Record) {
        self.counts.take(r);
        for (what, message) in &r.failures {
            self.failed(what, message, r.index);
        }
    }

    /// Counts and saves an input lost with its worker.
    fn lost(&mut self, lost: lanes::Lost) {
        self.counts.lost += 1;
        match lost.what {
            "hang" => self.counts.hangs += 1,
            _ => self.counts.aborts += 1,
        }
        let message = format!("lane {}: {}", lost.lane, lost.message);
        self.failed(lost.what, &message, lost.index);
    }

    /// Reports a failure and saves its input, made again from the seed
    /// (the first three of each message).
    fn failed(&mut self, what: &str, message: &str, index: u64) {
        let n = self.seen.entry(message.to_string()).or_default();
        *n += 1;
        if *n > 3 {
            return;
        }
        let (source, bytes, _) = input_for(
            self.target,
            self.seed,
            index,
            self.build_every,
            self.corpora,
        );
        let saved = save(
            &self.crashes,
            (what, self.target, source),
            self.seed,
            index,
            &bytes,
            message,
        );
        // Not `eprintln!`, which panics if stderr cannot be written.
        let _ = writeln!(
            std::io::stderr(),
            "fuzz: {what} on input {index} ({source:?}): {message}\n      saved as {saved}"
        );
    }
}

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
    /// Inputs whose worker died on them, and workers started again.
    aborts: u64,
    /// Inputs lost with their worker (aborts, and hangs it went silent on).
    lost: u64,
    restarts: u64,
    /// Time in the workers: making inputs, running them (builds apart).
    made: Duration,
    check_time: Duration,
    build_time: Duration,
    /// Time by phase (`harness::PHASES`), over every input.
    phases: Phases,
    /// Builds and their time by strategy (as the job's file names it).
    by_strategy: HashMap<&'static str, (u64, Duration)>,
    slowest_build: Duration,
    slow_builds: u64,
    slowest_check: Duration,
}

impl Counts {
    /// Counts one input's record.
    fn take(&mut self, r: &Record) {
        *self.inputs.entry(r.source).or_default() += 1;
        self.made += r.made;
        for (sum, t) in self.phases.iter_mut().zip(r.times) {
            *sum += t;
        }
        if r.build {
            let e = self.by_strategy.entry(r.strategy).or_default();
            e.0 += 1;
            e.1 += r.took;
        }
        if let Some(passed) = r.end_to_end {
            self.end_to_end += 1;
            self.end_to_end_failed += u64::from(!passed);
        }
        match r.kind {
            Kind::Done | Kind::Uncoded => {
                self.checked += 1;
                self.uncoded += u64::from(r.kind == Kind::Uncoded);
                self.clean += u64::from(r.clean);
                self.lowered += r.lowered;
                self.built += r.built;
                self.written += r.written;
                self.unwritten += r.unwritten;
                if r.build {
                    self.build_inputs += 1;
                    self.build_time += r.took;
                    self.slowest_build = self.slowest_build.max(r.took);
                    self.slow_builds += u64::from(r.took > Duration::from_secs(1));
                } else {
                    self.check_time += r.took;
                    self.slowest_check = self.slowest_check.max(r.took);
                }
            }
            Kind::Panicked => self.panics += 1,
            Kind::Hung => self.hangs += 1,
        }
    }
}

/// The strategy a small job's file uses.
fn strategy_of(bytes: &[u8]) -> &'static str {
    let text = String::from_utf8_lossy(bytes);
    STRATEGIES
        .into_iter()
        .find(|s| text.contains(&format!("= {s} {{")))
        .unwrap_or("other")
}

/// CPU seconds (user and system) of this process and of the children it
/// has waited for (the workers, and the `lensc` runs they waited for),
/// from `/proc/self/stat` (in its clock ticks, 100 a second on Linux):
/// what the summary's projection on quiet cores is made from, since the
/// wall time of a lane on a loaded machine is mostly waiting for a core.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name (which may hold spaces), from
    // the state (field 3): utime, stime, cutime, cstime are fields 14-17.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks: Option<Vec<f64>> = (11..15)
        .map(|i| fields.get(i)?.parse::<f64>().ok())
        .collect();
    Some(ticks?.iter().sum::<f64>() / 100.0)
}

/// Hours, or minutes under an hour, for a person.
fn span(seconds: f64) -> String {
    if !seconds.is_finite() {
        "never at this rate".into()
    } else if seconds >= 3600.0 {
        format!("{:.1} h", seconds / 3600.0)
    } else {
        format!("{:.0} min", (seconds / 60.0).ceil())
    }
}

/// The run's figures, on stdout (a full disk or a closed pipe loses them
/// quietly rather than panicking).
fn summary(
    c: &Counts,
    elapsed: Duration,
    cpu: Option<f64>,
    distinct: usize,
    lanes: u64,
    cores: u64,
    target: Target,
) {
    let secs = elapsed.as_secs_f64().max(1e-9);
    let check_only = c.checked.saturating_sub(c.build_inputs);
    let get = |s| c.inputs.get(&s).copied().unwrap_or(0);
    let total: u64 = c.inputs.values().sum();
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "fuzz: {secs:.1} s, {lanes} lane(s)");
    let _ = writeln!(
        out,
        "  inputs            {total} ({} generated, {} mutated, {} small jobs, {} programs, {} prescriptions, {} sessions, {} measurements), {:.0}/s",
        get(Source::Generated),
        get(Source::Mutated),
        get(Source::SmallJob),
        get(Source::Program),
        get(Source::Prescription),
        get(Source::Session),
        get(Source::Measurement),
        c.checked as f64 / secs
    );
    // Per lane: each lane's time in inputs that are not builds.
    let per_check_ms = c.check_time.as_secs_f64() * 1e3 / check_only.max(1) as f64;
    let _ = writeln!(
        out,
        "  through check     {} ({} clean), {:.0} inputs/s over the run, {per_check_ms:.2} ms each in a lane (outside builds), slowest {:.2} s",
        c.checked,
        c.clean,
        c.checked as f64 / secs,
        c.slowest_check.as_secs_f64()
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
        c.built as f64 / c.build_time.as_secs_f64().max(1e-9),
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
    // Where a lane's time went: making inputs, each phase, the rest
    // (the supervisor, the readers of other targets, the end-to-end runs).
    let lane_secs = secs * lanes as f64;
    let mut phases = vec![("make input", c.made)];
    phases.extend(PHASES.iter().copied().zip(c.phases));
    let accounted: f64 = phases.iter().map(|(_, t)| t.as_secs_f64()).sum();
    let mut line = String::from("  time by phase    ");
    for (name, t) in &phases {
        if !t.is_zero() {
            line.push_str(&format!(
                " {name} {:.3} ms/input ({:.0}%),",
                t.as_secs_f64() * 1e3 / total.max(1) as f64,
                100.0 * t.as_secs_f64() / lane_secs
            ));
        }
    }
    line.push_str(&format!(
        " other {:.0}% of the lanes' time",
        100.0 * (lane_secs - accounted).max(0.0) / lane_secs
    ));
    let _ = writeln!(out, "{line}");
    let rate = c.checked as f64 / secs;
    let _ = writeln!(
        out,
        "  an hour at this rate: {:.2e} inputs, {:.2e} builds",
        rate * 3600.0,
        c.built as f64 / secs * 3600.0
    );
    // The campaign's goals at this run's rate per lane, on `cores` cores
    // (a lane to a core). A target that builds nothing (or checks
    // nothing) says nothing of that goal.
    let scale = cores as f64 / lanes as f64;
    let check_rate = check_only as f64 / secs * scale;
    let build_rate = c.built as f64 / secs * scale;
    let mut goals = Vec::new();
    if matches!(target, Target::Mixed | Target::Check) && check_rate > 0.0 {
        goals.push(format!("10 M checks in {}", span(GOAL_CHECKS / check_rate)));
    }
    if matches!(target, Target::Mixed | Target::Build) && build_rate > 0.0 {
        goals.push(format!(
            "100 k builds in {}",
            span(GOAL_BUILDS / build_rate)
        ));
    }
    if !goals.is_empty() {
        let _ = writeln!(
            out,
            "  projection        on {cores} core(s) at this run's rate per lane: {}",
            goals.join(", ")
        );
    }
    // The same goals from the CPU time the run took (the workers and the
    // binaries they ran): on `cores` quiet cores each lane has a core of
    // its own, whatever the load was here.
    if let Some(cpu) = cpu.filter(|&t| t > 0.0 && total > 0) {
        let mut line = format!(
            "  CPU               {cpu:.1} s ({:.0} % of {lanes} lane(s)' wall time), {:.3} ms an input",
            100.0 * cpu / lane_secs,
            cpu * 1e3 / total as f64
        );
        if c.built > 0 {
            line.push_str(&format!(
                ", {:.1} ms a job built",
                cpu * 1e3 / c.built as f64
            ));
        }
        let mut goals = Vec::new();
        if target == Target::Check {
            goals.push(format!(
                "10 M checks in {}",
                span(GOAL_CHECKS * cpu / check_only.max(1) as f64 / cores as f64)
            ));
        }
        if target == Target::Build && c.built > 0 {
            goals.push(format!(
                "100 k builds in {}",
                span(GOAL_BUILDS * cpu / c.built as f64 / cores as f64)
            ));
        }
        if !goals.is_empty() {
            line.push_str(&format!("; on {cores} quiet core(s): {}", goals.join(", ")));
        }
        let _ = writeln!(out, "{line}");
    }
    let _ = writeln!(
        out,
        "  panics {}, hangs {}, aborts {} (workers started again: {}), uncoded rejections {} ({} distinct)",
        c.panics, c.hangs, c.aborts, c.restarts, c.uncoded, distinct
    );
}
