//! Lowering: a checked job to the runtime's job description, with the
//! checks that need several parts at once (is this strategy able to cut
//! this surface on this machine?).

use lensc_grammar::{Diagnostic, FileId};
use lensc_runtime::Job;
use lensc_runtime::machine::{Dialect, Lathe};
use lensc_runtime::surface::SurfaceInfo;
use lensc_runtime::tool::RoundNoseTool;
use lensc_runtime::toolpath::{Feed, ProfileTurning, Roughing, Stock, ToolLocation};

use crate::check::{CheckedJob, aperture_inner_radius, aperture_radius, trim_num};
use crate::codes;
use crate::units::Dim;
use crate::value::{self, Object, Value};

/// Lowers one checked job, or says why it cannot be built.
pub fn lower(job: &CheckedJob) -> Result<Job, Vec<Diagnostic>> {
    let part = |name: &str| value::object(&job.fields, name).expect("checked job part");
    let (surface, tool, machine, strategy) = (
        part("surface"),
        part("tool"),
        part("machine"),
        part("strategy"),
    );
    let mut errors = Vec::new();
    let at = |name: &str| {
        let f = value::field(&job.fields, name).expect("checked job part");
        (f.file, f.span)
    };

    let unsupported = |what: &str, name: &str, detail: String| {
        let (file, span) = at(name);
        Diagnostic::error(codes::UNSUPPORTED_COMBINATION, what.to_string(), file, span)
            .with_label(detail)
    };

    if strategy.kind.name != "profile_turning" {
        errors.push(unsupported(
            "lensc cannot build this strategy yet",
            "strategy",
            format!("`{}`", strategy.kind.name),
        ));
    }
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
    let surf = match surface_info(surface) {
        Some(s) => Some(s),
        None => {
            errors.push(
                unsupported(
                    "profile turning needs a rotationally symmetric surface with a circular aperture",
                    "surface",
                    format!("this is a `{}`", surface.kind.name),
                )
                .with_help("sphere, conic, asphere, qbfs and qcon surfaces with a circle or annulus aperture can be turned, and any profile made a surface of revolution with `revolve`"),
            );
            None
        }
    };
    if !errors.is_empty() {
        return Err(errors);
    }
    let surf = surf.expect("checked above");
    let f = &strategy.fields;
    let from = value::num(f, "from");
    if let Some(start) = from
        && start > surf.aperture_radius
    {
        let fld = value::field(f, "from").expect("from");
        errors.push(
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
        );
    }
    let feed = match value::field(f, "feed").map(|x| &x.value) {
        Some(Value::Num(v, d)) if *d == Dim::FEED_PER_REV => Feed::PerRevolution(*v),
        Some(Value::Num(v, _)) => Feed::PerTime(*v),
        _ => unreachable!("feed is required and checked"),
    };
    let strat = ProfileTurning {
        feed,
        spindle_speed: value::num(f, "spindle_speed").expect("required"),
        chord_tolerance: value::num(f, "chord_tolerance").unwrap_or(10e-6),
        start_radius: from,
        // An annular aperture's cut ends at its inner edge.
        end_radius: value::num(f, "to").unwrap_or_else(|| {
            value::object(&surface.fields, "aperture").map_or(0.0, |a| aperture_inner_radius(a))
        }),
        retract: value::num(f, "retract").unwrap_or(1.0),
        location: tool_location(f),
        roughing: roughing(f),
    };
    let m = &machine.fields;
    let travel = value::block(m, "travel").expect("required");
    let spindle = value::block(m, "spindle").expect("required");
    let lathe = Lathe {
        dialect: value::word(m, "dialect")
            .and_then(Dialect::from_name)
            .expect("the schema admits only known dialects"),
        resolution: value::num(m, "resolution").expect("required"),
        travel_x: value::range(travel, "x").expect("required"),
        travel_z: value::range(travel, "z").expect("required"),
        max_feed: value::num(m, "max_feed").expect("required"),
        max_spindle_speed: value::num(spindle, "max_speed").expect("required"),
    };
    let t = &tool.fields;
    let cutter = RoundNoseTool {
        nose_radius: value::num(t, "nose_radius").expect("required"),
        clearance_angle: value::num(t, "clearance").expect("required"),
        centre_height: value::num(t, "centre_height").unwrap_or(0.0),
        rake_angle: value::num(t, "rake").unwrap_or(0.0),
    };
    if !errors.is_empty() {
        return Err(errors);
    }
    let name_of = |p: &str, o: &Object| {
        job.part_names
            .get(p)
            .cloned()
            .unwrap_or_else(|| o.kind.name.to_string())
    };
    Ok(Job {
        name: job.name.name.clone(),
        surface_name: name_of("surface", surface),
        tool_name: name_of("tool", tool),
        machine_name: name_of("machine", machine),
        strategy_name: name_of("strategy", strategy),
        surface: surf,
        tool: cutter,
        machine: lathe,
        strategy: strat,
    })
}

/// Roughing passes, when the strategy states the stock and a depth of cut.
fn roughing(f: &[value::Field]) -> Option<Roughing> {
    let stock = match (value::num(f, "stock_top"), value::num(f, "stock_allowance")) {
        (Some(top), _) => Stock::Flat { top },
        (None, Some(allowance)) => Stock::Offset { allowance },
        (None, None) => return None,
    };
    Some(Roughing {
        stock,
        depth_of_cut: value::num(f, "depth_of_cut")?,
        finish_allowance: value::num(f, "finish_allowance").unwrap_or(0.0),
    })
}

/// The `search` of a profile-turning strategy: exact unless the user asks
/// for one of Lei et al.'s reference searches.
fn tool_location(f: &[value::Field]) -> ToolLocation {
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
                describe(o),
                trim_num(aperture_radius)
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
    let side = crate::surfaces::Side::of(&o.fields);
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
                let (unit, factor) = d.display_unit();
                words.push(format!(
                    "{name} {}{}{unit}",
                    exact_num(v * factor),
                    if unit.is_empty() { "" } else { " " }
                ));
            }
            _ => {}
        }
    }
    let inner = aperture_inner_radius(ap);
    let aperture = if inner > 0.0 {
        format!(
            "annular aperture {} .. {} mm",
            trim_num(inner),
            trim_num(aperture_radius)
        )
    } else {
        format!("aperture radius {} mm", trim_num(aperture_radius))
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

/// A surface in words: its kind and every parameter, nested surfaces in
/// brackets, apertures included (a revolved profile's own aperture is what
/// makes its seams).
pub fn describe(o: &Object) -> String {
    let mut words = vec![o.kind.name.to_string()];
    for fl in &o.fields {
        match &fl.value {
            Value::Num(v, d) => {
                let (unit, factor) = d.display_unit();
                words.push(format!(
                    "{} {}{}{unit}",
                    fl.name,
                    exact_num(v * factor),
                    if unit.is_empty() { "" } else { " " }
                ));
            }
            Value::Word(w) => words.push(format!("{} {w}", fl.name)),
            Value::Object(inner) => words.push(format!("{} [{}]", fl.name, describe(inner))),
            Value::Range(a, b, d) => {
                let (unit, factor) = d.display_unit();
                words.push(format!(
                    "{} {} .. {} {unit}",
                    fl.name,
                    exact_num(a * factor),
                    exact_num(b * factor)
                ));
            }
            _ => {}
        }
    }
    words.join(", ")
}

/// Where a plan error should point: the job's name.
pub fn job_site(job: &CheckedJob) -> (FileId, lensc_grammar::Span) {
    (job.file, job.name.span)
}

/// A parameter as a header states it: the shortest decimal that reads
/// back as the same f64 (never an exponent), or 12 decimals when a unit
/// conversion left a long tail (0.08499999999999999).
fn exact_num(v: f64) -> String {
    let s = format!("{v}");
    if s.trim_start_matches('-').len() <= 17 {
        return s;
    }
    let t = format!("{v:.12}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}
