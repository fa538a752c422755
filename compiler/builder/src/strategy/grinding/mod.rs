//! The `profile_grinding` strategy (seed 001, Kim et al.): a profile
//! ground with a spherical wheel on a 2-axis grinder. Lowering checks the
//! job for its machine, its tool and its feed, and the wheel against the
//! surface by the planner's own station scan; `build` plans, writes and
//! simulates it.

mod build;
pub(crate) mod errors;
mod estimate;
pub mod report;

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::grinding::{ProfileGrinding, check_profile_grinding};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::SectionAlongX;
use lensc_runtime::surface::analysis::Domain;

use crate::job::travel::{TravelAxis, part_beyond_travel};
use crate::job::{Evaluate, JobHead, Parts, all_clear};
use lensc_lang::schema::strategies::ProfileGrindingParams;

/// A `profile_grinding` job on a `grinder_2axis`, typed.
pub struct GrindingSpec {
    pub head: JobHead,
    pub grinding: ProfileGrinding,
    /// Height (mm) above the part's top for the rapid moves.
    pub retract: f64,
    /// The work spindle's speed (rad/s).
    pub spindle_speed: f64,
    /// The grinder's maximum feed (mm/s), for the approach through air.
    pub max_feed: f64,
}

impl crate::strategy::Strategy for GrindingSpec {
    const NAMES: &'static [&'static str] = &["profile_grinding"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Lathe;
    const WINDOWED: bool = false;
    const LENGTH_AXES: Option<u32> = None;
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>> {
        lower(p, dialect, evaluate)
    }
    fn head(&self) -> &JobHead {
        &self.head
    }
    fn path_tolerance(&self) -> Option<f64> {
        None
    }
    fn estimate(&self, _evaluate: Evaluate) -> crate::job::Estimate {
        estimate::estimate(self)
    }
    fn tiles(
        &self,
        _window: &lensc_runtime::verify::window::Window,
    ) -> Option<Vec<lensc_runtime::verify::window::Tile>> {
        None
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
) -> Result<GrindingSpec, Vec<Diagnostic>> {
    p.needs_kinds("profile grinding", &["grinder_2axis"], &["spherical_wheel"])?;
    let st = ProfileGrindingParams::read(p.strategy).map_err(|d| vec![d])?;
    let wheel_diameter = p.tool_needs(p.tool_params.diameter, "diameter")?;
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let edge = match lowered.domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => radius,
        Domain::Rect { x, .. } => x.1,
    };
    let feed = st.feed;
    let grinding = ProfileGrinding {
        wheel_diameter,
        interval: st.interval,
        feed,
        smoothness: st.smoothness,
        start: st.from.unwrap_or(0.0),
        end: st.to.unwrap_or(edge),
    };
    let mut errors: Vec<Diagnostic> = p.feed_error("grinding", feed).into_iter().collect();
    // The part against the X travel before its stations are scanned.
    let radii = (grinding.start, grinding.end);
    if let Some(e) = part_beyond_travel(p, TravelAxis::Radius, radii, wheel_diameter / 2.0) {
        errors.push(e);
        return Err(errors);
    }
    // The checks the planner makes first, on its own contact stations.
    let kernel = evaluate(&lowered.tape);
    if let Err(e) = check_profile_grinding(&grinding, &SectionAlongX(kernel.as_ref())) {
        errors.push(errors::error(e, p.site()));
    }
    all_clear(errors)?;
    Ok(GrindingSpec {
        head: p.head(dialect, lowered),
        grinding,
        retract: st.retract.unwrap_or(1.0),
        spindle_speed: st.spindle_speed,
        max_feed: p.machine_params.max_feed,
    })
}
