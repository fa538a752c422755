//! The summary `lensc build` prints for each job once the build is over:
//! its verdict, the form figures it was judged on (PV, RMS, gouge,
//! residual, each with its limit), the area judged, the cutting time and
//! the program written — a few aligned lines a person reads at a glance,
//! taken from the job's report (the JSON holds the rest).

use lensc_build::report::{CriterionResult, HeightMap, LimitSource, Report, Simulation};

/// What became of a job, as its summary says it.
pub enum Fate<'a> {
    /// Built, judged and written: the program and report at these paths,
    /// and the files beside them (set-up sheet, servo table).
    Written {
        program: &'a str,
        report: &'a str,
        beside: &'a [String],
    },
    /// Built and passed, but not written: another job failed and the
    /// build writes all or nothing (`--keep-going` writes it).
    Held,
    /// Built and passed, but its files could not be written.
    NotWritten,
    /// Built, but refused by its acceptance gate: the figures say why.
    Refused { errors: &'a [&'static str] },
    /// Not built: these errors refused it.
    NotBuilt { errors: &'a [&'static str] },
}

/// What the summary needs of a built job beyond its report.
pub struct Program {
    pub lines: usize,
    pub bytes: u64,
    /// Estimated cutting time (s).
    pub cutting_time: f64,
}

/// The summary of one job, a line for its verdict and one per figure,
/// the labels aligned; every line ends with a newline.
pub fn job_summary(job: &str, fate: &Fate, built: Option<(&Report, &Program)>) -> String {
    let mut out = format!("{job}: {}\n", verdict(fate, built.map(|(r, _)| r)));
    let Some((report, program)) = built else {
        return out;
    };
    let mut line = |label: &str, text: String| {
        out.push_str(&format!("  {label:<9} {text}\n"));
    };
    for (label, criterion) in [
        ("PV", "form_pv"),
        ("RMS", "form_rms"),
        ("gouge", "max_gouge"),
        ("residual", "max_residual"),
    ] {
        if let Some(text) = figure(report, criterion) {
            line(label, text);
        }
    }
    if let Some(text) = lenslets(report) {
        line("lenslets", text);
    }
    line("judged", judged(&report.simulation));
    if let Some(c) = &report.compensation {
        line(
            "corrected",
            format!(
                "from {} (measured {:.2} nm PV, {:.2} nm RMS), gain {}, smoothing {} mm: next part predicted {:.2} nm PV, {:.2} nm RMS",
                c.measurement,
                c.measured_pv_nm,
                c.measured_rms_nm,
                c.gain,
                c.smoothing_mm,
                c.predicted_pv_nm,
                c.predicted_rms_nm
            ),
        );
    }
    line("cutting", duration(program.cutting_time));
    let size = format!("{} lines, {}", program.lines, bytes(program.bytes));
    match fate {
        Fate::Written {
            program: path,
            report: report_path,
            beside,
        } => {
            let mut others: Vec<&str> = beside.iter().map(String::as_str).collect();
            others.push(report_path);
            let last = others.pop().unwrap_or_default();
            let rest = others.iter().map(|o| format!(", {o}")).collect::<String>();
            line("wrote", format!("{path} ({size}){rest} and {last}"))
        }
        _ => line("program", format!("{size}, not written")),
    }
    out
}

/// The verdict's words: passed, refused and why, not built and why.
fn verdict(fate: &Fate, report: Option<&Report>) -> String {
    let judged = |r: &Report| match r.acceptance.mode {
        lensc_build::report::AcceptanceMode::None => "not judged (accept: none)",
        _ if r.acceptance.passed => "passed",
        _ => "missed its acceptance criteria (--accept=warn)",
    };
    match fate {
        Fate::Written { .. } => format!("{}, written", report.map_or("built", judged)),
        Fate::Held => format!(
            "{}, not written: another job failed (all or nothing; --keep-going writes the jobs that pass)",
            report.map_or("built", judged)
        ),
        Fate::NotWritten => format!(
            "{}, not written (see the error above)",
            report.map_or("built", judged)
        ),
        Fate::Refused { errors } => {
            format!("REFUSED by its acceptance gate ({})", errors.join(", "))
        }
        Fate::NotBuilt { errors } => format!("NOT BUILT ({})", errors.join(", ")),
    }
}

/// A criterion's figure with its limit (`2.72 nm, limit 5 nm (stated)`),
/// or the simulation's figure where the job is not judged on it; `None`
/// if the report has neither.
fn figure(report: &Report, criterion: &str) -> Option<String> {
    if let Some(c) = report
        .acceptance
        .criteria
        .iter()
        .find(|c| c.criterion == criterion)
    {
        return Some(judged_figure(c));
    }
    simulated(&report.simulation, criterion).map(|v| format!("{} nm", nm(v)))
}

fn judged_figure(c: &CriterionResult) -> String {
    let source = match c.source {
        LimitSource::Stated => "stated",
        LimitSource::Default => "default",
    };
    // Why a figure is unmeasured is the gate's error, printed above.
    let measured = c
        .measured
        .map_or_else(|| "unmeasured".to_string(), |m| format!("{} nm", nm(m)));
    let mark = if c.passed { "" } else { "  MISSED" };
    format!("{measured:<10} limit {} nm ({source}){mark}", mm(c.limit))
}

/// The simulation's own figure for `criterion`, in nm.
fn simulated(sim: &Simulation, criterion: &str) -> Option<f64> {
    if let Simulation::Profile(p) = sim {
        return match criterion {
            "form_pv" => p.form_error_pv_nm,
            "form_rms" => p.form_error_rms_nm,
            "max_gouge" => Some(p.max_gouge_nm.value),
            "max_residual" => Some(p.max_residual_nm.value),
            _ => None,
        };
    }
    let f = height_map(sim).and_then(|h| h.contact.or(h.surface))?;
    match criterion {
        "form_pv" => Some(f.pv_nm),
        "form_rms" => Some(f.rms_nm),
        "max_gouge" => Some(f.max_gouge_nm.value),
        "max_residual" => Some(f.max_residual_nm.value),
        _ => None,
    }
}

fn height_map(sim: &Simulation) -> Option<&HeightMap> {
    match sim {
        Simulation::Profile(_) => None,
        Simulation::Following(f) => Some(&f.height_map),
        Simulation::HeightMap(h) => Some(&h.height_map),
        Simulation::Skipped(s) => s.height_map.as_ref(),
    }
}

/// An array's lenslets: how many, the worst named (its index and centre)
/// with its figures, and how many miss their limits; `None` without
/// lenslets.
fn lenslets(report: &Report) -> Option<String> {
    let h = height_map(&report.simulation)?;
    let w = h.worst_lenslet.as_ref()?;
    let mut missed: Vec<usize> = report
        .acceptance
        .lenslets
        .iter()
        .flat_map(|c| c.missed.iter().copied())
        .collect();
    missed.sort_unstable();
    missed.dedup();
    let verdict = match missed.len() {
        0 if report.acceptance.lenslets.is_empty() => String::new(),
        0 => ", every one within its limits".to_string(),
        1 => ", 1 misses its limits".to_string(),
        n => format!(", {n} miss their limits"),
    };
    Some(format!(
        "{}, the worst {} at x {}, y {} mm: PV {} nm, residual {} nm{verdict}",
        h.lenslets.len(),
        w.index,
        mm(w.centre_mm[0]),
        mm(w.centre_mm[1]),
        nm(w.pv_nm),
        nm(w.max_residual_nm)
    ))
}

/// The area the figures come from: a profile's radii, or a height map's
/// extent (the whole part, or a window stated by the job's `simulate`
/// block).
fn judged(sim: &Simulation) -> String {
    if let Simulation::Profile(p) = sim {
        return match (p.from_radius_mm, p.to_radius_mm) {
            (Some(a), Some(b)) => format!("the profile, radius {} to {} mm", mm(a), mm(b)),
            _ => "nothing: no radius was sampled".to_string(),
        };
    }
    let Some(h) = height_map(sim) else {
        return match sim {
            Simulation::Skipped(s) => format!("nothing: {}", s.skipped),
            _ => "nothing".to_string(),
        };
    };
    let w = &h.window;
    let whose = if w.whole_part {
        "the whole part"
    } else if w.given {
        "the job's `simulate` window"
    } else {
        "the default window"
    };
    format!(
        "{whose}, x {} to {} mm, y {} to {} mm, at {} mm ({} mm² simulated)",
        mm(w.x_mm[0]),
        mm(w.x_mm[1]),
        mm(w.y_mm[0]),
        mm(w.y_mm[1]),
        mm(w.spacing_mm),
        mm(h.simulated_area_mm2)
    )
}

/// A figure in nm to about three significant digits.
pub fn nm(v: f64) -> String {
    let a = v.abs();
    if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// A length in mm (or a limit in nm) in its fewest digits up to 1e-4.
fn mm(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A duration as a machinist reads it: `41.5 s`, `2 min 21.5 s`,
/// `59 h 46 min`.
pub fn duration(s: f64) -> String {
    if !s.is_finite() {
        return "unknown".to_string();
    }
    if s < 60.0 {
        format!("{s:.1} s")
    } else if s < 3600.0 {
        let m = (s / 60.0).floor();
        format!("{m} min {:.1} s", s - 60.0 * m)
    } else {
        let total = (s / 60.0).round();
        let h = (total / 60.0).floor();
        format!("{h} h {} min", total - 60.0 * h)
    }
}

/// A size in bytes, in decimal units (`1.2 kB`, `27.6 MB`).
pub fn bytes(b: u64) -> String {
    let v = b as f64;
    if b < 1000 {
        format!("{b} B")
    } else if v < 1e6 {
        format!("{:.1} kB", v / 1e3)
    } else if v < 1e9 {
        format!("{:.1} MB", v / 1e6)
    } else {
        format!("{:.2} GB", v / 1e9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_a_machinist_reads_them() {
        assert_eq!(duration(41.54), "41.5 s");
        assert_eq!(duration(141.5), "2 min 21.5 s");
        assert_eq!(duration(59.0 * 3600.0 + 46.0 * 60.0 + 10.0), "59 h 46 min");
        assert_eq!(duration(f64::NAN), "unknown");
    }

    #[test]
    fn sizes_and_figures_keep_three_digits() {
        assert_eq!(bytes(999), "999 B");
        assert_eq!(bytes(1_130), "1.1 kB");
        assert_eq!(bytes(27_550_000), "27.6 MB");
        assert_eq!(nm(2.7222), "2.72");
        assert_eq!(nm(25.43), "25.4");
        assert_eq!(nm(877.4), "877");
        assert_eq!(mm(-0.0), "0");
        assert_eq!(mm(0.1), "0.1");
    }
}
