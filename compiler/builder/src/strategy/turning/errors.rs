//! The profile-turning planner's errors in the words a user reads.
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::diagnostics::{Coded, coded, rpm, um};
use lensc_runtime::plan::turning::{MAX_SEARCH_COUNT, PlanError};

/// A profile-turning planner error as its diagnostic at `site`.
pub(crate) fn error(e: PlanError, site: (FileId, Span)) -> Diagnostic {
    coded_error(e).at(site)
}

/// A length (mm) as written, in exponent form where `trim_num` would
/// round it to nothing (1e-12 mm).
fn small_mm(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-6 {
        format!("{v:e}")
    } else {
        trim_num(v)
    }
}

/// A count in words, "about" where it is a number.
fn about(n: f64) -> String {
    let words = crate::job::estimate::count(n);
    if n.is_finite() {
        format!("about {words}")
    } else {
        words
    }
}

/// An angle (rad) in degrees as written.
fn deg(a: f64) -> String {
    trim_num((a.to_degrees() * 1e3).round() / 1e3)
}

fn coded_error(e: PlanError) -> Coded {
    match e {
        PlanError::NoseTooLarge { nose_radius, min_radius, at_radius } => coded(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at r = {} mm): the tool would gouge",
                um(nose_radius),
                um(min_radius),
                trim_num(at_radius)
            ),
        )
        .help("use a tool whose nose radius is below the smallest concave radius of curvature"),
        PlanError::OutOfTravel { axis, value, min, max } => coded(
            codes::OUT_OF_TRAVEL,
            format!(
                "the path moves {axis} to {} mm, outside the machine's travel {} .. {} mm",
                trim_num(value),
                trim_num(min),
                trim_num(max)
            ),
        )
        .help("check the machine's travel, the aperture and the retract height"),
        PlanError::FeedTooHigh { feed, max } => coded(
            codes::FEED_TOO_HIGH,
            format!(
                "the cutting feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                trim_num(feed * 60.0),
                trim_num(max * 60.0)
            ),
        )
        .help("lower the feed or the spindle speed"),
        PlanError::SpindleTooFast { speed, max } => coded(
            codes::SPINDLE_TOO_FAST,
            format!(
                "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                rpm(speed),
                rpm(max)
            ),
        )
        .help(format!("lower `spindle_speed` to at most {} rpm (with `surface_speed`, cap it with `spindle_cap`)", rpm(max))),
        PlanError::EdgeNotCovering { needed, measured, at_radius } => coded(
            codes::EDGE_ANGLES,
            format!(
                "the cut meets the nose at {}° .. {}° from its axis (the far end at r = {} mm), but the tool's edge profile covers only {}° .. {}°: the path cannot be compensated beyond the measured edge",
                deg(needed.0),
                deg(needed.1),
                trim_num(at_radius),
                deg(measured.0),
                deg(measured.1)
            ),
        )
        .help("measure the edge over the angles the cut uses (the surface's slope at each radius is the angle of contact), or cut a smaller `from`"),
        PlanError::EdgeNotCompensated { corner_at } => coded(
            codes::EDGE_ANGLES,
            match corner_at {
                Some(r) => format!(
                    "the profile has a corner at r = {} mm: a measured edge is compensated only along a smooth profile, where one angle of the edge touches it",
                    trim_num(r)
                ),
                None => "a measured edge is compensated only with the exact tool location, not with Lei's `search`".to_string(),
            },
        )
        .help("leave the tool's `edge_profile` out for this job (the nose is then a circle), or cut with `search` left out"),
        PlanError::SearchTooFine {
            parameter,
            span,
            step,
            count,
        } => coded(
            codes::TOO_MANY_POINTS,
            match parameter {
                "search_step" => format!(
                    "the sequential search would descend {} steps of {} mm at each point ({} mm, from a nose radius over the profile's highest point to one under its lowest), more than the {} lensc takes",
                    about(count),
                    small_mm(step),
                    trim_num(span),
                    crate::job::estimate::count(MAX_SEARCH_COUNT as f64)
                ),
                _ => format!(
                    "the search would discretise the profile into {} points {} mm apart ({} mm), more than the {} lensc plans for one job",
                    about(count),
                    small_mm(step),
                    trim_num(span),
                    crate::job::estimate::count(MAX_SEARCH_COUNT as f64)
                ),
            },
        )
        .help(format!("make `{parameter}` coarser: the count scales with its inverse")),
        PlanError::Undefined { at_radius } => coded(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface or the tool path is undefined at r = {} mm",
                trim_num(at_radius)
            ),
        ),
    }
}
