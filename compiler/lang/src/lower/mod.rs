//! Lowering: checked values to what the runtime reads. `surface` turns a
//! surface into IR; `read_back` finds what a program is read back
//! against. Here too: the dialect a job is written in, and a surface
//! described in words. (A whole job is lowered to its typed `JobSpec` by
//! its strategy, in lensc-build.)

pub mod read_back;
pub mod surface;

use lensc_grammar::suggest::did_you_mean;
use lensc_grammar::{Diagnostic, FileId};
use lensc_runtime::post::Dialect;

use crate::check::CheckedJob;
use crate::codes;
use crate::value::{self, Object, Value};

/// A surface in words: its kind and every parameter, nested surfaces in
/// brackets, apertures included (a revolved profile's own aperture is what
/// makes its seams).
pub fn describe(o: &Object) -> String {
    let mut words = vec![o.kind.name.to_string()];
    for fl in &o.fields {
        match &fl.value {
            Value::Num(v, d) => words.push(format!("{} {}", fl.name, stated(*v, *d))),
            Value::Word(w) => words.push(format!("{} {w}", fl.name)),
            Value::Object(inner) => words.push(format!("{} [{}]", fl.name, describe(inner))),
            Value::Range(a, b, d) => {
                let (unit, _) = d.display_unit();
                words.push(format!(
                    "{} {} .. {} {unit}",
                    fl.name,
                    exact_in(*a, &unit),
                    exact_in(*b, &unit)
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
    klartext_on_a_lathe(job)?;
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
        .with_help(dialect_help(requested.unwrap_or(""), &offered, &names)));
    };
    check_word_formats(o)?;
    controller_can_run(job, o)?;
    Ok(dialect_of(o, dialect_name(o)))
}

/// E0176 a G-code system on a dialect chosen for a machine that is not a
/// lathe; E0177 constant surface speed asked of a dialect that has none.
/// Both name the dialect and the machine.
fn controller_can_run(job: &CheckedJob, o: &Object) -> Result<(), Diagnostic> {
    let machine = value::object(&job.fields, "machine").expect("checked job part");
    let (file, span) = job_site(job);
    let system = match value::field(&o.fields, "gcode_system").map(|f| &f.value) {
        Some(Value::Str(s)) => Some(s.as_str()),
        _ => None,
    };
    if let Some(system) = system
        && !matches!(system, "A" | "B" | "C")
    {
        return Err(Diagnostic::error(
            codes::GCODE_SYSTEM_NOT_OFFERED,
            format!(
                "`{}` names G-code system `{system}`; a Fanuc lathe offers systems A, B and C (machine `{}`)",
                dialect_name(o),
                dialect_name(machine)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("write `gcode_system: \"A\"` (the 0i-TF's default), `\"B\"` or `\"C\"`, as the control's parameter is set"));
    }
    if let Some(system) = system
        && machine.kind.name == "mill_3axis"
    {
        return Err(Diagnostic::error(
            codes::GCODE_SYSTEM_NOT_OFFERED,
            format!(
                "`{}` is set to G-code system {}, a Fanuc lathe's setting; this machine is a `{}`",
                dialect_name(o),
                system,
                machine.kind.name
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("a mill's Fanuc control has one G-code system: name a mill dialect (`fanuc_0i_mill`), or leave `gcode_system` out of your copy"));
    }
    let strategy = value::object(&job.fields, "strategy").expect("checked job part");
    let empty = |n: &str| match value::field(&o.fields, n).map(|f| &f.value) {
        Some(Value::List(items)) => items.is_empty(),
        _ => true,
    };
    if strategy.kind.name == "profile_turning"
        && value::field(&strategy.fields, "surface_speed").is_some()
        && empty("surface_speed")
    {
        return Err(Diagnostic::error(
            codes::NO_SURFACE_SPEED,
            format!(
                "`{}` has no constant surface speed (no `surface_speed` lines), and strategy `{}` asks for it on machine `{}`",
                dialect_name(o),
                dialect_name(strategy),
                dialect_name(machine)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("give the strategy a `spindle_speed` instead, or give the dialect the blocks that set constant surface speed (`surface_speed: [\"G96 D{cap} S{speed}\"]`)"));
    }
    Ok(())
}

/// E0174 where a machine that is not a mill names a Klartext dialect
/// (as its `dialect` or among its `other_dialects`): Klartext is the TNC
/// mills' language, with no lathe programs.
fn klartext_on_a_lathe(job: &CheckedJob) -> Result<(), Diagnostic> {
    let machine = value::object(&job.fields, "machine").expect("checked job part");
    if machine.kind.name == "mill_3axis" {
        return Ok(());
    }
    let klartext = |o: &Object| value::word(&o.fields, "language") == Some("klartext");
    let mut named = Vec::new();
    if let Some(f) = value::field(&machine.fields, "dialect")
        && let Value::Object(o) = &f.value
    {
        named.push((o.as_ref(), f.file, f.span));
    }
    if let Some(f) = value::field(&machine.fields, "other_dialects")
        && let Value::List(items) = &f.value
    {
        for (v, span) in items {
            if let Value::Object(o) = v {
                named.push((o.as_ref(), f.file, *span));
            }
        }
    }
    let Some((o, file, span)) = named.into_iter().find(|(o, _, _)| klartext(o)) else {
        return Ok(());
    };
    Err(Diagnostic::error(
        codes::KLARTEXT_ON_A_LATHE,
        format!(
            "`{}` is Heidenhain Klartext, a language for TNC mills; this machine is a `{}`",
            dialect_name(o),
            machine.kind.name
        ),
        file,
        span,
    )
    .with_label("a Klartext dialect on a machine that is not a mill")
    .with_help("Klartext programs only mills: name a G-code dialect this machine's controller reads (`linuxcnc`, `fanuc_0i_lathe`, `siemens_840d_lathe`, `ultra_precision_lathe_gcode`)"))
}

/// E0172 at the first of a dialect's `word_formats` that does not read.
fn check_word_formats(o: &Object) -> Result<(), Diagnostic> {
    let Some(field) = value::field(&o.fields, "word_formats") else {
        return Ok(());
    };
    let Value::List(items) = &field.value else {
        return Ok(());
    };
    for (v, span) in items {
        if let Value::Str(text) = v
            && let Err(why) = lensc_runtime::dialect::WordFormat::parse(text)
        {
            return Err(Diagnostic::error(
                codes::BAD_WORD_FORMAT,
                format!("the dialect `{}` has a word format that does not read: {why}", dialect_name(o)),
                field.file,
                *span,
            )
            .with_label("this format")
            .with_help("write a letter, the most digits before the point, and for a word with a point `.` and the most decimals: `S5`, `X4.4`"));
        }
    }
    Ok(())
}

/// What to write instead of a dialect the machine does not offer: the
/// nearest name it offers; else, for a dialect the standard library has,
/// how to add it to the machine; else the nearest dialect there is.
fn dialect_help(requested: &str, offered: &[&Object], names: &[String]) -> String {
    let offers = format!("its machine offers {}", names.join(", "));
    let offered_names: Vec<String> = offered.iter().map(|o| dialect_name(o)).collect();
    if let Some(s) = did_you_mean(requested, offered_names.iter().map(String::as_str)) {
        return format!("did you mean `--dialect {s}`? {}", capitalised(&offers));
    }
    let std_dialects = || {
        crate::stdlib::items()
            .iter()
            .filter(|i| i.kind == lensc_grammar::ast::DeclKind::Dialect)
            .map(|i| i.name.as_str())
    };
    if std_dialects().any(|d| d == requested) {
        return format!(
            "{offers}; if its controller reads `{requested}`, add it to the machine's `other_dialects: [{requested}]`"
        );
    }
    match did_you_mean(requested, std_dialects()) {
        Some(s) => format!(
            "no standard dialect is called `{requested}`: did you mean `{s}`? {offers}; `lensc list dialects` shows them all"
        ),
        None => format!(
            "no standard dialect is called `{requested}`; {offers}; `lensc list dialects` shows them all"
        ),
    }
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
pub(crate) fn dialect_of(o: &Object, name: String) -> Dialect {
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
    use lensc_runtime::dialect::GcodeSystem;
    use lensc_runtime::moves::Plane;
    let system = match opt_text("gcode_system").as_deref() {
        Some("A") => Some(GcodeSystem::A),
        Some("B") => Some(GcodeSystem::B),
        Some("C") => Some(GcodeSystem::C),
        _ => None,
    };
    // A Fanuc lathe's code system fills its placeholders and feed words.
    let system_words = |l: String| match system {
        None => l,
        Some(s) => {
            let a = s == GcodeSystem::A;
            l.replace("{feeds}", if a { "G98" } else { "G90 G94" })
                .replace("{clamp}", if a { "G50" } else { "G92" })
                .replace("{home}", if a { "G28 U0. W0." } else { "G91 G28 X0. Z0." })
        }
    };
    let lines = |n: &str| -> Vec<String> { lines(n).into_iter().map(system_words).collect() };
    let (minute, revolution) = match system {
        Some(GcodeSystem::A) => (Some("G98"), Some("G99")),
        Some(_) => (Some("G94"), Some("G95")),
        None => (None, None),
    };
    Dialect {
        name,
        language: match value::word(f, "language") {
            Some("klartext") => lensc_runtime::dialect::Language::Klartext,
            _ => lensc_runtime::dialect::Language::GCode,
        },
        extension: text("extension", "nc"),
        comment: match value::word(f, "comment") {
            Some("semicolon") => lensc_runtime::post::CommentStyle::Semicolon,
            _ => lensc_runtime::post::CommentStyle::Parentheses,
        },
        start: lines("start"),
        program_number: count("program_number").unwrap_or(1) as u32,
        lathe_setup: lines("lathe_setup"),
        mill_setup: lines("mill_setup"),
        lathe_tool_call: lines("lathe_tool_call"),
        mill_tool_call: lines("mill_tool_call"),
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
        per_minute: opt_text("per_minute").or(minute.map(String::from)),
        per_revolution: opt_text("per_revolution").or(revolution.map(String::from)),
        inverse_time: opt_text("inverse_time"),
        spindle_on: text("spindle_on", "M3"),
        spindle_ccw: text("spindle_ccw", "M4"),
        spindle_off: text("spindle_off", "M5"),
        constant_rpm: opt_text("constant_rpm"),
        spindle_orient: lines("spindle_orient"),
        coolant_flood: opt_text("coolant_flood"),
        coolant_mist: opt_text("coolant_mist"),
        coolant_off: opt_text("coolant_off"),
        // Checked by `word_formats` before the dialect is built.
        word_formats: lines("word_formats")
            .iter()
            .filter_map(|t| lensc_runtime::dialect::WordFormat::parse(t).ok())
            .collect(),
        c_letter: text("c_letter", "C").chars().next().unwrap_or('C'),
        c_decimals: count("c_decimals").unwrap_or(5) as u32,
        max_decimals: count("max_decimals").map(|v| v as u32),
        max_digits: count("max_digits").map(|v| v as u32),
        max_line_length: count("max_line_length").map(|v| v as usize),
        line_numbers: count("line_numbers"),
        max_line_number: count("max_line_number"),
        block_end: text("block_end", ""),
        gcode_system: system,
        length_offset: text("length_offset", ""),
        surface_speed_per_revolution: value::word(f, "surface_speed_feed")
            == Some("per_revolution"),
    }
}

/// Where a plan error should point: the job's name.
pub fn job_site(job: &CheckedJob) -> (FileId, lensc_grammar::Span) {
    (job.file, job.name.span)
}

/// A figure `v` (base units) as a header states it in `unit`: the
/// shortest decimal that reads back, through the unit, to the same f64
/// (scientific notation past 17 characters, never `-0`).
pub fn exact_in(v: f64, unit: &str) -> String {
    lensc_runtime::post::header::exact_in(v, crate::units::size_of(unit).unwrap_or(1.0))
}

/// A quantity as a header states it: the figure in its dimension's display
/// unit, and that unit (`3 deg`, `0.5 mm`, `0.00021 1/mm^3`, `-0.62`).
pub fn stated(v: f64, d: crate::units::Dim) -> String {
    let (unit, _) = d.display_unit();
    let n = exact_in(v, &unit);
    if unit.is_empty() {
        n
    } else {
        format!("{n} {unit}")
    }
}

/// `its machine …` → `Its machine …`, to start a sentence.
fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}
