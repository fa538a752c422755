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

use crate::job::travel::{TravelAxis, part_beyond_travel};
use crate::job::{Evaluate, JobHead, Parts};
use lensc_grammar::{FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::schema::Surface;
use lensc_lang::schema::machines::MachineParams;
use lensc_lang::schema::strategies::{ProfileTurningParams, StatedFeed};
use lensc_lang::value::{Object, Value};

/// A profile-turning job, typed.
pub struct TurningSpec {
    pub head: JobHead,
    /// What the planner and the post-processor read.
    pub job: TurningJob,
    /// The tool's measured edge, when it names one, for the report.
    pub edge: Option<crate::edge::EdgeReport>,
}

impl crate::strategy::Strategy for TurningSpec {
    const NAMES: &'static [&'static str] = &["profile_turning"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Lathe;
    const WINDOWED: bool = false;
    const LENGTH_AXES: Option<u32> = Some(2);
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
    let mut job = turning_job(p, dialect.clone())?;
    let edge = match crate::edge::measured_edge(p).map_err(|d| vec![d])? {
        Some((measured, report)) => {
            job.tool.edge = Some(measured);
            Some(report)
        }
        None => None,
    };
    // The part against the X travel before its profile is scanned: the
    // cut runs in from `from` (the aperture's edge) to `to`.
    let from = job
        .strategy
        .start_radius
        .unwrap_or(job.surface.aperture_radius);
    let radii = (
        from.min(job.strategy.end_radius),
        from.max(job.strategy.end_radius),
    );
    if let Some(e) = part_beyond_travel(p, TravelAxis::Radius, radii, job.tool.nose_radius) {
        return Err(vec![e]);
    }
    let lowered = p.lowered().map_err(|d| vec![d])?;
    // The checks the planner would make first, on the section it follows.
    let kernel = evaluate(&lowered.tape);
    if let Err(errs) = check_profile_turning(&job, &SectionAlongX(kernel.as_ref())) {
        // The edge's errors at the tool's `edge_profile`, the rest at the job.
        let edge_site = p.tool_params.edge_profile.as_ref().map(|e| e.site);
        return Err(errs
            .into_iter()
            .map(|e| {
                let site = match (&e, edge_site) {
                    (
                        lensc_runtime::plan::turning::PlanError::EdgeNotCovering { .. }
                        | lensc_runtime::plan::turning::PlanError::EdgeNotCompensated { .. },
                        Some(s),
                    ) => s,
                    _ => p.site(),
                };
                errors::error(e, site)
            })
            .collect());
    }
    if let Some(e) = nose_out_of_reach(p, &job, &SectionAlongX(kernel.as_ref())) {
        return Err(vec![e]);
    }
    let head = p.head(dialect, lowered);
    if let Some(c) = &head.surface.compensation {
        // The runtime writes the header: the surface's line says it.
        job.surface.description = format!(
            "{}; {}",
            job.surface.description,
            crate::compensate::header_words(c)
        );
    }
    Ok(TurningSpec { head, job, edge })
}

/// The runtime's description of the job, or why it cannot be turned.
fn turning_job(p: &Parts, dialect: Dialect) -> Result<TurningJob, Vec<Diagnostic>> {
    let (surface, tool, machine, strategy) = (p.surface, p.tool, p.machine, p.strategy);
    let mut errors = Vec::new();
    let sites = p.params.part_sites;
    let unsupported = |what: &str, site: Option<(FileId, Span)>, detail: String| {
        let (file, span) = site.unwrap_or(p.site());
        Diagnostic::error(codes::UNSUPPORTED_COMBINATION, what.to_string(), file, span)
            .with_label(detail)
    };
    if machine.kind.name != "lathe" {
        errors.push(unsupported(
            "profile turning needs a lathe",
            sites.machine,
            format!("this is a `{}`", machine.kind.name),
        ));
    }
    if tool.kind.name != "round_nose" {
        errors.push(unsupported(
            "profile turning needs a round-nose tool",
            sites.tool,
            format!("this is a `{}`", tool.kind.name),
        ));
    }
    let surf = surface_info(surface, &p.surface_params);
    if surf.is_none() {
        errors.push(
            unsupported(
                "profile turning needs a rotationally symmetric surface with a circular aperture",
                sites.surface,
                format!("this is a `{}`", surface.kind.name),
            )
            .with_help(not_turnable_help(surface.kind.name)),
        );
    }
    let Some(surf) = surf.filter(|_| errors.is_empty()) else {
        return Err(errors);
    };
    let f = ProfileTurningParams::read(strategy).map_err(|d| vec![d])?;
    if let Some(from) = f.from
        && from.value > surf.aperture_radius
    {
        let (start, fld) = (from.value, from.site);
        return Err(vec![
            Diagnostic::error(
                codes::OUTSIDE_APERTURE,
                format!(
                    "the cut starts at r = {} mm, outside the aperture (radius {} mm)",
                    trim_num(start),
                    trim_num(surf.aperture_radius)
                ),
                fld.0,
                fld.1,
            )
            .with_label("beyond the aperture")
            .with_help("start at or inside the aperture edge"),
        ]);
    }
    let feed = f.feed.map(feed_of).ok_or_else(|| {
        vec![p.error(
            codes::MISSING_PARAMETER,
            "this profile turning states no `feed`".into(),
        )]
    })?;
    Ok(TurningJob {
        name: p.job.name.name.clone(),
        surface_name: name_of(p, "surface", surface),
        tool_name: name_of(p, "tool", tool),
        machine_name: name_of(p, "machine", machine),
        strategy_name: name_of(p, "strategy", strategy),
        strategy: profile_turning(p, &f, feed)?,
        surface: surf,
        tool: round_nose(p)?,
        machine: lathe(&p.machine_params, dialect),
    })
}

fn name_of(p: &Parts, part: &str, o: &Object) -> String {
    p.job
        .part_names
        .get(part)
        .cloned()
        .unwrap_or_else(|| o.kind.name.to_string())
}

/// A feed as the planner takes it.
fn feed_of(f: StatedFeed) -> Feed {
    match f {
        StatedFeed::PerRevolution(v) => Feed::PerRevolution(v),
        StatedFeed::PerTime(v) => Feed::PerTime(v),
    }
}

fn profile_turning(
    p: &Parts,
    f: &ProfileTurningParams,
    feed: Feed,
) -> Result<ProfileTurning, Vec<Diagnostic>> {
    let tolerance =
        p.chord_tolerance(<TurningSpec as crate::strategy::Strategy>::LENGTH_AXES.unwrap_or(2));
    Ok(ProfileTurning {
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
                holds: p.holds(<TurningSpec as crate::strategy::Strategy>::LENGTH_AXES),
            },
        ),
        feed,
        // Under constant surface speed the spindle speed is its cap.
        spindle_speed: f
            .spindle_speed
            .or(f.spindle_cap)
            .unwrap_or(p.max_spindle_speed()),
        surface_speed: f.surface_speed,
        chord_tolerance: tolerance,
        start_radius: f.from.map(|s| s.value),
        // An annular aperture's cut ends at its inner edge.
        end_radius: f
            .to
            .unwrap_or_else(|| p.surface_params.region().map_or(0.0, |a| a.inner_radius())),
        retract: f.retract.unwrap_or(1.0),
        location: tool_location(f),
        roughing: roughing(f),
    })
}

fn lathe(m: &MachineParams, dialect: Dialect) -> Lathe {
    // A lathe's travel states X and Z (the checker requires both).
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    Lathe {
        dialect,
        resolution: m.resolution,
        travel_x: m.travel[0].unwrap_or(all),
        travel_z: m.travel[2].unwrap_or(all),
        max_feed: m.max_feed,
        max_spindle_speed: m.max_spindle_speed.unwrap_or(f64::INFINITY),
    }
}

/// The round-nose tool, or E0121 for what it lacks.
fn round_nose(p: &Parts) -> Result<RoundNoseTool, Vec<Diagnostic>> {
    let t = &p.tool_params;
    Ok(RoundNoseTool {
        nose_radius: p.tool_needs(t.nose_radius, "nose_radius")?,
        clearance_angle: p.tool_needs(t.clearance, "clearance")?,
        centre_height: t.centre_height.unwrap_or(0.0),
        rake_angle: t.rake.unwrap_or(0.0),
        // Read, with its checks, by `lower` (`crate::edge`).
        edge: None,
    })
}

/// Roughing passes, when the strategy states the stock and a depth of cut.
fn roughing(f: &ProfileTurningParams) -> Option<Roughing> {
    let stock = match (f.stock_top, f.stock_allowance) {
        (Some(top), _) => Stock::Flat { top },
        (None, Some(allowance)) => Stock::Offset { allowance },
        (None, None) => return None,
    };
    Some(Roughing {
        stock,
        depth_of_cut: f.depth_of_cut?,
        finish_allowance: f.finish_allowance.unwrap_or(0.0),
        // The checker refuses a stock without it (E0170).
        feed: f.rough_feed.map(feed_of)?,
        spindle_speed: f.rough_spindle_speed,
    })
}

/// The `search` of a profile-turning strategy: exact unless the user asks
/// for one of Lei et al.'s reference searches.
fn tool_location(f: &ProfileTurningParams) -> ToolLocation {
    let spacing = f.search_spacing.unwrap_or(1e-3);
    match f.search {
        Some("sequential") => ToolLocation::Sequential {
            spacing,
            step: f.search_step.unwrap_or(1e-5),
        },
        Some("binary") => ToolLocation::Binary {
            spacing,
            tolerance: f.search_step.unwrap_or(1e-6),
        },
        _ => ToolLocation::Exact,
    }
}

/// What the program header says about a surface of revolution that can be
/// turned (sphere, conic, asphere, Q-bfs, Q-con with a circular or annular
/// aperture), or `None` if it is not one.
fn surface_info(o: &Object, params: &Surface) -> Option<SurfaceInfo> {
    if let Surface::Revolve(revolve) = params {
        let aperture_radius = revolve.aperture.radius()?;
        return Some(SurfaceInfo {
            description: format!(
                "{}, aperture radius {} mm; +Z out of the material",
                lensc_lang::lower::describe(o),
                lensc_lang::lower::exact_in(aperture_radius, "mm")
            ),
            aperture_radius,
        });
    }
    let (base, facing, ap) = match params {
        Surface::Sphere(c) | Surface::Conic(c) | Surface::Asphere(c) => {
            (&c.base, c.facing, &c.aperture)
        }
        Surface::Qbfs(f) | Surface::Qcon(f) => (&f.base, f.facing, &f.aperture),
        _ => return None,
    };
    let aperture_radius = ap.radius()?;
    let side = lensc_lang::lower::surface::Side::from(facing);
    let radius = base.radius;
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
    let inner = ap.inner_radius();
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

/// What to do with a surface profile turning cannot cut: a rotationally
/// symmetric kind needs a circular aperture; any other is cut on a spiral
/// that follows its height around each turn (`revolve` would sweep one
/// profile round: another part).
fn not_turnable_help(kind: &str) -> String {
    const SYMMETRIC: [&str; 7] = [
        "sphere", "conic", "asphere", "qbfs", "qcon", "plane", "revolve",
    ];
    if SYMMETRIC.contains(&kind) {
        "sphere, conic, asphere, qbfs, qcon and revolve surfaces are turned with a circle or annulus aperture: give it one".to_string()
    } else {
        format!(
            "a `{kind}` is not rotationally symmetric: cut it with `spiral_turning` on a slow-tool-servo lathe (or `fts_spiral` with a fast tool servo), whose spiral follows its height around each turn; `revolve` would sweep one profile round, another part"
        )
    }
}

/// E0141, before planning, at the tool's nose radius: a nose so large that
/// its centre, touching the surface where the cut ends, is above the
/// machine's Z travel (a 0.5 m nose for 0.5 mm): the nose cannot reach
/// the part, whatever the path. The centre there is z + ρ / sqrt(1 + z′²).
fn nose_out_of_reach(
    p: &Parts,
    job: &TurningJob,
    profile: &dyn lensc_runtime::surface::Profile,
) -> Option<Diagnostic> {
    let (_, z_max) = p.machine_params.travel[2]?;
    let rho = job.tool.nose_radius;
    let end = profile.point(job.strategy.end_radius);
    let centre = end.z + rho / end.dz.hypot(1.0);
    if centre.is_nan() || centre <= z_max {
        return None;
    }
    let (file, span) = lensc_lang::value::Reader::new(&p.tool.fields)
        .field("nose_radius")
        .map_or(p.site(), |f| (f.file, f.span));
    Some(
        Diagnostic::error(
            codes::OUT_OF_TRAVEL,
            format!(
                "a nose of radius {} mm cannot reach the part: touching it at r = {} mm its centre is at Z {} mm, above the machine's Z travel (up to {} mm)",
                trim_num(rho),
                trim_num(job.strategy.end_radius),
                trim_num(centre),
                trim_num(z_max)
            ),
            file,
            span,
        )
        .with_label("this nose radius")
        .with_help("check the nose radius's unit (`0.5 mm`, not `0.5 m`); a nose this size needs a machine with that much Z travel"),
    )
}
