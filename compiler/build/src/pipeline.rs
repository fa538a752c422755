//! The pipeline over a file's jobs: each checked job is lowered to its
//! typed `JobSpec` (lensc-lang, with every check that needs no planning)
//! and handed to its strategy's builder — the one `match` over `JobSpec`.

use std::path::Path;

use lensc_grammar::Diagnostic;
use lensc_lang::Checked;
use lensc_lang::check::CheckedJob;
use lensc_lang::lower::job::{JobSpec, lower_job};
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};

use crate::builders;
use crate::driver::{Built, evaluator, source_hash};

/// What `lensc build` was asked for beyond the file.
#[derive(Clone, Copy, Debug, Default)]
pub struct Request<'a> {
    /// Only this job.
    pub job: Option<&'a str>,
    /// This dialect instead of each machine's own (it must offer it).
    pub dialect: Option<&'a str>,
}

/// How the build evaluates surfaces while lowering: the JIT, or the
/// interpreter should cranelift refuse the tape.
fn evaluate(tape: &SurfaceTape) -> Box<dyn SurfaceFn + Sync> {
    evaluator(tape).0
}

/// Lowers one checked job as a build does (its checks are what `lensc
/// check` reports beyond the checker's).
pub fn lower(job: &CheckedJob, dialect: Option<&str>) -> Result<JobSpec, Vec<Diagnostic>> {
    lower_job(job, dialect, &evaluate)
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
    let mut diags = Vec::new();
    let mut out = Vec::new();
    let prov = Provenance {
        source: source_name.to_string(),
        source_hash: source_hash(&c.loaded),
        lensc_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let jobs = c
        .checked
        .jobs
        .iter()
        .filter(|j| request.job.is_none_or(|n| j.name.name == n));
    for job in jobs {
        let built = lower(job, request.dialect).and_then(|spec| build(&spec, &prov, spool_dir));
        match built {
            Ok(mut b) => {
                diags.append(&mut b.warnings);
                out.push(b);
            }
            Err(mut d) => diags.append(&mut d),
        }
    }
    (out, diags)
}

/// Plans, emits and simulates one lowered job with its strategy's builder.
pub fn build(
    spec: &JobSpec,
    prov: &Provenance,
    spool_dir: Option<&Path>,
) -> Result<Built, Vec<Diagnostic>> {
    match spec {
        JobSpec::Turning(s) => builders::turning::build(s, prov),
        JobSpec::Spiral(s) => builders::fts::build(s, prov, spool_dir),
        JobSpec::Raster(s) => builders::raster::build(s, prov),
        JobSpec::Grinding(s) => builders::grinding::build(s, prov),
        JobSpec::Roller(s) => builders::roller::build(s, prov, spool_dir),
    }
}
