//! Lowering the jobs of 2- and 3-axis machines beyond the lathe: iso-plane
//! raster on a mill and profile grinding with a spherical wheel, each
//! checked for its machine, its tool and its feed, and against its surface
//! by the planner's own pre-plan check (the tool against the smallest
//! concave radius, the knife's clearance against the steepest slope).

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::chords::ChordPlacement;
use lensc_runtime::plan::grinding::{ProfileGrinding, check_profile_grinding};
use lensc_runtime::plan::optimise;
use lensc_runtime::plan::raster::{Axis, Raster, RasterTool, check_clearance, check_raster};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::SectionAlongX;
use lensc_runtime::surface::analysis::Domain;

use super::{Evaluate, JobHead, Parts, all_clear};
use crate::check::trim_num;
use crate::codes;
use crate::lower::diagnostics::RuntimeError;
use crate::value;

/// A `raster` job on a `mill_3axis`, typed.
pub struct RasterSpec {
    pub head: JobHead,
    pub raster: Raster,
    pub tool: RasterTool,
    /// The tool in the header's words.
    pub tool_words: String,
    /// The knife's clearance angle (rad), if it has one: the planner's
    /// steepest slope along the cut must stay below it.
    pub clearance: Option<f64>,
    /// The cutting feed (mm/s).
    pub feed: f64,
    /// The cutter's spindle speed (rad/s); none for a knife, which cuts
    /// with the spindle held still.
    pub spindle_speed: Option<f64>,
}

/// A `profile_grinding` job on a `grinder_2axis`, typed.
pub struct GrindingSpec {
    pub head: JobHead,
    pub grinding: ProfileGrinding,
    /// Height (mm) above the part's top for the rapid moves.
    pub retract: f64,
    /// The work spindle's speed (rad/s).
    pub spindle_speed: f64,
}

pub(super) fn lower_raster(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<RasterSpec, Vec<Diagnostic>> {
    p.needs_kinds("raster", &["mill_3axis"], &["microshaper", "ball_end"])?;
    let (st, t) = (&p.strategy.fields, &p.tool.fields);
    let mut raster = Raster {
        along: if value::word(st, "along") == Some("y") {
            Axis::Y
        } else {
            Axis::X
        },
        zigzag: value::word(st, "direction") == Some("zigzag"),
        stepover: value::num(st, "stepover").expect("required"),
        chord_tolerance: value::num(st, "chord_tolerance").unwrap_or(super::DEFAULT_PATH_TOLERANCE),
        max_step: value::num(st, "max_step"),
        lin_angle: value::num(st, "lin_angle"),
        retract: value::num(st, "retract").unwrap_or(1.0),
        chords: ChordPlacement::OnPath,
    };
    // The chords take their share of the tolerance, the fitted lines and
    // arcs theirs (`plan::optimise`).
    raster.chords = super::chords::placement(
        p,
        super::chords::ChordPath {
            tolerance: Some(raster.chord_tolerance),
            sag: raster.chord_tolerance * optimise::CHORD_SHARE,
            fit: raster.chord_tolerance * optimise::FIT_SHARE,
            // Fitted lines and arcs: fewest through points on the path.
            long_chords: false,
        },
    );
    let (tool, tool_words) = match p.tool.kind.name {
        "ball_end" => {
            let d = value::num(t, "diameter").expect("required");
            (
                RasterTool::Ball { radius: d / 2.0 },
                format!(
                    "ball-end mill, diameter {} mm, referenced at the ball centre",
                    crate::lower::exact_in(d, "mm")
                ),
            )
        }
        _ => {
            let r = value::num(t, "nose_radius").expect("required");
            (
                RasterTool::Knife { nose_radius: r },
                format!(
                    "microshaper knife, nose radius {} mm, its edge across the cut, referenced at the nose centre",
                    crate::lower::exact_in(r, "mm")
                ),
            )
        }
    };
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let feed = value::num(st, "feed").expect("required");
    let clearance = value::num(t, "clearance");
    let mut errors: Vec<Diagnostic> = feed_error(p, "cutting", feed).into_iter().collect();
    let spindle_speed = value::num(st, "spindle_speed");
    errors.extend(raster_spindle_error(p, &tool, spindle_speed));
    // The checks the planner makes first, on the planes it cuts.
    let kernel = evaluate(&lowered.tape);
    let scanned = check_raster(&raster, &tool, kernel.as_ref(), &lowered.domain)
        .and_then(|scan| clearance.map_or(Ok(()), |c| check_clearance(c, scan.max_slope_along)));
    if let Err(e) = scanned {
        errors.push(RuntimeError::Raster(e).at(p.site()));
    }
    all_clear(errors)?;
    Ok(RasterSpec {
        head: p.head(dialect, lowered),
        raster,
        tool,
        tool_words,
        clearance,
        feed,
        spindle_speed,
    })
}

/// E0171: a rotating cutter (a ball-end mill) needs its spindle speed; a
/// knife cuts with the spindle held still and is given none.
fn raster_spindle_error(p: &Parts, tool: &RasterTool, speed: Option<f64>) -> Option<Diagnostic> {
    match (tool, speed) {
        (RasterTool::Ball { .. }, None) => Some(
            p.error(
                codes::RASTER_SPINDLE,
                "a ball-end mill cuts turning: this raster states no `spindle_speed`, so its program would plunge a stationary cutter".into(),
            )
            .with_help("add `spindle_speed: …` (rpm) to the raster strategy"),
        ),
        (RasterTool::Knife { .. }, Some(_)) => {
            let f = value::field(&p.strategy.fields, "spindle_speed").expect("given");
            Some(
                Diagnostic::error(
                    codes::RASTER_SPINDLE,
                    "a microshaper knife cuts with the spindle held still (oriented), not turning",
                    f.file,
                    f.span,
                )
                .with_label("a turning spindle would swing the knife through the part")
                .with_help("remove `spindle_speed`: the program orients and holds the spindle"),
            )
        }
        _ => None,
    }
}

pub(super) fn lower_grinding(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<GrindingSpec, Vec<Diagnostic>> {
    p.needs_kinds("profile grinding", &["grinder_2axis"], &["spherical_wheel"])?;
    let (st, t) = (&p.strategy.fields, &p.tool.fields);
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let edge = match lowered.domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => radius,
        Domain::Rect { x, .. } => x.1,
    };
    let feed = value::num(st, "feed").expect("required");
    let grinding = ProfileGrinding {
        wheel_diameter: value::num(t, "diameter").expect("required"),
        interval: value::num(st, "interval").expect("required"),
        feed,
        smoothness: value::num(st, "smoothness").expect("required"),
        start: value::num(st, "from").unwrap_or(0.0),
        end: value::num(st, "to").unwrap_or(edge),
    };
    let mut errors: Vec<Diagnostic> = feed_error(p, "grinding", feed).into_iter().collect();
    // The checks the planner makes first, on its own contact stations.
    let kernel = evaluate(&lowered.tape);
    if let Err(e) = check_profile_grinding(&grinding, &SectionAlongX(kernel.as_ref())) {
        errors.push(RuntimeError::Grinding(e).at(p.site()));
    }
    all_clear(errors)?;
    Ok(GrindingSpec {
        head: p.head(dialect, lowered),
        grinding,
        retract: value::num(st, "retract").unwrap_or(1.0),
        spindle_speed: value::num(st, "spindle_speed").expect("required"),
    })
}

/// E0142 when the `what` feed (mm/s) is above the machine's maximum.
fn feed_error(p: &Parts, what: &str, feed: f64) -> Option<Diagnostic> {
    let max_feed = value::num(&p.machine.fields, "max_feed").expect("required");
    (feed > max_feed).then(|| {
        p.error(
            codes::FEED_TOO_HIGH,
            format!(
                "the {what} feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                trim_num(feed * 60.0),
                trim_num(max_feed * 60.0)
            ),
        )
    })
}
