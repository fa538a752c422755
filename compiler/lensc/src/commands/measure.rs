//! `lensc measure FILE PART [--job NAME]`: a measured part held to its
//! job's design (`lensc_build::measure`): the job lowered as `build`
//! lowers it, the measurement read under the project's file rules,
//! registered and figured (with `--lenslet`, the lenslet named checked
//! against the job's array before the file is read, the error pointing at
//! the job); `JOB.measure.json` and `JOB.error_map.svg`
//! written as one unit, or nothing and a coded error naming the file.

use std::path::Path;

use lensc::render;
use lensc_build::measure::{self, Failure, Options};
use lensc_grammar::{Diagnostic, Span};
use lensc_lang::source::SourceMap;

use crate::MessageFormat;
use crate::output::{Output, cannot_write, load_jobs};

/// Runs the subcommand; returns the exit code.
pub fn run(
    out: &Output,
    (file, part): (&Path, &Path),
    job: Option<&str>,
    dir: &Path,
    opts: Options,
) -> u8 {
    let c = match load_jobs(out, file, job) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let jobs: Vec<_> = c
        .checked
        .jobs
        .iter()
        .filter(|j| job.is_none_or(|n| j.name.name == n))
        .collect();
    let [checked_job] = jobs[..] else {
        let names: Vec<&str> = jobs.iter().map(|j| j.name.name.as_str()).collect();
        eprintln!(
            "error: {} has {} jobs ({}): name the one the part was cut by with --job",
            file.display(),
            names.len(),
            names.join(", ")
        );
        return 2;
    };
    let spec = match lensc_build::pipeline::lower(checked_job, None, &Default::default()) {
        Ok((spec, _)) => spec,
        Err(diags) => {
            out.diagnostics(&c, &diags);
            return 1;
        }
    };
    // The lenslet named must be one of the job's array's: said over the
    // job, before the measurement is read.
    if let Some(pick) = opts.lenslet
        && let Err(f) = measure::lenslet_of(spec.head(), pick)
    {
        let (file_id, span) = spec.head().site;
        let mut d = Diagnostic::error(f.code, f.message.clone(), file_id, span);
        if let Some(h) = &f.help {
            d = d.with_help(h.clone());
        }
        out.diagnostics(&c, &[d]);
        return 1;
    }
    let root = out.root.clone().unwrap_or_else(|| {
        file.parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf()
    });
    let name = part.display().to_string();
    let bytes = match measure::read_file(part, &root) {
        Ok(b) => b,
        Err(f) => return refuse(out, part, &[], &f),
    };
    let outcome = match measure::measure(&spec, &name, &bytes, &opts) {
        Ok(o) => o,
        Err(f) => return refuse(out, part, &bytes, &f),
    };
    let job_name = &outcome.report.job;
    let json = lensc_build::report::json_text(&outcome.report);
    let files = [
        (format!("{job_name}.measure.json"), json),
        (format!("{job_name}.error_map.svg"), outcome.svg),
    ];
    let mut temps = Vec::new();
    for (n, text) in &files {
        let target = dir.join(n);
        match lensc_build::driver::output_path(dir, n)
            .and_then(|p| lensc_build::output::text_temp(dir, text).map(|t| (t, p)))
        {
            Ok(t) => temps.push(t),
            Err(e) => {
                cannot_write(&target, &e);
                return 1;
            }
        }
    }
    if let Err(e) = lensc_build::driver::put_in_place(temps) {
        cannot_write(dir, &e);
        return 1;
    }
    let f = &outcome.report.form_error;
    let r = &outcome.report.registration;
    if out.format == MessageFormat::Human {
        eprintln!(
            "{name}: error along the normal PV {:.2} nm, RMS {:.2} nm; decentre {:.3}, {:.3} µm, tilt {:.1}, {:.1} µrad",
            f.pv_nm, f.rms_nm, r.decentre_x_um, r.decentre_y_um, r.tilt_x_urad, r.tilt_y_urad
        );
    }
    if let Some(f) = outcome
        .report
        .lenslet
        .as_ref()
        .and_then(|l| l.finding.as_ref())
    {
        warn(out, part, &bytes, &[f]);
    }
    if let (Some(l), MessageFormat::Human) = (&outcome.report.lenslet, out.format) {
        eprintln!(
            "{name}: lenslet {} (row {}, column {}; centre x = {}, y = {} mm), {:.1} % of its aperture measured; {} found on the part at x = {:.4}, y = {:.4} mm",
            l.index,
            l.row,
            l.column,
            l.centre_mm[0],
            l.centre_mm[1],
            100.0 * l.aperture_covered,
            l.reference,
            l.found_at_mm[0],
            l.found_at_mm[1]
        );
    }
    if let Some(l) = &outcome.report.lenslets {
        let findings: Vec<_> = l.each.iter().filter_map(|e| e.finding.as_ref()).collect();
        if !findings.is_empty() {
            warn(out, part, &bytes, &findings);
        }
        if out.format == MessageFormat::Human {
            eprintln!(
                "{name}: lenslet by lenslet: {} of the array's {} reached, {} registered",
                l.reached,
                l.in_array,
                l.reached - l.not_registered
            );
        }
    }
    for (n, text) in &files {
        eprintln!("wrote {} ({} bytes)", dir.join(n).display(), text.len());
    }
    0
}

/// Prints each lenslet's finding (W0036, W0037) as a warning naming the
/// measurement file: a finding is of the whole map, at no byte of it, so
/// no line of the file is shown (`plain`).
fn warn(out: &Output, part: &Path, bytes: &[u8], findings: &[&measure::report::Finding]) {
    let help = |code: &str| {
        if code == lensc_lang::codes::FIELD_PART_OF_LENSLET {
            "centre the field on the lenslet (or give where it lay with --at) to measure all of it"
        } else {
            "measure that lenslet again, or lower --min-valid knowing what its figures then cover"
        }
    };
    if out.format == MessageFormat::Human {
        for f in findings {
            plain(
                "warning",
                &f.code,
                &f.message,
                Some(help(&f.code)),
                part,
                None,
            );
        }
        return;
    }
    let text = std::str::from_utf8(bytes)
        .map(str::to_owned)
        .unwrap_or_default();
    let mut sources = SourceMap::default();
    let id = sources.add(part.display().to_string(), Some(part.to_path_buf()), text);
    let diags: Vec<Diagnostic> = findings
        .iter()
        .map(|f| {
            let code = if f.code == lensc_lang::codes::FIELD_PART_OF_LENSLET {
                lensc_lang::codes::FIELD_PART_OF_LENSLET
            } else {
                lensc_lang::codes::LENSLET_NOT_REGISTERED
            };
            Diagnostic::warning(code, f.message.clone(), id, Span::new(0, 0)).with_help(help(code))
        })
        .collect();
    let _ = render::json_lines(&diags, &sources, &mut std::io::stdout().lock());
}

/// A diagnostic about the measurement file `part` with no line of it to
/// show: the file is binary (an X3P, a MetroPro `.dat`), or what is wrong
/// lies at no byte of it (a registration, a mask). The message names the
/// file; the line under it names the byte, where one is known.
fn plain(
    severity: &str,
    code: &str,
    message: &str,
    help: Option<&str>,
    part: &Path,
    at: Option<usize>,
) {
    eprintln!("{severity}[{code}]: {message}");
    match at {
        Some(at) => eprintln!("  --> {}, byte {at}", part.display()),
        None => eprintln!("  --> {}", part.display()),
    }
    if let Some(h) = help {
        eprintln!("  help: {h}");
    }
}

/// Prints a refusal over the measurement file and returns exit code 1:
/// with the line it points at where the file is text and the failure lies
/// at a byte of it; otherwise named in words (`plain`), with no line.
fn refuse(out: &Output, part: &Path, bytes: &[u8], f: &Failure) -> u8 {
    let text = std::str::from_utf8(bytes).ok();
    let shown = text.zip(f.at).filter(|(t, a)| *a <= t.len());
    if out.format == MessageFormat::Human && shown.is_none() {
        plain("error", f.code, &f.message, f.help.as_deref(), part, f.at);
        return 1;
    }
    let at = shown.map_or(f.at.unwrap_or(0), |(_, a)| a);
    let mut sources = SourceMap::default();
    let id = sources.add(
        part.display().to_string(),
        Some(part.to_path_buf()),
        text.unwrap_or_default().to_owned(),
    );
    let mut d = Diagnostic::error(f.code, f.message.clone(), id, Span::new(at, at));
    if let Some(h) = &f.help {
        d = d.with_help(h.clone());
    }
    let _ = match out.format {
        MessageFormat::Human => {
            render::human(&[d], &sources, out.color, &mut std::io::stderr().lock())
        }
        MessageFormat::Json => render::json_lines(&[d], &sources, &mut std::io::stdout().lock()),
    };
    1
}
