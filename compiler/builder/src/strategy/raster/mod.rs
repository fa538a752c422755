//! The `raster` strategy (seed 000, Lin's scraping): iso-plane raster on a
//! 3-axis mill. Lowering checks the job for its machine, its tool and its
//! feed, and against its surface by the planner's own pre-plan check (the
//! knife's clearance against the steepest slope along the cut); `build`
//! plans, writes and simulates it.

mod build;
pub(crate) mod errors;
mod estimate;
pub mod report;

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::chords::ChordPlacement;
use lensc_runtime::plan::optimise;
use lensc_runtime::plan::raster::{
    Axis, PlaneSpans, Raster, RasterTool, check_clearance, check_raster_planes,
};
use lensc_runtime::post::Dialect;

use crate::job::{Evaluate, JobHead, Parts, all_clear};
use lensc_lang::codes;
use lensc_lang::schema::strategies::RasterParams;
use lensc_lang::value::Stated;

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
    /// The planes lowering's scan found cutting, the rim's among them:
    /// what the estimate counts.
    pub planes: PlaneSpans,
}

impl crate::strategy::Strategy for RasterSpec {
    const NAMES: &'static [&'static str] = &["raster"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Mill;
    const WINDOWED: bool = true;
    const LENGTH_AXES: Option<u32> = Some(3);
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>> {
        lower(p, dialect, evaluate)
    }
    fn head(&self) -> &JobHead {
        &self.head
    }
    fn path_tolerance(&self) -> Option<f64> {
        Some(self.raster.chord_tolerance)
    }
    fn estimate(&self, evaluate: Evaluate) -> crate::job::Estimate {
        estimate::estimate(self, evaluate)
    }
    fn tiles(
        &self,
        window: &lensc_runtime::verify::window::Window,
    ) -> Option<Vec<lensc_runtime::verify::window::Tile>> {
        Some(lensc_runtime::verify::window::split(
            &window.cartesian(self.raster.along == Axis::X),
            None,
        ))
    }
    fn build(
        &self,
        cx: &crate::context::BuildContext,
    ) -> Result<crate::output::Built, Vec<Diagnostic>> {
        build::build(self, cx)
    }
}

pub(crate) fn lower(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<RasterSpec, Vec<Diagnostic>> {
    p.needs_kinds("raster", &["mill_3axis"], &["microshaper", "ball_end"])?;
    let st = RasterParams::read(p.strategy).map_err(|d| vec![d])?;
    let t = &p.tool_params;
    let mut raster = Raster {
        along: if st.along_y { Axis::Y } else { Axis::X },
        zigzag: st.zigzag,
        stepover: st.stepover,
        chord_tolerance: p
            .chord_tolerance(<RasterSpec as crate::strategy::Strategy>::LENGTH_AXES.unwrap_or(2)),
        max_step: st.max_step,
        lin_angle: st.lin_angle,
        retract: st.retract.unwrap_or(1.0),
        chords: ChordPlacement::OnPath,
    };
    // The chords take their share of the tolerance, the fitted lines and
    // arcs theirs (`plan::optimise`).
    raster.chords = crate::job::chords::placement(
        p,
        crate::job::chords::ChordPath {
            tolerance: Some(raster.chord_tolerance),
            sag: raster.chord_tolerance * optimise::CHORD_SHARE,
            fit: raster.chord_tolerance * optimise::FIT_SHARE,
            // Fitted lines and arcs: fewest through points on the path.
            long_chords: false,
            holds: p.holds(<RasterSpec as crate::strategy::Strategy>::LENGTH_AXES),
        },
    );
    let (tool, tool_words) = match p.tool.kind.name {
        "ball_end" => {
            let d = p.tool_needs(t.diameter, "diameter")?;
            (
                RasterTool::Ball { radius: d / 2.0 },
                format!(
                    "ball-end mill, diameter {} mm",
                    lensc_lang::lower::exact_in(d, "mm")
                ),
            )
        }
        _ => {
            let r = p.tool_needs(t.nose_radius, "nose_radius")?;
            (
                RasterTool::Knife { nose_radius: r },
                format!(
                    "microshaper knife, nose radius {} mm, its edge across the cut",
                    lensc_lang::lower::exact_in(r, "mm")
                ),
            )
        }
    };
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let feed = st.feed;
    let clearance = t.clearance;
    let mut errors: Vec<Diagnostic> = p.feed_error("cutting", feed).into_iter().collect();
    let spindle_speed = st.spindle_speed.map(|s| s.value);
    errors.extend(raster_spindle_error(p, &tool, st.spindle_speed));
    // The checks the planner makes first, on the planes it cuts (kept
    // for the estimate).
    let kernel = evaluate(&lowered.tape);
    let scanned = check_raster_planes(&raster, &tool, kernel.as_ref(), &lowered.domain).and_then(
        |(scan, planes)| {
            clearance.map_or(Ok(()), |c| check_clearance(c, scan.max_slope_along))?;
            Ok(planes)
        },
    );
    let planes = scanned.unwrap_or_else(|e| {
        errors.push(errors::error(e, p.site()));
        PlaneSpans::default()
    });
    all_clear(errors)?;
    Ok(RasterSpec {
        head: p.head(dialect, lowered),
        raster,
        tool,
        tool_words,
        clearance,
        feed,
        spindle_speed,
        planes,
    })
}

/// E0171: a rotating cutter (a ball-end mill) needs its spindle speed; a
/// knife cuts with the spindle held still and is given none.
fn raster_spindle_error(
    p: &Parts,
    tool: &RasterTool,
    speed: Option<Stated<f64>>,
) -> Option<Diagnostic> {
    match (tool, speed) {
        (RasterTool::Ball { .. }, None) => Some(
            p.error(
                codes::RASTER_SPINDLE,
                "a ball-end mill cuts turning: this raster states no `spindle_speed`, so its program would plunge a stationary cutter".into(),
            )
            .with_help("add `spindle_speed: …` (rpm) to the raster strategy"),
        ),
        (RasterTool::Knife { .. }, Some(f)) => Some(
                Diagnostic::error(
                    codes::RASTER_SPINDLE,
                    "a microshaper knife cuts with the spindle held still (oriented), not turning",
                    f.site.0,
                    f.site.1,
                )
                .with_label("a turning spindle would swing the knife through the part")
                .with_help("remove `spindle_speed`: the program orients and holds the spindle"),
        ),
        _ => None,
    }
}
