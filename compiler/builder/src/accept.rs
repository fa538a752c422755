//! The acceptance gate: a built job's simulated part against the criteria
//! its `accept` block states, the rest at defaults derived from the
//! machine: the path tolerance its class holds (or the strategy's, if
//! tighter) and its resolution (`job::accept::default_limit`). Each criterion
//! missed (or that the simulation cannot measure) is a coded diagnostic
//! naming the criterion, by how much and where on the part — an error
//! that stops the program being written, or under `--accept=warn` a
//! warning — and every criterion goes into the report's `acceptance`
//! section with its limit, the figure measured and pass or fail.
//!
//! The figures are read from the report the builder filled (the one
//! place every strategy's simulation lands), so a criterion is measured
//! the same way for every strategy.

mod lenslets;

use crate::job::accept::{self, Accept, Criterion};
use crate::strategy::JobSpec;
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_runtime::surface::analysis::Domain;

use crate::output::Built;
use crate::report::{
    AcceptanceMode, CriterionResult, HeightMap, Judged, JudgedArea, LimitSource, Place, ProfileCut,
    Simulation,
};

/// How a build treats criteria missed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Errors: no program is written (the default).
    #[default]
    Gate,
    /// Warnings: the program is written (`--accept=warn`).
    Warn,
}

use crate::job::accept::DEFAULT_TOLERANCE;

/// Runs the gate on `built` (lowered as `spec`): fills the report's
/// `acceptance` and returns a diagnostic per criterion missed or not
/// measurable (errors under `Mode::Gate`, warnings under `Mode::Warn`).
pub fn gate(spec: &JobSpec, built: &mut Built, mode: Mode) -> Vec<Diagnostic> {
    let head = spec.head();
    let judged = judged(&built.report.simulation);
    if head.accept == Accept::Nothing {
        built.report.acceptance = crate::report::Acceptance {
            judged,
            ..crate::report::Acceptance::pending()
        };
        return Vec::new();
    }
    let tolerance = spec.path_tolerance();
    let holds = crate::job::holds(head.resolution, spec.length_axes());
    let mut results = Vec::new();
    let mut diags = Vec::new();
    // Criteria the simulation cannot measure, by the reason: one
    // diagnostic a reason.
    let mut unmeasured: Vec<Unmeasured> = Vec::new();
    // The form criteria's limits, for the lenslets.
    let mut form_limits = Vec::new();
    for c in Criterion::ALL {
        let stated = head.accept.stated(c);
        let limit = match stated {
            Some(l) => Limit {
                value: l.value,
                fraction: l.fraction,
                rule: None,
            },
            None => match default_limit(c, tolerance, head.resolution, holds) {
                Some(l) => l,
                None => continue,
            },
        };
        let r = judge(c, &limit, built, &head.surface.lowered.domain);
        // A following error is held to its default only where the job
        // simulates one (a fast tool servo with a servo model).
        if stated.is_none() && c == Criterion::MaxFollowingError && r.unmeasured.is_some() {
            continue;
        }
        form_limits.push((c, r.limit, stated.map(|l| l.site)));
        match r.unmeasured {
            Some(why) => match unmeasured.iter_mut().find(|u| u.0 == why) {
                Some(u) => {
                    u.1.push(c.name());
                    u.2 = u.2.or(stated.map(|l| l.site));
                }
                None => unmeasured.push((why, vec![c.name()], stated.map(|l| l.site))),
            },
            None if !r.passed => {
                let site = stated.map(|l| l.site).unwrap_or(head.site);
                diags.push(missed(c, &limit, &r, site, stated.is_some(), mode));
            }
            None => {}
        }
        results.push(r);
    }
    for (why, names, site) in unmeasured {
        diags.push(cannot_measure(why, &names, site, head.site, mode));
    }
    let lenslets = match form(&built.report.simulation) {
        Ok(Form::Map(h)) => lenslets::judge(h, &form_limits),
        _ => Vec::new(),
    };
    // A lenslet is named where the whole part passes: where it misses,
    // its diagnostic says so already (the summary names the worst).
    let whole_passed = |name: &str| results.iter().any(|r| r.criterion == name && r.passed);
    for l in lenslets
        .iter()
        .filter(|l| !l.passed && whole_passed(l.criterion))
    {
        diags.push(lenslets::missed(l, &form_limits, head.site, mode));
    }
    built.report.acceptance = crate::report::Acceptance {
        mode: match mode {
            Mode::Gate => AcceptanceMode::Gate,
            Mode::Warn => AcceptanceMode::Warn,
        },
        passed: results.iter().all(|r| r.passed) && lenslets.iter().all(|l| l.passed),
        criteria: results,
        judged,
        lenslets,
    };
    diags
}

/// The area of the part `sim`'s figures come from, in words: the whole
/// part or the window of a height map (with its place, size and spacing),
/// or the radii a profile samples.
fn judged(sim: &Simulation) -> Judged {
    let um = |mm: f64| trim_num((mm * 1e4).round() / 10.0);
    let mm = |v: f64| trim_num((v * 1e4).round() / 1e4);
    match form(sim) {
        Ok(Form::Map(h)) => {
            let w = &h.window;
            let place = format!(
                "x {} .. {} mm, y {} .. {} mm at {} um",
                mm(w.x_mm[0]),
                mm(w.x_mm[1]),
                mm(w.y_mm[0]),
                mm(w.y_mm[1]),
                um(w.spacing_mm)
            );
            if w.whole_part {
                Judged {
                    area: JudgedArea::WholePart,
                    words: format!("whole part ({place})"),
                }
            } else {
                Judged {
                    area: JudgedArea::Window,
                    words: format!(
                        "window {} x {} mm of the part ({place}, the job's `simulate` block)",
                        mm(w.x_mm[1] - w.x_mm[0]),
                        mm(w.y_mm[1] - w.y_mm[0])
                    ),
                }
            }
        }
        Ok(Form::Profile(p)) => Judged {
            area: JudgedArea::WholePart,
            words: match (p.from_radius_mm, p.to_radius_mm) {
                (Some(a), Some(b)) => format!(
                    "whole profile ({} samples, r {} .. {} mm)",
                    p.samples,
                    mm(a),
                    mm(b)
                ),
                _ => "whole profile".into(),
            },
        },
        Err(why) => Judged {
            area: JudgedArea::None,
            words: why.into(),
        },
    }
}

/// Why criteria cannot be measured, their names, and where the first of
/// them was stated (none: all at their defaults).
type Unmeasured = (&'static str, Vec<&'static str>, Option<(FileId, Span)>);

/// A limit in the criterion's own base unit (mm, mm², a fraction, s), and
/// how it was derived if it is a default.
struct Limit {
    value: f64,
    fraction: bool,
    rule: Option<String>,
}

/// The default limit of `c` for a strategy planned to `tolerance` (mm;
/// `None`: it has none of its own) on a machine of `resolution` (mm)
/// (`accept::default_limit`: the form error lies within ±(tolerance +
/// resolution)), with the rule that derives it in words.
fn default_limit(
    c: Criterion,
    tolerance: Option<f64>,
    resolution: f64,
    holds: f64,
) -> Option<Limit> {
    let value = accept::default_limit(c, tolerance, resolution, holds)?;
    let t_words = match tolerance {
        Some(t) if t > holds => format!(
            "{} nm (the least of the path tolerance {} nm and the {} nm the machine holds: a looser path does not loosen the part)",
            trim_num(holds * 1e6),
            trim_num(t * 1e6),
            trim_num(holds * 1e6)
        ),
        Some(t) => format!("the path tolerance {} nm", trim_num(t * 1e6)),
        None => format!(
            "{} nm (the strategy has no path tolerance: the default chord_tolerance)",
            trim_num(DEFAULT_TOLERANCE * 1e6)
        ),
    };
    let sum = format!(
        "{t_words} + the machine's resolution {} nm",
        trim_num(resolution * 1e6)
    );
    let rule = match c {
        Criterion::FormPv => format!("2 × ({sum})"),
        Criterion::FormRms => format!("({sum}) / 2"),
        Criterion::MaxGouge | Criterion::MaxResidual => sum,
        Criterion::MaxFollowingError => format!(
            "{sum}: the servo's lag moves the cut by as much, beyond the form the commands simulate"
        ),
        Criterion::UncutArea => "none of the area simulated left uncut".into(),
        Criterion::MaxCuttingTime => return None,
    };
    Some(Limit {
        value,
        fraction: false,
        rule: Some(rule),
    })
}

/// A figure measured (in the report's unit for the criterion) and where.
struct Measured {
    value: f64,
    at: Vec<Place>,
}

/// The criterion's unit in the report, and the factor from its base unit.
fn unit(c: Criterion, fraction: bool) -> (&'static str, f64) {
    match c {
        Criterion::UncutArea if fraction => ("fraction", 1.0),
        Criterion::UncutArea => ("mm2", 1.0),
        Criterion::MaxCuttingTime => ("s", 1.0),
        _ => ("nm", 1e6),
    }
}

/// `c` measured on `built` and compared with `limit`.
fn judge(c: Criterion, limit: &Limit, built: &Built, domain: &Domain) -> CriterionResult {
    let (unit, factor) = unit(c, limit.fraction);
    // In the report's unit, without the scaling's last-digit noise (50
    // nm, not 49.99999999999999).
    let limit_shown = round_to(limit.value * factor, 1e-9);
    let measured = measure(c, limit.fraction, built, domain);
    let (value, at, unmeasured) = match measured {
        Ok(m) => (Some(m.value), m.at, None),
        Err(why) => (None, Vec::new(), Some(why)),
    };
    CriterionResult {
        criterion: c.name(),
        unit,
        limit: limit_shown,
        source: if limit.rule.is_some() {
            LimitSource::Default
        } else {
            LimitSource::Stated
        },
        default_rule: limit.rule.clone(),
        measured: value,
        at,
        // A figure NaN is a failure, not a pass.
        passed: value.is_some_and(|v| v <= limit_shown),
        unmeasured,
    }
}

/// What the simulation gives for the form: a height map or a profile.
enum Form<'a> {
    Map(&'a HeightMap),
    Profile(&'a ProfileCut),
}

fn form(sim: &Simulation) -> Result<Form<'_>, &'static str> {
    match sim {
        Simulation::Profile(p) => Ok(Form::Profile(p)),
        Simulation::Following(f) => Ok(Form::Map(&f.height_map)),
        Simulation::HeightMap(h) => Ok(Form::Map(&h.height_map)),
        Simulation::Skipped(s) => s.height_map.as_ref().map(Form::Map).ok_or(s.skipped),
    }
}

fn point(what: &'static str, p: &crate::report::AtPoint) -> Place {
    Place {
        what,
        x_mm: Some(p.x_mm),
        y_mm: Some(p.y_mm),
        radius_mm: None,
    }
}

fn radius(what: &'static str, r: f64) -> Place {
    Place {
        what,
        x_mm: None,
        y_mm: None,
        radius_mm: Some(r),
    }
}

const NO_CONTACT: &str = "no pass's contact fell in the simulation window";
const NO_RADIUS: &str = "the simulated profile cut no radius";

/// The figure `c` of `built`'s simulated part.
fn measure(
    c: Criterion,
    fraction: bool,
    built: &Built,
    domain: &Domain,
) -> Result<Measured, &'static str> {
    let sim = &built.report.simulation;
    let m = |value: f64, at: Vec<Place>| Ok(Measured { value, at });
    match c {
        Criterion::MaxCuttingTime => m(built.cutting_time, Vec::new()),
        Criterion::MaxFollowingError => match sim {
            Simulation::Following(f) => m(
                f.max_following_error_nm.value,
                vec![radius("worst", f.max_following_error_nm.at_radius_mm)],
            ),
            Simulation::Skipped(s) if s.height_map.is_some() => Err(s.skipped),
            _ => Err("only a fast-tool-servo job with a servo model simulates its following"),
        },
        Criterion::UncutArea => {
            let (uncut, area, at) = match form(sim)? {
                Form::Map(h) => (
                    h.uncut_area_mm2,
                    h.simulated_area_mm2,
                    h.first_uncut_mm.map(|[x, y]| Place {
                        what: "first_uncut",
                        x_mm: Some(x),
                        y_mm: Some(y),
                        radius_mm: None,
                    }),
                ),
                Form::Profile(p) => (
                    p.uncut_area_mm2,
                    p.simulated_area_mm2,
                    p.first_uncut_radius_mm.map(|r| radius("first_uncut", r)),
                ),
            };
            let value = if !fraction {
                uncut
            } else if area > 0.0 {
                uncut / area
            } else {
                0.0
            };
            m(value, at.into_iter().collect())
        }
        _ => form_figure(c, form(sim)?, domain),
    }
}

/// A form criterion (PV, RMS, gouge, residual) of a height map's
/// contacts (its gouge over every cell too) or of a profile.
fn form_figure(c: Criterion, form: Form, domain: &Domain) -> Result<Measured, &'static str> {
    let m = |value: f64, at: Vec<Place>| Ok(Measured { value, at });
    match form {
        Form::Map(h) => {
            let f = h.contact.as_ref().ok_or(NO_CONTACT)?;
            match c {
                Criterion::FormPv => m(
                    f.pv_nm,
                    vec![
                        point("highest", &f.max_residual_nm),
                        point("lowest", &f.max_gouge_nm),
                    ],
                ),
                Criterion::FormRms => m(f.rms_nm, Vec::new()),
                Criterion::MaxResidual => {
                    // At the contacts, or at any cell beyond the scallops
                    // its own neighbouring passes leave beside it (a rim
                    // or an axis no contact reaches), the larger: as each
                    // lenslet is judged.
                    let r = crate::report::max_residual(Some(f), h.residual_beyond_scallops_nm)
                        .unwrap_or(f.max_residual_nm);
                    let what = if r.value <= f.max_residual_nm.value {
                        "highest"
                    } else if at_rim(domain, r.x_mm, r.y_mm) {
                        "highest_where_no_contact_reached,_at_the_rim"
                    } else {
                        "highest_where_no_contact_reached"
                    };
                    m(r.value, vec![point(what, &r)])
                }
                _ => {
                    // The deepest cut at the contacts or at any cell.
                    let mut g = f.max_gouge_nm;
                    if let Some(s) = &h.surface
                        && s.max_gouge_nm.value > g.value
                    {
                        g = s.max_gouge_nm;
                    }
                    m(g.value, vec![point("deepest", &g)])
                }
            }
        }
        Form::Profile(p) => {
            let (res, gouge) = (p.max_residual_nm, p.max_gouge_nm);
            match c {
                Criterion::FormPv => m(
                    p.form_error_pv_nm.ok_or(NO_RADIUS)?,
                    vec![
                        radius("highest", res.at_radius_mm),
                        radius("lowest", gouge.at_radius_mm),
                    ],
                ),
                Criterion::FormRms => m(p.form_error_rms_nm.ok_or(NO_RADIUS)?, Vec::new()),
                Criterion::MaxResidual => m(res.value, vec![radius("highest", res.at_radius_mm)]),
                _ => m(gouge.value, vec![radius("deepest", gouge.at_radius_mm)]),
            }
        }
    }
}

/// Whether (x, y) (mm) lies at the rim of the aperture `domain`: within
/// 1 % of the edge's distance from the spindle axis along its ray, or of
/// the rectangle's size from its sides.
fn at_rim(domain: &Domain, x: f64, y: f64) -> bool {
    match *domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => {
            x.hypot(y) >= 0.99 * radius
        }
        Domain::Rect {
            x: (x0, x1),
            y: (y0, y1),
        } => {
            let m = 0.01 * (x1 - x0).max(y1 - y0);
            x - x0 <= m || x1 - x <= m || y - y0 <= m || y1 - y <= m
        }
    }
}

/// The figure and its unit for a message.
fn shown(v: f64, unit: &str) -> String {
    match unit {
        "nm" if v.abs() >= 1000.0 => format!("{} µm", trim_num(round_to(v / 1000.0, 0.001))),
        "nm" => format!("{} nm", trim_num(round_to(v, 0.01))),
        "mm2" => format!("{} mm²", trim_num(v)),
        "fraction" => format!("{} %", trim_num(round_to(v * 100.0, 0.001))),
        _ => hours(v),
    }
}

fn round_to(v: f64, step: f64) -> f64 {
    (v / step).round() * step
}

/// A time in s as h, min or s.
fn hours(s: f64) -> String {
    if s >= 3600.0 {
        format!("{} h", trim_num(round_to(s / 3600.0, 0.01)))
    } else if s >= 60.0 {
        format!("{} min", trim_num(round_to(s / 60.0, 0.1)))
    } else {
        format!("{} s", trim_num(round_to(s, 0.1)))
    }
}

/// The places of a result in words: "highest at x = 1, y = 2 mm, …".
fn places(at: &[Place]) -> String {
    let one = |p: &Place| {
        let what = p.what.replace('_', " ");
        match (p.x_mm, p.y_mm, p.radius_mm) {
            (Some(x), Some(y), _) => format!(
                "{what} at x = {}, y = {} mm",
                trim_num(round_to(x, 1e-4)),
                trim_num(round_to(y, 1e-4))
            ),
            (_, _, Some(r)) => format!("{what} at r = {} mm", trim_num(round_to(r, 1e-4))),
            _ => what,
        }
    };
    at.iter().map(one).collect::<Vec<_>>().join(", ")
}

/// An error under `Mode::Gate`, else a warning, labelled.
fn diagnostic(
    mode: Mode,
    (error, warning): (&'static str, &'static str),
    message: String,
    (file, span): (FileId, Span),
    label: &str,
) -> Diagnostic {
    match mode {
        Mode::Gate => Diagnostic::error(error, message, file, span),
        Mode::Warn => Diagnostic::warning(warning, message, file, span),
    }
    .with_label(label)
}

/// E0195 (W0020): a criterion measured and missed, by how much and where.
fn missed(
    c: Criterion,
    limit: &Limit,
    r: &CriterionResult,
    site: (FileId, Span),
    stated: bool,
    mode: Mode,
) -> Diagnostic {
    let v = r.measured.unwrap_or(f64::NAN);
    let where_ = if r.at.is_empty() {
        String::new()
    } else {
        format!("; {}", places(&r.at))
    };
    let as_fraction = if r.unit == "fraction" {
        " (as a fraction of the area simulated)"
    } else {
        ""
    };
    let message = format!(
        "the simulated part misses `{}`{as_fraction}: {}, over the {}limit of {} by {}{where_}",
        c.name(),
        shown(v, r.unit),
        if stated { "" } else { "default " },
        shown(r.limit, r.unit),
        shown(v - r.limit, r.unit),
    );
    let help = match &limit.rule {
        Some(rule) => format!(
            "the default limit is {rule}; state the limit the part needs in `accept: {{ {}: … }}`, or `accept: none`; `--accept=warn` writes the program anyway; the report's `acceptance` lists every criterion",
            c.name()
        ),
        None => "the report's `acceptance` lists every criterion; `--accept=warn` writes the program anyway".to_string(),
    };
    diagnostic(
        mode,
        (codes::ACCEPTANCE_MISSED, codes::ACCEPTANCE_MISSED_WARNING),
        message,
        site,
        if stated { "this limit" } else { "this job" },
    )
    .with_help(help)
}

/// E0196 (W0021): criteria the simulation cannot measure, and why; at
/// the first of them stated, or at the job.
fn cannot_measure(
    why: &str,
    names: &[&str],
    stated: Option<(FileId, Span)>,
    job: (FileId, Span),
    mode: Mode,
) -> Diagnostic {
    let listed: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    let listed = match listed.as_slice() {
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
        [] => String::new(),
    };
    diagnostic(
        mode,
        (codes::ACCEPTANCE_UNMEASURED, codes::ACCEPTANCE_UNMEASURED_WARNING),
        format!("{listed} cannot be checked: {why}"),
        stated.unwrap_or(job),
        if stated.is_some() { "this limit" } else { "this job" },
    )
    .with_help("say `accept: none` to build without the gate, or state only criteria the simulation measures; `--accept=warn` writes the program anyway")
}
