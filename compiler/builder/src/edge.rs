//! A round nose's `edge_profile`: the measured edge read as a job's files
//! are read (relative to the job's file, beneath the project root, a
//! regular file of at most `sandbox::MAX_FILE_BYTES`), parsed
//! (`lensc_runtime::machine::edge`), checked against the nose (its samples
//! within the nose's arc, no deviation at or beyond
//! `MAX_DEVIATION_SHARE` of the radius), and named by its MD5 for the
//! program header and the report. Every refusal is a coded diagnostic at
//! the tool's `edge_profile`, naming the file.

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::sandbox;
use lensc_lang::value::Stated;
use lensc_runtime::machine::edge::{EdgeError, EdgeProfile};
use lensc_runtime::machine::tool::MeasuredEdge;
use schemars::JsonSchema;
use serde::Serialize;

use crate::job::Parts;

/// The largest deviation from the nose circle, as a share of its radius,
/// an edge profile may state: beyond it the edge is no round nose (a
/// chip, a file in the wrong unit), and its offset no longer the circle's
/// plus a small correction.
pub const MAX_DEVIATION_SHARE: f64 = 0.01;

/// The edge profile a job's tool was compensated for, in the report.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct EdgeReport {
    /// The file, as the tool names it.
    pub file: String,
    /// MD5 of the file's bytes, lowercase hex: which measurement this is.
    pub md5: String,
    /// Samples, and the angles (deg) they cover.
    pub samples: usize,
    pub from_deg: f64,
    pub to_deg: f64,
    /// The largest |deviation| from the nose circle (nm) and its angle (deg).
    pub largest_deviation_nm: f64,
    pub largest_at_deg: f64,
}

/// The tool's measured edge, if it names one, with its report; or the
/// coded refusal.
pub(crate) fn measured_edge(p: &Parts) -> Result<Option<(MeasuredEdge, EdgeReport)>, Diagnostic> {
    let Some(named) = &p.tool_params.edge_profile else {
        return Ok(None);
    };
    let radius = p.tool_params.nose_radius.unwrap_or(f64::NAN);
    let file = named.value.as_str();
    let at = |code: &'static str, message: String, help: &str| {
        Diagnostic::error(code, message, named.site.0, named.site.1)
            .with_label("the edge profile this tool names")
            .with_help(help.to_string())
    };
    let bytes = read(p, named)?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        at(
            codes::EDGE_UNREADABLE,
            format!("{file}: not text (byte {} is not UTF-8)", e.valid_up_to()),
            FORMAT_HELP,
        )
    })?;
    let profile = lensc_runtime::machine::edge::parse(text)
        .and_then(|s| EdgeProfile::from_samples(&s))
        .map_err(|e| {
            let help = match e {
                EdgeError::NotIncreasing { .. } => {
                    "sort the samples by angle, each angle once (the tool's axis is 0°, + towards +X)"
                }
                _ => FORMAT_HELP,
            };
            at(codes::EDGE_UNREADABLE, format!("{file}: {e}"), help)
        })?;
    // The nose's arc: ± half its included angle about the tool's axis,
    // ±90° (a half circle) when the tool states none.
    let half = p
        .tool_params
        .included_angle
        .map_or(std::f64::consts::FRAC_PI_2, |a| 0.5 * a);
    let (lo, hi) = profile.range();
    if lo < -half - 1e-12 || hi > half + 1e-12 {
        return Err(at(
            codes::EDGE_ANGLES,
            format!(
                "{file}: the samples run from {}° to {}°, beyond the nose's arc of ±{}° about its axis",
                deg(lo),
                deg(hi),
                deg(half)
            ),
            "angles are measured from the tool's axis (0° at the nose's lowest point, + towards +X); the nose's arc is ± half the tool's `included_angle` (±90° when it states none)",
        ));
    }
    let (largest, largest_at) = profile.largest();
    if largest >= MAX_DEVIATION_SHARE * radius {
        return Err(at(
            codes::EDGE_DEVIATION,
            format!(
                "{file}: the edge departs {} um from the nose circle at {}°, {}% of the {} mm nose radius: at most {}% is a round nose's waviness",
                trim_num((largest * 1e3 * 1e4).round() / 1e4),
                deg(largest_at),
                trim_num((largest / radius * 1e4).round() / 1e2),
                trim_num(radius),
                trim_num(MAX_DEVIATION_SHARE * 100.0)
            ),
            "the deviations are in micrometres (a file in nanometres reads 1000 times too large); an edge chipped this much needs relapping, not compensation",
        ));
    }
    let md5 = lensc_measure::md5_hex(&bytes);
    let report = EdgeReport {
        file: file.to_owned(),
        md5: md5.clone(),
        samples: profile.len(),
        from_deg: lo.to_degrees(),
        to_deg: hi.to_degrees(),
        largest_deviation_nm: largest * 1e6,
        largest_at_deg: largest_at.to_degrees(),
    };
    Ok(Some((
        MeasuredEdge {
            profile,
            source: format!("{file} md5 {md5}"),
        },
        report,
    )))
}

/// E0375 for a job whose strategy does not compensate a measured edge
/// but whose tool names one: refused rather than cut as if the edge were
/// a circle.
pub(crate) fn not_compensated(p: &Parts, strategy: &str) -> Option<Diagnostic> {
    let named = p.tool_params.edge_profile.as_ref()?;
    Some(
        Diagnostic::error(
            codes::EDGE_ANGLES,
            format!("`{strategy}` does not compensate a measured edge, and this tool names one"),
            named.site.0,
            named.site.1,
        )
        .with_label("the edge profile this tool names")
        .with_help(
            "`profile_turning`, `spiral_turning`, `fts_spiral` and `roller_helix` place the nose by the edge's deviation at the angle of contact; leave `edge_profile` out of a tool for other strategies (the nose is then taken as a circle)",
        ),
    )
}

/// Radii and spindle angles at which a spiral's angles of contact are
/// scanned (`uncovered_spiral`).
const SPIRAL_SCAN: (usize, usize) = (256, 360);

/// E0375 for a spiral whose angles of contact the measured edge does not
/// cover. The edge lies in the plane of the spindle axis and the ray the
/// tool is over (`lensc_runtime::plan::spiral`), so it touches the
/// trajectory at atan of its slope along the ray, outwards: scanned on a
/// polar grid over `radii` (the spiral's end and start, mm) within the
/// surface's `domain`.
pub(crate) fn uncovered_spiral(
    p: &Parts,
    edge: &EdgeProfile,
    trajectory: &dyn lensc_runtime::surface::ir::SurfaceFn,
    domain: &lensc_runtime::surface::analysis::Domain,
    radii: (f64, f64),
) -> Option<Diagnostic> {
    let named = p.tool_params.edge_profile.as_ref()?;
    let (n_r, n_c) = SPIRAL_SCAN;
    let (r0, r1) = (radii.0.max(0.0), radii.1);
    let contacts = (0..=n_r).flat_map(|i| {
        let r = r0 + (r1 - r0) * i as f64 / n_r as f64;
        (0..n_c).filter_map(move |k| {
            let c = std::f64::consts::TAU * k as f64 / n_c as f64;
            let (x, y) = (r * c.cos(), r * c.sin());
            if !domain.contains(x, y) {
                return None;
            }
            let o = trajectory.eval(x, y);
            Some(((o[1] * c.cos() + o[2] * c.sin()).atan(), r, c))
        })
    });
    let (lo, hi) = extremes(contacts);
    let (m0, m1) = edge.range();
    let far = beyond(edge, lo, hi)?;
    Some(
        Diagnostic::error(
            codes::EDGE_ANGLES,
            format!(
                "the spiral meets the nose at {}° .. {}° from its axis (the far end at r = {} mm, C = {}°), but the tool's edge profile covers only {}° .. {}°: the path cannot be compensated beyond the measured edge",
                deg(lo.0),
                deg(hi.0),
                trim_num((far.1 * 1e4).round() / 1e4),
                trim_num((far.2.to_degrees() * 1e2).round() / 1e2),
                deg(m0),
                deg(m1)
            ),
            named.site.0,
            named.site.1,
        )
        .with_label("the edge profile this tool names")
        .with_help("measure the edge over the angles the cut uses (the surface's slope along the ray from the spindle axis is the angle of contact), or cut a smaller `from`"),
    )
}

/// The least and the greatest angle of contact among `contacts`, each
/// (angle rad, and where: two coordinates); angles not finite skipped.
fn extremes(contacts: impl Iterator<Item = (f64, f64, f64)>) -> ((f64, f64, f64), (f64, f64, f64)) {
    let (mut lo, mut hi) = ((f64::INFINITY, 0.0, 0.0), (f64::NEG_INFINITY, 0.0, 0.0));
    for a in contacts.filter(|a| a.0.is_finite()) {
        if a.0 < lo.0 {
            lo = a;
        }
        if a.0 > hi.0 {
            hi = a;
        }
    }
    (lo, hi)
}

/// The extreme of `lo`, `hi` that lies beyond the angles `edge` covers,
/// if either does.
fn beyond(edge: &EdgeProfile, lo: (f64, f64, f64), hi: (f64, f64, f64)) -> Option<(f64, f64, f64)> {
    let (m0, m1) = edge.range();
    if lo.0 < m0 {
        Some(lo)
    } else if hi.0 > m1 {
        Some(hi)
    } else {
        None
    }
}

/// Axial positions and angles around the roller at which a roller
/// helix's angles of contact are scanned (`uncovered_roller`).
const ROLLER_SCAN: (usize, usize) = (256, 360);

/// E0375 for a roller helix whose angles of contact the measured edge
/// does not cover. The edge lies in the cutting plane, through the roller
/// axis (`lensc_runtime::plan::roller`, "Measured edge"), so it touches
/// the design at atan of its axial slope ∂z/∂x, + towards +Z: scanned on
/// a grid over design x in `x` (where the contacts lie: the helix's axial
/// range widened by what the nose reaches) and design y in `y` (the
/// design's extent around the roller).
pub(crate) fn uncovered_roller(
    p: &Parts,
    edge: &EdgeProfile,
    design: &dyn lensc_runtime::surface::ir::SurfaceFn,
    x: (f64, f64),
    y: (f64, f64),
) -> Option<Diagnostic> {
    let named = p.tool_params.edge_profile.as_ref()?;
    let (n_x, n_y) = ROLLER_SCAN;
    let at = |(a, b): (f64, f64), i: usize, n: usize| a + (b - a) * i as f64 / n as f64;
    let contacts = (0..=n_x).flat_map(|i| {
        let u = at(x, i, n_x);
        (0..=n_y).map(move |j| {
            let v = at(y, j, n_y);
            (design.eval(u, v)[1].atan(), u, v)
        })
    });
    let (lo, hi) = extremes(contacts);
    let far = beyond(edge, lo, hi)?;
    let (m0, m1) = edge.range();
    Some(
        Diagnostic::error(
            codes::EDGE_ANGLES,
            format!(
                "the helix meets the nose at {}° .. {}° from its axis (the far end at design x = {} mm, y = {} mm), but the tool's edge profile covers only {}° .. {}°: the path cannot be compensated beyond the measured edge",
                deg(lo.0),
                deg(hi.0),
                trim_num((far.1 * 1e4).round() / 1e4),
                trim_num((far.2 * 1e4).round() / 1e4),
                deg(m0),
                deg(m1)
            ),
            named.site.0,
            named.site.1,
        )
        .with_label("the edge profile this tool names")
        .with_help("measure the edge over the angles the cut uses (the design's slope along the roller axis is the angle of contact, + towards +Z), or cut a shorter `z` range"),
    )
}

const FORMAT_HELP: &str = "an edge profile is text, one sample a line: the angle in degrees, then the deviation from the nose circle in micrometres (`-30.0, 0.012`); `#` starts a comment; a first line of column names is skipped";

/// An angle (rad) in degrees, to a thousandth.
fn deg(a: f64) -> String {
    trim_num((a.to_degrees() * 1e3).round() / 1e3)
}

/// The edge profile's bytes (`job_file::read`: beneath the root, at most
/// `sandbox::MAX_FILE_BYTES`).
fn read(p: &Parts, m: &Stated<String>) -> Result<Vec<u8>, Diagnostic> {
    crate::job_file::read(
        p.job,
        m,
        "the edge profile",
        sandbox::MAX_FILE_BYTES,
        "files of at most 16 MiB are read",
    )
}
