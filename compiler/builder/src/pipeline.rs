//! The pipeline over a file's jobs: each checked job is lowered to its
//! typed `JobSpec` (lensc-lang, with every check that needs no planning)
//! and handed to its strategy's builder — the one `match` over `JobSpec` —
//! and what it built is held to the job's acceptance criteria (`accept`).

use std::path::Path;

use crate::context::BuildContext;
use crate::job::{Estimate, Limits};
use crate::strategy::{JobSpec, lower_job};
use lensc_grammar::Diagnostic;
use lensc_lang::Checked;
use lensc_lang::check::CheckedJob;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};

use crate::evaluate::evaluator;
use crate::output::{Built, Destination};
use crate::progress::{Event, Meter, Observer, Phase};
use crate::read_back::ReadBack;

/// What `lensc build` was asked for beyond the file.
#[derive(Clone, Copy, Debug, Default)]
pub struct Request<'a> {
    /// Only this job.
    pub job: Option<&'a str>,
    /// This dialect instead of each machine's own (it must offer it).
    pub dialect: Option<&'a str>,
    /// The largest program (bytes) to write (`--max-program-size`); the
    /// default limit if `None`.
    pub max_program_size: Option<u64>,
    /// Whether a job whose simulated part misses its acceptance criteria
    /// is an error (the default) or a warning (`--accept=warn`).
    pub accept: crate::accept::Mode,
    /// Who hears how far the build has got (`progress`), if anyone.
    pub progress: Observer<'a>,
}

impl Request<'_> {
    /// The limits the build is held to.
    pub fn limits(&self) -> Limits {
        let mut l = Limits::default();
        if let Some(m) = self.max_program_size {
            l.max_program_size = m;
        }
        l
    }
}

/// How the build evaluates surfaces while lowering: the JIT, or the
/// interpreter should cranelift refuse the tape.
fn evaluate(tape: &SurfaceTape) -> Box<dyn SurfaceFn + Sync> {
    evaluator(tape).0
}

/// Lowers one checked job as a build does (its checks are what `lensc
/// check` reports beyond the checker's), with the estimate of what it
/// writes; a job whose estimate is over `limits` is refused.
pub fn lower(
    job: &CheckedJob,
    dialect: Option<&str>,
    limits: &Limits,
) -> Result<(JobSpec, Estimate), Vec<Diagnostic>> {
    let spec = lower_job(job, dialect, &evaluate)?;
    if let Some(d) = reserved_name(spec.head()) {
        return Err(vec![d]);
    }
    let estimate = spec.estimate(&evaluate);
    let refused = crate::job::refusals(spec.head(), &estimate, limits);
    if refused.is_empty() {
        Ok((spec, estimate))
    } else {
        Err(refused)
    }
}

/// The names, after the job's name and a dot, of the files a build or
/// `lensc report` writes beside a program (the report, the set-up sheet,
/// the plots).
pub const RESERVED_EXTENSIONS: [&str; 5] = [
    "report.json",
    crate::setup_sheet::EXTENSION,
    "profile.svg",
    "form_error.svg",
    "following.svg",
];

/// E0188 when the program's name (`JOB.EXT`) would be the name of a file
/// written beside it: the report, the set-up sheet, a plot, the dialect's
/// servo table.
/// Compared without case (a share on a case-blind file system), and any
/// extension ending in one of them (`x.report.json`) too.
fn reserved_name(head: &crate::job::JobHead) -> Option<Diagnostic> {
    let ext = head.dialect.extension.to_ascii_lowercase();
    let table = head
        .dialect
        .fts_table
        .as_deref()
        .map(str::to_ascii_lowercase);
    let clash = RESERVED_EXTENSIONS
        .iter()
        .map(|r| r.to_string())
        .chain(table.clone())
        .find(|r| ext == *r || ext.ends_with(&format!(".{r}")))?;
    let what = if Some(&clash) == table.as_ref() {
        "the servo table the dialect writes beside the program"
    } else if clash == "report.json" {
        "the build report"
    } else if clash == crate::setup_sheet::EXTENSION {
        "the set-up sheet"
    } else {
        "a plot `lensc report` writes"
    };
    Some(
        head.error(
            lensc_lang::codes::OUTPUT_NAME_RESERVED,
            format!(
                "the program `{}` would have the name of {what} (`{}.{clash}`)",
                head.program_name(),
                head.name
            ),
        )
        .with_help(format!(
            "give the dialect `{}` another extension (the names after the job's are reserved: {})",
            head.dialect.name,
            RESERVED_EXTENSIONS.join(", ")
        )),
    )
}

/// What `lensc check` reports of a checked file beyond the checker's own
/// findings: once the file checks, each job lowered as `build` lowers it
/// (in its machine's own dialect), with its refusals (the limits on its
/// points and program size among them) or the warnings it earns before
/// planning. Nothing while the file has errors. `lensc lsp` shows the
/// same for a saved document.
pub fn findings_before_planning(c: &Checked, limits: &Limits) -> Vec<Diagnostic> {
    if c.has_errors() {
        return Vec::new();
    }
    // A surface with no value over part of its aperture: refused here, as
    // the build would refuse it once planning.
    let mut found = crate::evaluate::undefined_surfaces(c, lensc_grammar::Severity::Error, None);
    for j in &c.checked.jobs {
        match lower(j, None, limits) {
            Ok((spec, _)) => found.extend(spec.warnings_before_planning()),
            Err(refused) => found.extend(refused),
        }
    }
    found
}

/// Builds programs and reports (without writing them) for the checked
/// jobs. Returns them and any further diagnostics. Large programs are
/// spooled into `spool_dir` (the output directory) when one is given.
pub fn plan_and_emit(
    c: &Checked,
    request: Request,
    source_name: &str,
    spool_dir: Option<&Path>,
) -> (Vec<Built>, Vec<Diagnostic>) {
    let (outcomes, diags) = plan_and_emit_outcomes(c, request, source_name, spool_dir);
    (built_only(outcomes), diags)
}

/// `plan_and_emit`, with every job's outcome, built or not, in the order
/// of the file (`lensc build`'s summary lists each).
pub fn plan_and_emit_outcomes(
    c: &Checked,
    request: Request,
    source_name: &str,
    spool_dir: Option<&Path>,
) -> (Vec<Outcome>, Vec<Diagnostic>) {
    let to = spool_dir.map_or(Destination::Memory, Destination::Spool);
    plan_jobs(c, request, source_name, to)
}

/// What became of one job of a build.
pub struct Outcome {
    /// The job's name.
    pub job: String,
    /// Its program and report, if it was built (refused by its acceptance
    /// gate or not: the report's figures say by how much it missed).
    pub built: Option<Built>,
    /// Built and passed its gate: its files may be written.
    pub accepted: bool,
    /// The codes of the errors that refused it, in order, each once.
    pub errors: Vec<&'static str>,
}

/// The jobs built and passed, in order.
fn built_only(outcomes: Vec<Outcome>) -> Vec<Built> {
    outcomes
        .into_iter()
        .filter(|o| o.accepted)
        .filter_map(|o| o.built)
        .collect()
}

/// The codes of the errors among `diags`, each once, in order.
fn error_codes(diags: &[Diagnostic]) -> Vec<&'static str> {
    let mut codes = Vec::new();
    for d in diags.iter().filter(|d| d.is_error()) {
        if !codes.contains(&d.code) {
            codes.push(d.code);
        }
    }
    codes
}

/// Plans and simulates the checked jobs as `plan_and_emit` does, with
/// their reports and plots, but formats no program of the spiral and
/// roller jobs (whose programs run to millions of lines): theirs come
/// back empty. For `lensc report`, which writes no program; a number a
/// dialect cannot print (E0150) is found by the build alone.
pub fn plan_and_simulate(
    c: &Checked,
    request: Request,
    source_name: &str,
) -> (Vec<Built>, Vec<Diagnostic>) {
    let (outcomes, diags) = plan_jobs(c, request, source_name, Destination::Nowhere);
    (built_only(outcomes), diags)
}

fn plan_jobs(
    c: &Checked,
    request: Request,
    source_name: &str,
    to: Destination,
) -> (Vec<Outcome>, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut out = Vec::new();
    let prov = Provenance {
        source: source_name.to_string(),
        source_hash: c.loaded.fnv1a64(),
        lensc_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let jobs: Vec<&CheckedJob> = c
        .checked
        .jobs
        .iter()
        .filter(|j| request.job.is_none_or(|n| j.name.name == n))
        .collect();
    let observer = request.progress;
    for (index, job) in jobs.iter().enumerate() {
        let name = job.name.name.as_str();
        observer.event(Event::Job {
            job: name,
            index,
            jobs: jobs.len(),
        });
        match build_job(job, &request, &prov, to) {
            Ok((mut b, mut gate)) => {
                diags.append(&mut b.warnings);
                let refused = gate.iter().any(|d| d.is_error());
                observer.event(Event::JobDone {
                    job: name,
                    built: !refused,
                    points: b.cut_points as u64,
                    bytes: b.program.bytes(),
                });
                // A job that fails its gate is not written (its spooled
                // program is removed as it is dropped).
                let errors = error_codes(&gate);
                diags.append(&mut gate);
                out.push(Outcome {
                    job: name.to_string(),
                    built: Some(b),
                    accepted: !refused,
                    errors,
                });
            }
            Err(mut d) => {
                out.push(Outcome {
                    job: name.to_string(),
                    built: None,
                    accepted: false,
                    errors: error_codes(&d),
                });
                diags.append(&mut d);
                observer.event(Event::JobDone {
                    job: name,
                    built: false,
                    points: 0,
                    bytes: 0,
                });
            }
        }
    }
    (out, diags)
}

/// One job lowered, built, read back and held to its acceptance criteria,
/// its observer told of each phase: what it built and the gate's
/// findings, or why it could not be built.
fn build_job(
    job: &CheckedJob,
    request: &Request,
    prov: &Provenance,
    to: Destination,
) -> Result<(Built, Vec<Diagnostic>), Vec<Diagnostic>> {
    let (name, observer) = (job.name.name.as_str(), request.progress);
    let phase = |phase, est: Option<&Estimate>| {
        observer.event(Event::Phase {
            job: name,
            phase,
            estimated_points: est.map_or(0, |e| e.points as u64),
            estimated_bytes: est.map_or(0, |e| e.program_bytes as u64),
        })
    };
    phase(Phase::Lowering, None);
    let (spec, est) = lower(job, request.dialect, &request.limits())?;
    phase(Phase::Planning, Some(&est));
    let meter = observer.meter(name, est.points as u64);
    // A program formatted nowhere has nothing to read back.
    let read = (crate::read_back::enabled() && !matches!(to, Destination::Nowhere))
        .then(|| ReadBack::of(job, spec.head()));
    let mut b = build_metered(&spec, prov, to, meter, read.as_ref())?;
    // Every count, told at the end of planning.
    observer.event(Event::Planned {
        job: name,
        points: b.cut_points as u64,
        bytes: b.program.bytes(),
    });
    if read.is_some() {
        phase(Phase::ReadingBack, Some(&est));
        read_back(job, &spec, &mut b)?;
    }
    b.read_back = read;
    b.report.estimate = (&est).into();
    b.warnings.extend(crate::plausibility::cutting_time_warning(
        spec.head(),
        b.cutting_time,
    ));
    let gate = crate::accept::gate(&spec, &mut b, request.accept);
    // A program larger than the control takes, split into parts a main
    // program calls (read back as one), and its link's rate checked.
    if !matches!(to, Destination::Nowhere) {
        let head = spec.head();
        let lathe = head.control.machine_kind != "mill_3axis";
        let peak = crate::delivery::peak_warning(head, &b, lathe);
        crate::delivery::deliver(head, &mut b, lathe)?;
        b.warnings
            .extend(crate::delivery::rate_warning(head, &b).or(peak));
    }
    // The set-up sheet, written in one unit with the program it sets up.
    if !matches!(to, Destination::Nowhere) {
        crate::setup_sheet::add(spec.head(), &mut b);
    }
    Ok((b, gate))
}

/// The reader's findings in `b`'s program (`job` lowered to `spec`) as
/// errors, if it refuses it.
fn read_back(job: &CheckedJob, spec: &JobSpec, b: &mut Built) -> Result<(), Vec<Diagnostic>> {
    let read = b.read_findings.take();
    let refused = crate::read_back::findings(job, spec.head(), &mut b.program, read);
    if refused.is_empty() {
        Ok(())
    } else {
        Err(refused)
    }
}

/// Plans, emits and simulates one lowered job with its strategy's builder;
/// the long programs go `to` memory, a spool file or nowhere (the
/// acceptance gate is `plan_and_emit`'s, after it).
pub fn build(spec: &JobSpec, prov: &Provenance, to: Destination) -> Result<Built, Vec<Diagnostic>> {
    build_metered(spec, prov, to, Meter::silent(), None)
}

/// `build` of `job` (lowered to `spec`) as `lensc build` makes it: its
/// program read back as well, or the reader's findings if it refuses it.
pub fn build_and_read_back(
    job: &CheckedJob,
    spec: &JobSpec,
    prov: &Provenance,
    to: Destination,
) -> Result<Built, Vec<Diagnostic>> {
    let read = ReadBack::of(job, spec.head());
    let mut b = build_metered(spec, prov, to, Meter::silent(), Some(&read))?;
    read_back(job, spec, &mut b)?;
    Ok(b)
}

/// `build`, the points the streamed builders plan and the bytes they
/// format counted by `meter` as they go; a streamed program spooled is
/// read back (`read`) as it is spooled.
fn build_metered(
    spec: &JobSpec,
    prov: &Provenance,
    to: Destination,
    meter: Meter,
    read: Option<&ReadBack>,
) -> Result<Built, Vec<Diagnostic>> {
    spec.build(&BuildContext {
        prov,
        to,
        meter,
        read,
    })
}
