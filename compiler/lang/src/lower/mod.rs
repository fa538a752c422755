//! Lowering: a checked job to the runtime's job description, with the
//! checks that need several parts at once (is this strategy able to cut
//! this surface on this machine?).

pub mod surface;

use lensc_grammar::{Diagnostic, FileId};
use lensc_runtime::machine::Lathe;
use lensc_runtime::machine::tool::RoundNoseTool;
use lensc_runtime::plan::turning::TurningJob;
use lensc_runtime::plan::turning::{Feed, ProfileTurning, Roughing, Stock, ToolLocation};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::SurfaceInfo;

use crate::check::{CheckedJob, aperture_inner_radius, aperture_radius, trim_num};
use crate::codes;
use crate::units::Dim;
use crate::value::{self, Object, Value};

/// Lowers one checked job, or says why it cannot be built.
pub fn lower(job: &CheckedJob, dialect: Dialect) -> Result<TurningJob, Vec<Diagnostic>> {
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
        // Under constant surface speed the spindle speed is its cap.
        spindle_speed: value::num(f, "spindle_speed")
            .or_else(|| value::num(f, "spindle_cap"))
            .unwrap_or_else(|| {
                value::block(&machine.fields, "spindle")
                    .and_then(|s| value::num(s, "max_speed"))
                    .expect("required")
            }),
        surface_speed: value::num(f, "surface_speed"),
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
        dialect,
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
    Ok(TurningJob {
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
    let side = crate::lower::surface::Side::of(&o.fields);
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

/// The dialect a job's program is written in: the machine's `dialect`, or
/// the one `requested` (by `lensc build --dialect`) among it and its
/// `other_dialects`; E0148 if the machine offers no dialect of that name.
pub fn dialect(job: &CheckedJob, requested: Option<&str>) -> Result<Dialect, Diagnostic> {
    let offered = offered(job);
    let chosen = match requested {
        None => offered.first().copied(),
        Some(r) => offered.iter().copied().find(|o| dialect_name(o) == r),
    };
    let Some(o) = chosen else {
        let (file, span) = job_site(job);
        let names: Vec<String> = offered
            .iter()
            .map(|o| format!("`{}`", dialect_name(o)))
            .collect();
        return Err(Diagnostic::error(
            codes::DIALECT_NOT_OFFERED,
            format!(
                "the machine of this job is not programmed in `{}`",
                requested.unwrap_or("")
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help(format!(
            "its machine offers {}; add the dialect to the machine's `other_dialects` if its controller reads it",
            names.join(", ")
        )));
    };
    Ok(dialect_of(o, dialect_name(o)))
}

/// The names of the dialects a job's machine offers, its own first.
pub fn offered_dialects(job: &CheckedJob) -> Vec<String> {
    offered(job).into_iter().map(dialect_name).collect()
}

fn dialect_name(o: &Object) -> String {
    o.name.clone().unwrap_or_else(|| o.kind.name.to_string())
}

/// The machine's `dialect` and then its `other_dialects`.
fn offered(job: &CheckedJob) -> Vec<&Object> {
    let machine = value::object(&job.fields, "machine").expect("checked job part");
    let mut offered: Vec<&Object> = value::object(&machine.fields, "dialect")
        .map(|o| o.as_ref())
        .into_iter()
        .collect();
    if let Some(Value::List(items)) =
        value::field(&machine.fields, "other_dialects").map(|f| &f.value)
    {
        offered.extend(items.iter().filter_map(|(v, _)| match v {
            Value::Object(o) => Some(o.as_ref()),
            _ => None,
        }));
    }
    offered
}

/// A checked `gcode { … }` dialect as the post-processor reads it.
fn dialect_of(o: &Object, name: String) -> Dialect {
    let f = &o.fields;
    let text = |n: &str, default: &str| match value::field(f, n).map(|x| &x.value) {
        Some(Value::Str(s)) => s.clone(),
        _ => default.to_string(),
    };
    let opt_text = |n: &str| match value::field(f, n).map(|x| &x.value) {
        Some(Value::Str(s)) => Some(s.clone()),
        _ => None,
    };
    let lines = |n: &str| match value::field(f, n).map(|x| &x.value) {
        Some(Value::List(items)) => items
            .iter()
            .filter_map(|(v, _)| match v {
                Value::Str(s) => Some(s.clone()),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    };
    let count = |n: &str| value::num(f, n).map(|v| v as u64);
    use lensc_runtime::moves::Plane;
    Dialect {
        name,
        extension: text("extension", "nc"),
        comment: match value::word(f, "comment") {
            Some("semicolon") => lensc_runtime::post::CommentStyle::Semicolon,
            _ => lensc_runtime::post::CommentStyle::Parentheses,
        },
        start: lines("start"),
        program_number: count("program_number").unwrap_or(1) as u32,
        lathe_setup: lines("lathe_setup"),
        mill_setup: lines("mill_setup"),
        path_tolerance: lines("path_tolerance"),
        c_axis_on: lines("c_axis_on"),
        c_axis_off: lines("c_axis_off"),
        surface_speed: lines("surface_speed"),
        fts_table: opt_text("fts_table"),
        fts_on: lines("fts_on"),
        fts_off: lines("fts_off"),
        end: lines("end"),
        trailer: lines("trailer"),
        lathe_x_diameter: value::word(f, "lathe_x") == Some("diameter"),
        rapid: text("rapid", "G0"),
        linear: text("linear", "G1"),
        arc_cw: text("arc_cw", "G2"),
        arc_ccw: text("arc_ccw", "G3"),
        arc_planes: lines("arc_planes")
            .iter()
            .filter_map(|p| match p.as_str() {
                "xy" => Some(Plane::Xy),
                "zx" => Some(Plane::Zx),
                "yz" => Some(Plane::Yz),
                _ => None,
            })
            .collect(),
        arc_centre_absolute: value::word(f, "arc_centre") == Some("absolute"),
        arc_radius_tolerance: value::num(f, "arc_radius_tolerance").unwrap_or(0.001),
        per_minute: opt_text("per_minute"),
        per_revolution: opt_text("per_revolution"),
        inverse_time: opt_text("inverse_time"),
        spindle_on: text("spindle_on", "M3"),
        spindle_off: text("spindle_off", "M5"),
        c_letter: text("c_letter", "C").chars().next().unwrap_or('C'),
        c_decimals: count("c_decimals").unwrap_or(5) as u32,
        max_decimals: count("max_decimals").map(|v| v as u32),
        max_digits: count("max_digits").map(|v| v as u32),
        max_line_length: count("max_line_length").map(|v| v as usize),
        line_numbers: count("line_numbers"),
        max_line_number: count("max_line_number"),
        block_end: text("block_end", ""),
    }
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
