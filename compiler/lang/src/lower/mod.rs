//! Lowering: checked values to what the runtime reads. `surface` turns a
//! surface into IR; `read_back` finds what a program is read back
//! against. Here too: the dialect a job is written in, and a surface
//! described in words. (A whole job is lowered to its typed `JobSpec` by
//! its strategy, in lensc-build.)

pub mod read_back;
pub mod surface;

use lensc_grammar::suggest::{completions, did_you_mean, meant};
use lensc_grammar::{Diagnostic, FileId};
use lensc_runtime::post::Dialect;

use crate::check::CheckedJob;
use crate::codes;
use crate::schema::{self, Gcode, OfferedDialect};
use crate::value::{Object, Reader, Value};

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
    let machine = machine_of(job)?;
    klartext_on_a_lathe(machine)?;
    let offered = schema::offered_dialects(machine);
    let chosen = match requested {
        None => offered.first(),
        Some(r) => offered.iter().find(|o| o.name() == r),
    };
    let Some(o) = chosen else {
        let (file, span) = job_site(job);
        let names: Vec<String> = offered.iter().map(|o| format!("`{}`", o.name())).collect();
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
    let gcode = Gcode::read(o.dialect);
    check_word_formats(&gcode, &o.name())?;
    controller_can_run(job, &gcode, &o.name())?;
    Ok(dialect_from(gcode, o.name()))
}

/// The machine of a checked job; E0121 if it has none (one that did not
/// check).
fn machine_of(job: &CheckedJob) -> Result<&Object, Diagnostic> {
    match Reader::new(&job.fields).object("machine") {
        Some(machine) => Ok(machine),
        None => Err(Diagnostic::error(
            codes::MISSING_PARAMETER,
            format!("job `{}` is missing `machine`", job.name.name),
            job.file,
            job.name.span,
        )
        .with_label("this job")),
    }
}

/// E0176 a G-code system on a dialect chosen for a machine that is not a
/// lathe, or one a Fanuc lathe does not offer; E0177 constant surface
/// speed asked of a dialect that has none; E0178 a tool set to its tip on
/// a fast-tool-servo lathe whose dialect drives the servo from a table of
/// nose-centre heights. Each names the dialect and the machine.
fn controller_can_run(job: &CheckedJob, g: &Gcode, dialect: &str) -> Result<(), Diagnostic> {
    let parts = Reader::new(&job.fields);
    let (Some(machine), Some(strategy)) = (parts.object("machine"), parts.object("strategy"))
    else {
        return Ok(());
    };
    let name = |o: &Object| o.name.clone().unwrap_or_else(|| o.kind.name.to_string());
    let (file, span) = job_site(job);
    if let Some(system) = g.gcode_system.as_deref()
        && !matches!(system, "A" | "B" | "C")
    {
        return Err(Diagnostic::error(
            codes::GCODE_SYSTEM_NOT_OFFERED,
            format!(
                "`{dialect}` names G-code system `{system}`; a Fanuc lathe offers systems A, B and C (machine `{}`)",
                name(machine)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("write `gcode_system: \"A\"` (the 0i-TF's default), `\"B\"` or `\"C\"`, as the control's parameter is set"));
    }
    if let Some(system) = g.gcode_system.as_deref()
        && machine.kind.name == "mill_3axis"
    {
        return Err(Diagnostic::error(
            codes::GCODE_SYSTEM_NOT_OFFERED,
            format!(
                "`{dialect}` is set to G-code system {system}, a Fanuc lathe's setting; this machine is a `{}`",
                machine.kind.name
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("a mill's Fanuc control has one G-code system: name a mill dialect (`fanuc_0i_mill`), or leave `gcode_system` out of your copy"));
    }
    let tip_stated = parts.object("tool").and_then(|t| {
        Reader::new(&t.fields)
            .stated_word("control_point")
            .filter(|w| w.value == "tool_tip")
            .map(|w| (name(t), w.site))
    });
    if let (Some((tool, (tip_file, tip_span))), Some(table)) = (tip_stated, g.fts_table.as_deref())
        && machine.kind.name == "fts_lathe"
    {
        return Err(Diagnostic::error(
            codes::CONTROL_POINT_NOT_EXPRESSIBLE,
            format!(
                "tool `{tool}` is set to its tip (`control_point: tool_tip`), and `{dialect}` drives the fast tool servo of machine `{}` from a `.{table}` table whose W is the nose centre's height: the table cannot be written for the tip",
                name(machine)
            ),
            tip_file,
            tip_span,
        )
        .with_label("the tip")
        .with_help("set the tool to its nose centre (`control_point: tool_centre`, the servo lathes' default), or name a dialect without a servo table"));
    }
    let asks_surface_speed = strategy.kind.name == "profile_turning"
        && crate::schema::strategies::ProfileTurningParams::read(strategy)
            .is_ok_and(|p| p.surface_speed.is_some());
    if asks_surface_speed && g.surface_speed.is_empty() {
        return Err(Diagnostic::error(
            codes::NO_SURFACE_SPEED,
            format!(
                "`{dialect}` has no constant surface speed (no `surface_speed` lines), and strategy `{}` asks for it on machine `{}`",
                name(strategy),
                name(machine)
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
fn klartext_on_a_lathe(machine: &Object) -> Result<(), Diagnostic> {
    if machine.kind.name == "mill_3axis" {
        return Ok(());
    }
    let Some(o) = schema::offered_dialects(machine)
        .into_iter()
        .find(|o| Gcode::read(o.dialect).klartext)
    else {
        return Ok(());
    };
    Err(Diagnostic::error(
        codes::KLARTEXT_ON_A_LATHE,
        format!(
            "`{}` is Heidenhain Klartext, a language for TNC mills; this machine is a `{}`",
            o.name(),
            machine.kind.name
        ),
        o.file,
        o.span,
    )
    .with_label("a Klartext dialect on a machine that is not a mill")
    .with_help("Klartext programs only mills: name a G-code dialect this machine's controller reads (`linuxcnc`, `fanuc_0i_lathe`, `siemens_840d_lathe`, `ultra_precision_lathe_gcode`)"))
}

/// E0172 at the first of a dialect's `word_formats` that does not read.
fn check_word_formats(gcode: &Gcode, name: &str) -> Result<(), Diagnostic> {
    for format in &gcode.word_formats {
        if let Err(why) = lensc_runtime::dialect::WordFormat::parse(&format.text) {
            return Err(Diagnostic::error(
                codes::BAD_WORD_FORMAT,
                format!("the dialect `{name}` has a word format that does not read: {why}"),
                format.file,
                format.span,
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
fn dialect_help(requested: &str, offered: &[OfferedDialect], names: &[String]) -> String {
    let offers = format!("its machine offers {}", names.join(", "));
    let offered_names: Vec<String> = offered.iter().map(OfferedDialect::name).collect();
    if let Some(s) = did_you_mean(requested, offered_names.iter().map(String::as_str)) {
        return format!("did you mean `--dialect {s}`? {}", capitalised(&offers));
    }
    let cut_short = completions(requested, offered_names.iter().map(String::as_str));
    if !cut_short.is_empty() {
        let options: Vec<String> = cut_short
            .iter()
            .map(|c| format!("`--dialect {c}`"))
            .collect();
        return format!(
            "did you mean {}? {}",
            options.join(" or "),
            capitalised(&offers)
        );
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
    match meant(requested, std_dialects()) {
        Some(s) => format!(
            "no standard dialect is called `{requested}`: did you mean {s}? {offers}; `lensc list dialects` shows them all"
        ),
        None => format!(
            "no standard dialect is called `{requested}`; {offers}; `lensc list dialects` shows them all"
        ),
    }
}

/// The names of the dialects a job's machine offers, its own first.
pub fn offered_dialects(job: &CheckedJob) -> Vec<String> {
    machine_of(job)
        .map(|m| {
            schema::offered_dialects(m)
                .iter()
                .map(OfferedDialect::name)
                .collect()
        })
        .unwrap_or_default()
}

/// A checked `gcode { … }` dialect as the post-processor reads it.
pub(crate) fn dialect_of(o: &Object, name: String) -> Dialect {
    dialect_from(Gcode::read(o), name)
}

/// A dialect's parameters, read, as the post-processor reads them.
fn dialect_from(g: Gcode, name: String) -> Dialect {
    use lensc_runtime::dialect::GcodeSystem;
    use lensc_runtime::moves::Plane;
    let system = match g.gcode_system.as_deref() {
        Some("A") => Some(GcodeSystem::A),
        Some("B") => Some(GcodeSystem::B),
        Some("C") => Some(GcodeSystem::C),
        _ => None,
    };
    // A Fanuc lathe's code system fills its placeholders and feed words.
    let system_words = |lines: &mut Vec<String>| {
        let Some(s) = system else { return };
        let a = s == GcodeSystem::A;
        for l in lines.iter_mut() {
            *l = l
                .replace("{feeds}", if a { "G98" } else { "G90 G94" })
                .replace("{clamp}", if a { "G50" } else { "G92" })
                .replace("{home}", if a { "G28 U0. W0." } else { "G91 G28 X0. Z0." });
        }
    };
    let mut g = g;
    for lines in [
        &mut g.start,
        &mut g.lathe_setup,
        &mut g.mill_setup,
        &mut g.lathe_tool_call,
        &mut g.mill_tool_call,
        &mut g.path_tolerance,
        &mut g.c_axis_on,
        &mut g.c_axis_off,
        &mut g.surface_speed,
        &mut g.fts_on,
        &mut g.fts_off,
        &mut g.end,
        &mut g.trailer,
        &mut g.spindle_orient,
    ] {
        system_words(lines);
    }
    let (minute, revolution) = match system {
        Some(GcodeSystem::A) => (Some("G98"), Some("G99")),
        Some(_) => (Some("G94"), Some("G95")),
        None => (None, None),
    };
    Dialect {
        name,
        language: if g.klartext {
            lensc_runtime::dialect::Language::Klartext
        } else {
            lensc_runtime::dialect::Language::GCode
        },
        extension: g.extension.clone(),
        comment: if g.semicolon_comments {
            lensc_runtime::post::CommentStyle::Semicolon
        } else {
            lensc_runtime::post::CommentStyle::Parentheses
        },
        start: g.start,
        program_number: g.program_number,
        lathe_setup: g.lathe_setup,
        mill_setup: g.mill_setup,
        lathe_tool_call: g.lathe_tool_call,
        mill_tool_call: g.mill_tool_call,
        path_tolerance: g.path_tolerance,
        c_axis_on: g.c_axis_on,
        c_axis_off: g.c_axis_off,
        surface_speed: g.surface_speed,
        fts_table: g.fts_table,
        fts_on: g.fts_on,
        fts_off: g.fts_off,
        end: g.end,
        trailer: g.trailer,
        lathe_x_diameter: g.lathe_x_diameter,
        rapid: g.rapid,
        linear: g.linear,
        arc_cw: g.arc_cw,
        arc_ccw: g.arc_ccw,
        arc_planes: g
            .arc_planes
            .iter()
            // The checker refuses a plane that does not name one (E0126).
            .filter_map(|p| Plane::from_name(p))
            .collect(),
        arc_centre_absolute: g.arc_centre_absolute,
        arc_radius_tolerance: g.arc_radius_tolerance,
        per_minute: g.per_minute.or(minute.map(String::from)),
        per_revolution: g.per_revolution.or(revolution.map(String::from)),
        inverse_time: g.inverse_time,
        spindle_on: g.spindle_on,
        spindle_ccw: g.spindle_ccw,
        spindle_off: g.spindle_off,
        constant_rpm: g.constant_rpm,
        spindle_orient: g.spindle_orient,
        blank_form: g.blank_form,
        coolant_flood: g.coolant_flood,
        coolant_mist: g.coolant_mist,
        coolant_off: g.coolant_off,
        // Checked by `word_formats` before the dialect is built.
        word_formats: g
            .word_formats
            .iter()
            .filter_map(|w| lensc_runtime::dialect::WordFormat::parse(&w.text).ok())
            .collect(),
        c_letter: g.c_letter,
        c_decimals: g.c_decimals,
        max_decimals: g.max_decimals,
        max_digits: g.max_digits,
        max_line_length: g.max_line_length,
        line_numbers: g.line_numbers,
        max_line_number: g.max_line_number,
        block_end: g.block_end,
        gcode_system: system,
        length_offset: g.length_offset,
        surface_speed_per_revolution: g.surface_speed_per_revolution,
        spline: if g.nurbs {
            Some(lensc_runtime::dialect::SplineForm::Nurbs)
        } else if g.bspline {
            Some(lensc_runtime::dialect::SplineForm::Bspline)
        } else {
            None
        },
        spline_option: g.spline_option,
        spline_by_default: g.spline_by_default,
        parts: g.part_call.map(|call| lensc_runtime::dialect::PartCalls {
            call,
            name: g.part_name,
            extension: g.part_extension.unwrap_or_else(|| g.extension.clone()),
            start: g.part_start,
            end: g.part_end,
            continuous: g.part_joins_continuous,
        }),
    }
}

/// Where a plan error should point: the job's name.
pub fn job_site(job: &CheckedJob) -> (FileId, lensc_grammar::Span) {
    (job.file, job.name.span)
}

/// A figure `v` (base units) as a header states it in `unit`: the
/// shortest decimal that reads back, through the unit, to the same f64
/// (scientific notation past 17 characters, never `-0`).
///
/// A figure the file stated in another unit may have no such decimal
/// (`0.2 um` is 0.2 × 1e-3 mm, and no d × 1e-6 is that f64): then the
/// shortest decimal whose product with the unit is that f64's neighbour
/// (one unit in the last place, the rounding of the unit conversion
/// itself): `200 nm`, not `200.00000000000003 nm`.
/// A figure lensc derived rather than one the job states (a default
/// start radius, a settling offset): [`exact_in`] where that takes at
/// most 10 significant digits, else `v` in `unit` to `decimals` places,
/// trailing zeros trimmed: `83.3333 um`, not `83.33333333333334 um`.
pub fn derived_in(v: f64, unit: &str, decimals: usize) -> String {
    let exact = exact_in(v, unit);
    let digits = exact
        .split(['e', 'E'])
        .next()
        .unwrap_or("")
        .chars()
        .filter(char::is_ascii_digit)
        .skip_while(|&c| c == '0')
        .count();
    if digits <= 10 || !v.is_finite() {
        return exact;
    }
    let size = crate::units::size_of(unit).unwrap_or(1.0);
    let s = format!("{:.decimals$}", v / size);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" { "0".into() } else { s.to_string() }
}

pub fn exact_in(v: f64, unit: &str) -> String {
    let size = crate::units::size_of(unit).unwrap_or(1.0);
    let exact = lensc_runtime::post::header::exact_in(v, size);
    if size == 1.0 || !v.is_finite() {
        return exact;
    }
    // The fewest significant digits that read back to `v` or, failing
    // that at this many digits, to a neighbour of it.
    let shown = v / size;
    let neighbours = [v.next_down(), v.next_up()];
    for digits in 0..17 {
        let Ok(d) = format!("{shown:.digits$e}").parse::<f64>() else {
            continue;
        };
        if d * size == v {
            return lensc_runtime::post::header::exact(d);
        }
        if neighbours.contains(&(d * size)) {
            return lensc_runtime::post::header::exact(d);
        }
    }
    exact
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

#[cfg(test)]
mod derived_tests {
    use super::derived_in;

    #[test]
    fn a_derived_figure_is_exact_when_short_and_rounded_when_not() {
        // A settling trajectory of 1 ms at 5 m/min: 83.333… um.
        assert_eq!(derived_in(5000.0 / 60.0 * 1e-3, "um", 4), "83.3333");
        // The default start radius of seed 003's corner: 3.5 √2 mm.
        assert_eq!(derived_in(3.5 * 2f64.sqrt(), "mm", 7), "4.9497475");
        // What a job states stays as stated.
        assert_eq!(derived_in(2.637, "mm", 7), "2.637");
        assert_eq!(derived_in(0.0037, "um", 4), "3.7");
    }
}
