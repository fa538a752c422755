//! Lowering a `profile_turning` job: the runtime's `TurningJob`, checked
//! against its profile (the nose against the smallest concave radius, the
//! feed and spindle against the machine) before any path is planned.

mod build;
pub(crate) mod errors;
mod estimate;
pub mod report;

use lensc_grammar::Diagnostic;
use lensc_runtime::machine::Lathe;
use lensc_runtime::machine::tool::RoundNoseTool;
use lensc_runtime::plan::optimise;
use lensc_runtime::plan::turning::{
    Feed, ProfileTurning, Roughing, Stock, ToolLocation, TurningJob, check_profile_turning,
};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::{SectionAlongX, SurfaceInfo};

use crate::job::{Evaluate, JobHead, Parts};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::domain::{aperture_inner_radius, aperture_radius};
use lensc_lang::units::Dim;
use lensc_lang::value::{self, Field, Object, Value};

/// A profile-turning job, typed.
pub struct TurningSpec {
    pub head: JobHead,
    /// What the planner and the post-processor read.
    pub job: TurningJob,
}

impl crate::strategy::Strategy for TurningSpec {
    const NAMES: &'static [&'static str] = &["profile_turning"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Lathe;
    const WINDOWED: bool = false;
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>> {
        lower(p, dialect, evaluate)
    }
    fn head(&self) -> &JobHead {
        &self.head
    }
    fn path_tolerance(&self) -> Option<f64> {
        Some(self.job.strategy.chord_tolerance)
    }
    fn estimate(&self, evaluate: Evaluate) -> crate::job::Estimate {
        estimate::estimate(self, evaluate)
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
) -> Result<TurningSpec, Vec<Diagnostic>> {
    let job = turning_job(p, dialect.clone())?;
    let lowered = p.lowered().map_err(|d| vec![d])?;
    // The checks the planner would make first, on the section it follows.
    let kernel = evaluate(&lowered.tape);
    if let Err(errs) = check_profile_turning(&job, &SectionAlongX(kernel.as_ref())) {
        return Err(errs
            .into_iter()
            .map(|e| errors::error(e, p.site()))
            .collect());
    }
    Ok(TurningSpec {
        head: p.head(dialect, lowered),
        job,
    })
}

/// The runtime's description of the job, or why it cannot be turned.
fn turning_job(p: &Parts, dialect: Dialect) -> Result<TurningJob, Vec<Diagnostic>> {
    let (surface, tool, machine, strategy) = (p.surface, p.tool, p.machine, p.strategy);
    let mut errors = Vec::new();
    let at = |name: &str| {
        let f = value::field(&p.job.fields, name).expect("checked job part");
        (f.file, f.span)
    };
    let unsupported = |what: &str, name: &str, detail: String| {
        let (file, span) = at(name);
        Diagnostic::error(codes::UNSUPPORTED_COMBINATION, what.to_string(), file, span)
            .with_label(detail)
    };
    if machine.kind.name != "lathe" {
        errors.push(unsupported(
            "profile turning needs a lathe",
            "machine",
            format!("this is a `{}`", machine.kind.name),
        ));
    }
    if tool.kind.name != "round_nose" {
        errors.push(unsupported(
            "profile turning needs a round-nose tool",
            "tool",
            format!("this is a `{}`", tool.kind.name),
        ));
    }
    let surf = surface_info(surface);
    if surf.is_none() {
        errors.push(
            unsupported(
                "profile turning needs a rotationally symmetric surface with a circular aperture",
                "surface",
                format!("this is a `{}`", surface.kind.name),
            )
            .with_help("sphere, conic, asphere, qbfs and qcon surfaces with a circle or annulus aperture can be turned, and any profile made a surface of revolution with `revolve`"),
        );
    }
    let Some(surf) = surf.filter(|_| errors.is_empty()) else {
        return Err(errors);
    };
    let f = &strategy.fields;
    let from = value::num(f, "from");
    if let Some(start) = from
        && start > surf.aperture_radius
    {
        let fld = value::field(f, "from").expect("from");
        return Err(vec![
            Diagnostic::error(
                codes::OUTSIDE_APERTURE,
                format!(
                    "the cut starts at r = {} mm, outside the aperture (radius {} mm)",
                    trim_num(start),
                    trim_num(surf.aperture_radius)
                ),
                fld.file,
                fld.span,
            )
            .with_label("beyond the aperture")
            .with_help("start at or inside the aperture edge"),
        ]);
    }
    Ok(TurningJob {
        name: p.job.name.name.clone(),
        surface_name: name_of(p, "surface", surface),
        tool_name: name_of(p, "tool", tool),
        machine_name: name_of(p, "machine", machine),
        strategy_name: name_of(p, "strategy", strategy),
        strategy: profile_turning(p, f, surface, p.max_spindle_speed()),
        surface: surf,
        tool: round_nose(&tool.fields),
        machine: lathe(&machine.fields, dialect),
    })
}

fn name_of(p: &Parts, part: &str, o: &Object) -> String {
    p.job
        .part_names
        .get(part)
        .cloned()
        .unwrap_or_else(|| o.kind.name.to_string())
}

/// A feed field (per revolution or per minute), if given.
fn feed_of(f: &[Field], name: &str) -> Option<Feed> {
    match value::field(f, name).map(|x| &x.value) {
        Some(Value::Num(v, d)) if *d == Dim::FEED_PER_REV => Some(Feed::PerRevolution(*v)),
        Some(Value::Num(v, _)) => Some(Feed::PerTime(*v)),
        _ => None,
    }
}

fn profile_turning(p: &Parts, f: &[Field], surface: &Object, max_spindle: f64) -> ProfileTurning {
    let feed = feed_of(f, "feed").expect("feed is required and checked");
    let tolerance = value::num(f, "chord_tolerance").unwrap_or(crate::job::DEFAULT_PATH_TOLERANCE);
    ProfileTurning {
        // The chords take their share of the tolerance, the fitted lines
        // and arcs theirs (`plan::optimise`).
        chords: crate::job::chords::placement(
            p,
            crate::job::chords::ChordPath {
                tolerance: Some(tolerance),
                sag: tolerance * optimise::CHORD_SHARE,
                fit: tolerance * optimise::FIT_SHARE,
                // Fitted lines and arcs: fewest through points on the path.
                long_chords: false,
            },
        ),
        feed,
        // Under constant surface speed the spindle speed is its cap.
        spindle_speed: value::num(f, "spindle_speed")
            .or_else(|| value::num(f, "spindle_cap"))
            .unwrap_or(max_spindle),
        surface_speed: value::num(f, "surface_speed"),
        chord_tolerance: value::num(f, "chord_tolerance")
            .unwrap_or(crate::job::DEFAULT_PATH_TOLERANCE),
        start_radius: value::num(f, "from"),
        // An annular aperture's cut ends at its inner edge.
        end_radius: value::num(f, "to").unwrap_or_else(|| {
            value::object(&surface.fields, "aperture").map_or(0.0, |a| aperture_inner_radius(a))
        }),
        retract: value::num(f, "retract").unwrap_or(1.0),
        location: tool_location(f),
        roughing: roughing(f),
    }
}

fn lathe(m: &[Field], dialect: Dialect) -> Lathe {
    let travel = value::block(m, "travel").expect("required");
    let spindle = value::block(m, "spindle").expect("required");
    Lathe {
        dialect,
        resolution: value::num(m, "resolution").expect("required"),
        travel_x: value::range(travel, "x").expect("required"),
        travel_z: value::range(travel, "z").expect("required"),
        max_feed: value::num(m, "max_feed").expect("required"),
        max_spindle_speed: value::num(spindle, "max_speed").expect("required"),
    }
}

fn round_nose(t: &[Field]) -> RoundNoseTool {
    RoundNoseTool {
        nose_radius: value::num(t, "nose_radius").expect("required"),
        clearance_angle: value::num(t, "clearance").expect("required"),
        centre_height: value::num(t, "centre_height").unwrap_or(0.0),
        rake_angle: value::num(t, "rake").unwrap_or(0.0),
    }
}

/// Roughing passes, when the strategy states the stock and a depth of cut.
fn roughing(f: &[Field]) -> Option<Roughing> {
    let stock = match (value::num(f, "stock_top"), value::num(f, "stock_allowance")) {
        (Some(top), _) => Stock::Flat { top },
        (None, Some(allowance)) => Stock::Offset { allowance },
        (None, None) => return None,
    };
    Some(Roughing {
        stock,
        depth_of_cut: value::num(f, "depth_of_cut")?,
        finish_allowance: value::num(f, "finish_allowance").unwrap_or(0.0),
        // The checker refuses a stock without it (E0170).
        feed: feed_of(f, "rough_feed")?,
        spindle_speed: value::num(f, "rough_spindle_speed"),
    })
}

/// The `search` of a profile-turning strategy: exact unless the user asks
/// for one of Lei et al.'s reference searches.
fn tool_location(f: &[Field]) -> ToolLocation {
    let spacing = value::num(f, "search_spacing").unwrap_or(1e-3);
    match value::word(f, "search") {
        Some("sequential") => ToolLocation::Sequential {
            spacing,
            step: value::num(f, "search_step").unwrap_or(1e-5),
        },
        Some("binary") => ToolLocation::Binary {
            spacing,
            tolerance: value::num(f, "search_step").unwrap_or(1e-6),
        },
        _ => ToolLocation::Exact,
    }
}

/// What the program header says about a surface of revolution that can be
/// turned (sphere, conic, asphere, Q-bfs, Q-con with a circular or annular
/// aperture), or `None` if it is not one.
fn surface_info(o: &Object) -> Option<SurfaceInfo> {
    if o.kind.name == "revolve" {
        let ap = value::object(&o.fields, "aperture")?;
        let aperture_radius = aperture_radius(ap)?;
        return Some(SurfaceInfo {
            description: format!(
                "{}, aperture radius {} mm; +Z out of the material",
                lensc_lang::lower::describe(o),
                lensc_lang::lower::exact_in(aperture_radius, "mm")
            ),
            aperture_radius,
        });
    }
    if !matches!(
        o.kind.name,
        "sphere" | "conic" | "asphere" | "qbfs" | "qcon"
    ) {
        return None;
    }
    let ap = value::object(&o.fields, "aperture")?;
    let aperture_radius = aperture_radius(ap)?;
    let side = lensc_lang::lower::surface::Side::of(&o.fields);
    let radius = value::num(&o.fields, "radius")?;
    let convex = if side.signed {
        radius > 0.0
    } else {
        side.sigma < 0.0
    };
    let mut words = vec![o.kind.name.to_string()];
    for fl in &o.fields {
        match (&fl.value, fl.name.as_str()) {
            (_, "sense" | "convention" | "aperture") => {}
            (Value::Num(v, d), name) => {
                words.push(format!("{name} {}", lensc_lang::lower::stated(*v, *d)));
            }
            _ => {}
        }
    }
    let inner = aperture_inner_radius(ap);
    let aperture = if inner > 0.0 {
        format!(
            "annular aperture {} .. {} mm",
            lensc_lang::lower::exact_in(inner, "mm"),
            lensc_lang::lower::exact_in(aperture_radius, "mm")
        )
    } else {
        format!(
            "aperture radius {} mm",
            lensc_lang::lower::exact_in(aperture_radius, "mm")
        )
    };
    let side_words = if side.signed {
        ", radius signed as in lens design"
    } else {
        ""
    };
    Some(SurfaceInfo {
        description: format!(
            "{}, {aperture}; {}: material on the -Z side{side_words}",
            words.join(", "),
            if convex { "convex" } else { "concave" }
        ),
        aperture_radius,
    })
}
