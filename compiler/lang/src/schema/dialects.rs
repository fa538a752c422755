//! The `gcode` dialect kind: everything a post-processor needs to know
//! about a controller, as data; `Gcode`, a dialect's parameters read once,
//! and the dialects a machine offers.

use std::rc::Rc;

use lensc_grammar::FileId;
use lensc_grammar::ast::Span;

use super::{Category, Check, Kind, LENGTH, NUMBER, Param, Ty, opt, req};
use crate::value::{Object, Reader, Value};

const fn text(name: &'static str, doc: &'static str) -> Param {
    opt(name, Ty::Text, Check::Any, doc)
}
const fn texts(name: &'static str, doc: &'static str) -> Param {
    opt(name, Ty::Texts, Check::Any, doc)
}

/// A G-code dialect: everything a post-processor needs to know about a
/// controller, so a shop adds one in a `.lens` file without rebuilding
/// lensc. Lines may hold `{job}`, `{JOB}` (upper case), `{number}` and
/// `{tolerance}` (mm, to the machine's decimals).
const GCODE_PARAMS: &[Param] = &[
    opt(
        "language",
        Ty::Word(&["gcode", "klartext"]),
        Check::Any,
        "the program language: `gcode` (ISO address words, the default) or `klartext` (Heidenhain's conversational language for TNC mills: `L X+1 R0 F100`, `CC`/`C` arcs, `TOOL CALL`, numbered `BEGIN PGM`/`END PGM`); a Klartext dialect has no lathe programs",
    ),
    req(
        "extension",
        Ty::Text,
        Check::Any,
        "the program file's extension, without the dot",
    ),
    req(
        "comment",
        Ty::Word(&["parentheses", "semicolon"]),
        Check::Any,
        "comment syntax: `(text)` or `; text`",
    ),
    texts(
        "start",
        "lines before the header comments (`%`, `O{number}`, a program name line)",
    ),
    opt(
        "program_number",
        NUMBER,
        Check::Count,
        "the program number `{number}` stands for; default 1",
    ),
    texts(
        "lathe_setup",
        "the safe-start lines of a lathe program (plane, units, absolute, radius or diameter mode, cancels)",
    ),
    texts("mill_setup", "the safe-start lines of a mill program"),
    texts(
        "lathe_tool_call",
        "the blocks that call a lathe program's tool after its setup (`{tool}`, `{offset}`; `{tool:2}`, `{offset:2}` zero-padded to two digits: Fanuc's `T{tool:2}{offset:2}`); a lathe program is refused without them",
    ),
    texts(
        "mill_tool_call",
        "the blocks that call a mill program's tool after its setup (`T{tool} M6`, `G43 H{offset}`); a mill program is refused without them",
    ),
    texts(
        "path_tolerance",
        "lines that hold the controller's blending to `{tolerance}`; left out if absent",
    ),
    texts(
        "c_axis_on",
        "lines that switch the spindle to a position-controlled C axis before a C move",
    ),
    texts(
        "c_axis_off",
        "lines that give the spindle back after C moves",
    ),
    texts("end", "the blocks that end the program (`M2`, `M30`)"),
    texts(
        "trailer",
        "lines after the last block, written as they are (`%`)",
    ),
    req(
        "lathe_x",
        Ty::Word(&["radius", "diameter"]),
        Check::Any,
        "whether a lathe's X word is the radius or the diameter (the setup lines must select the same)",
    ),
    text("rapid", "the rapid-move word; default `G0`"),
    text("linear", "the linear-move word; default `G1`"),
    text("arc_cw", "the clockwise-arc word; default `G2`"),
    text("arc_ccw", "the counter-clockwise-arc word; default `G3`"),
    texts(
        "arc_planes",
        "planes the controller interpolates arcs in, of \"xy\" (G17), \"zx\" (G18), \"yz\" (G19); none: no arcs",
    ),
    req(
        "arc_centre",
        Ty::Word(&["incremental", "absolute"]),
        Check::Any,
        "arc centres I J K from the arc's start (`incremental`) or in work coordinates",
    ),
    texts(
        "surface_speed",
        "blocks that set constant surface speed before the spindle-on word (`{speed}` m/min, `{cap}` rpm); none: the controller cannot",
    ),
    text(
        "fts_table",
        "the extension of a fast-tool-servo table file (rows `C X W`: degrees, mm, mm) written beside the program; absent: the fast axis's motion is programmed on Z",
    ),
    texts(
        "fts_on",
        "blocks that arm the servo to follow its table, before the plunge (`{table}`: the table's file name)",
    ),
    texts(
        "fts_off",
        "blocks that release the servo after the last revolution",
    ),
    text(
        "part_call",
        "the block a main program calls a part of a split program with and returns (`{part}` its name, `{PART}` upper case, `{number}` its program number, `{k}` the part from 1); absent: the controller calls no parts, and a program larger than the machine's `delivery` allows is refused (see the delivery page of the language guide)",
    ),
    text(
        "part_name",
        "a part's name (`{job}`, `{JOB}`, `{k}`, `{number}`); default `{job}_{k}`",
    ),
    text(
        "part_extension",
        "a part file's extension; default the program's",
    ),
    texts(
        "part_start",
        "the lines that open a part file (`{part}`, `{PART}`, `{number}`, `{k}`)",
    ),
    texts(
        "part_end",
        "the lines that close a part file: its return to the main program",
    ),
    opt(
        "part_joins",
        Ty::Word(&["retract", "continuous"]),
        Check::Any,
        "where a part may end: `retract` (only where the tool is clear of the part, after a rapid: the control stops between parts) or `continuous` (between any two moves: the control reads through the call and the return without stopping the path); default retract",
    ),
    opt(
        "arc_radius_tolerance",
        LENGTH,
        Check::Positive,
        "the most an arc's end radius may differ from its start radius before the controller refuses it; default 0.001 mm (LinuxCNC allows about 0.025 mm, Beckhoff 0.005 mm); arcs are checked after rounding",
    ),
    text(
        "per_minute",
        "the word for feeds per minute; absent: not available",
    ),
    text(
        "per_revolution",
        "the word for feeds per revolution; absent: not available",
    ),
    text(
        "inverse_time",
        "the word for inverse-time feeds (F = 1/minutes of the move); absent: moves that turn the C axis cannot be timed",
    ),
    text(
        "spindle_on",
        "the word that starts the spindle clockwise; default `M3`",
    ),
    text(
        "spindle_ccw",
        "the word that starts the spindle counter-clockwise; default `M4`",
    ),
    text(
        "constant_rpm",
        "the word that cancels constant surface speed, written in the block of every constant-rpm start (`G97`: `G97 S1000 M3`); absent: none",
    ),
    texts(
        "spindle_orient",
        "the blocks that stop the spindle at a fixed angle and hold it, for a knife that cuts with the spindle still (`M19`)",
    ),
    texts(
        "blank_form",
        "blocks that state the workpiece blank for the control's graphic test run, where the strategy states one: `{x0}` `{y0}` `{z0}` its least corner and `{x1}` `{y1}` `{z1}` its greatest (mm), written after the setup (Heidenhain ISO's `G30 G17 X{x0} Y{y0} Z{z0}`, `G31 G90 X{x1} Y{y1} Z{z1}`; Klartext writes its `BLK FORM` itself); absent: no blank is stated",
    ),
    text(
        "coolant_flood",
        "the flood-coolant word (`M8`); absent: none",
    ),
    text("coolant_mist", "the mist-coolant word (`M7`); absent: none"),
    text(
        "coolant_off",
        "the word that stops the coolant (`M9`); absent: no coolant can be asked for",
    ),
    texts(
        "word_formats",
        "how each word's number is written: `S5` an integer word of at most 5 digits, written without a point; `X4.4` at most 4 digits before the point and 4 after, the point always written. Words without one follow the writer's defaults (axes to the machine's resolution, F to 6 decimals, S to 3, all with a point)",
    ),
    text("spindle_off", "the spindle-off word; default `M5`"),
    text("c_letter", "the spindle's C-axis letter; default `C`"),
    opt(
        "c_decimals",
        NUMBER,
        Check::Count,
        "decimals of C in degrees; default 5 (4 nm of arc at 25 mm)",
    ),
    opt(
        "max_decimals",
        NUMBER,
        Check::Count,
        "the most decimals a linear axis takes; a machine whose resolution needs more is refused",
    ),
    opt(
        "max_digits",
        NUMBER,
        Check::Count,
        "the most digits in one value (Fanuc: 8); a program needing more is refused",
    ),
    opt(
        "max_line_length",
        NUMBER,
        Check::Count,
        "the longest line the controller reads, in characters",
    ),
    opt(
        "line_numbers",
        NUMBER,
        Check::Count,
        "number each block `N…` in steps of this; absent: no numbers",
    ),
    opt(
        "max_line_number",
        NUMBER,
        Check::Count,
        "block numbers start again from the step after this",
    ),
    text(
        "block_end",
        "text closing every block (Heidenhain ISO: ` *`); default none",
    ),
    text(
        "gcode_system",
        "a Fanuc lathe's G-code system, as its parameter sets the control: `\"A\"` (G98/G99 feeds per minute and per revolution, `G50 S` the spindle clamp, G90 G92 G94 turning cycles, no G90/G91 words), `b` or `c` (G94/G95 feeds, `G92 S` the clamp, G90 absolute); lines may hold `{feeds}` (A: `G98`; B, C: `G90 G94`), `{clamp}` (A: `G50`; B, C: `G92`) and `{home}` (A: `G28 U0. W0.`; B, C: `G91 G28 X0. Z0.`), and `per_minute` and `per_revolution` default to the system's words; only for a lathe, and only A, B or C (E0176); absent: not a Fanuc lathe",
    ),
    opt(
        "spline",
        Ty::Word(&["none", "nurbs", "bspline"]),
        Check::Any,
        "the spline the controller interpolates that lensc writes: `nurbs` (Fanuc's G06.2: rank P, knots K, weights R, control points in X, Y and Z, docs/controllers/fanuc.md), `bspline` (Siemens' BSPLINE: degree SD, knot spacing PL, weights PW, docs/controllers/siemens.md) or `none` (the default: a job asking `interpolation: spline` is E0182)",
    ),
    text(
        "spline_option",
        "the control option the spline needs, named in the program's header and the set-up sheet; default none named",
    ),
    opt(
        "interpolation",
        Ty::Word(&["lines_arcs", "spline"]),
        Check::Any,
        "how a job that does not say is written: `lines_arcs` (the default) or `spline` (only where `spline` names one)",
    ),
    text(
        "length_offset",
        "words taking the tool's length offset in the block of the first move that states Z after the tool call (`G43 H{offset}`: Fanuc's G43 H with its Z move); default none (the tool call takes it)",
    ),
    opt(
        "surface_speed_feed",
        Ty::Word(&["stated", "per_revolution"]),
        Check::Any,
        "`per_revolution`: constant surface speed selects feed per revolution itself, and a feed-mode word would switch it off (Sinumerik: G94 G95 G96 G97 are one group), so none is written while it is on; default `stated` (the first feed after the spindle block states its mode)",
    ),
];

pub(super) const GCODE: Kind = Kind {
    name: "gcode",
    category: Category::Dialect,
    params: GCODE_PARAMS,
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a G-code (ISO 6983 family) program dialect: how one controller wants its programs written",
};

/// A line of a dialect's list as written, with where: what a message
/// about it points at.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    pub text: String,
    pub file: FileId,
    pub span: Span,
}

/// A checked `gcode { … }` dialect's parameters (`GCODE_PARAMS`), read
/// once, with the defaults their docs state: the only place they are named.
/// A text, word or list a declaration that did not check lacks reads as
/// its default (the checker has reported it).
#[derive(Clone, Debug, PartialEq)]
pub struct Gcode {
    /// `language: klartext`.
    pub klartext: bool,
    pub extension: String,
    /// `comment: semicolon` (else parentheses).
    pub semicolon_comments: bool,
    pub start: Vec<String>,
    pub program_number: u32,
    pub lathe_setup: Vec<String>,
    pub mill_setup: Vec<String>,
    pub lathe_tool_call: Vec<String>,
    pub mill_tool_call: Vec<String>,
    pub path_tolerance: Vec<String>,
    pub c_axis_on: Vec<String>,
    pub c_axis_off: Vec<String>,
    pub end: Vec<String>,
    pub trailer: Vec<String>,
    /// `lathe_x: diameter` (else radius).
    pub lathe_x_diameter: bool,
    pub rapid: String,
    pub linear: String,
    pub arc_cw: String,
    pub arc_ccw: String,
    /// As written: `"xy"`, `"zx"`, `"yz"`.
    pub arc_planes: Vec<String>,
    /// `arc_centre: absolute` (else incremental).
    pub arc_centre_absolute: bool,
    pub surface_speed: Vec<String>,
    pub fts_table: Option<String>,
    pub fts_on: Vec<String>,
    pub fts_off: Vec<String>,
    pub arc_radius_tolerance: f64,
    pub per_minute: Option<String>,
    pub per_revolution: Option<String>,
    pub inverse_time: Option<String>,
    pub spindle_on: String,
    pub spindle_ccw: String,
    pub constant_rpm: Option<String>,
    pub spindle_orient: Vec<String>,
    pub blank_form: Vec<String>,
    pub coolant_flood: Option<String>,
    pub coolant_mist: Option<String>,
    pub coolant_off: Option<String>,
    /// Each as written, with where (E0172 points at one that does not read).
    pub word_formats: Vec<Line>,
    pub spindle_off: String,
    pub c_letter: char,
    pub c_decimals: u32,
    pub max_decimals: Option<u32>,
    pub max_digits: Option<u32>,
    pub max_line_length: Option<usize>,
    pub line_numbers: Option<u64>,
    pub max_line_number: Option<u64>,
    pub block_end: String,
    /// A Fanuc lathe's G-code system as written (`"A"`, `"B"`, `"C"`;
    /// anything else is E0176).
    pub gcode_system: Option<String>,
    /// Words taking the tool's length offset with the first Z move.
    pub length_offset: String,
    /// `surface_speed_feed: per_revolution`.
    pub surface_speed_per_revolution: bool,
    /// `spline: nurbs`.
    pub nurbs: bool,
    /// `spline: bspline`.
    pub bspline: bool,
    pub spline_option: String,
    /// `interpolation: spline`.
    pub spline_by_default: bool,
    /// How a split program's parts are called (`part_call`; none: not).
    pub part_call: Option<String>,
    pub part_name: String,
    pub part_extension: Option<String>,
    pub part_start: Vec<String>,
    pub part_end: Vec<String>,
    /// `part_joins: continuous`.
    pub part_joins_continuous: bool,
}

impl Gcode {
    pub fn read(o: &Object) -> Gcode {
        let r = Reader::new(&o.fields);
        let opt_text = |n: &str| match r.field(n).map(|x| &x.value) {
            Some(Value::Str(s)) => Some(s.clone()),
            _ => None,
        };
        let text = |n: &str, default: &str| opt_text(n).unwrap_or_else(|| default.to_string());
        let written = |n: &str| -> Vec<Line> {
            match r.field(n) {
                Some(f) => match &f.value {
                    Value::List(items) => items
                        .iter()
                        .filter_map(|(v, span)| match v {
                            Value::Str(s) => Some(Line {
                                text: s.clone(),
                                file: f.file,
                                span: *span,
                            }),
                            _ => None,
                        })
                        .collect(),
                    _ => Vec::new(),
                },
                None => Vec::new(),
            }
        };
        let lines = |n: &str| -> Vec<String> { written(n).into_iter().map(|l| l.text).collect() };
        let count = |n: &str| r.num(n).map(|v| v as u64);
        Gcode {
            klartext: r.word("language") == Some("klartext"),
            extension: text("extension", "nc"),
            semicolon_comments: r.word("comment") == Some("semicolon"),
            start: lines("start"),
            program_number: count("program_number").unwrap_or(1) as u32,
            lathe_setup: lines("lathe_setup"),
            mill_setup: lines("mill_setup"),
            lathe_tool_call: lines("lathe_tool_call"),
            mill_tool_call: lines("mill_tool_call"),
            path_tolerance: lines("path_tolerance"),
            c_axis_on: lines("c_axis_on"),
            c_axis_off: lines("c_axis_off"),
            end: lines("end"),
            trailer: lines("trailer"),
            lathe_x_diameter: r.word("lathe_x") == Some("diameter"),
            rapid: text("rapid", "G0"),
            linear: text("linear", "G1"),
            arc_cw: text("arc_cw", "G2"),
            arc_ccw: text("arc_ccw", "G3"),
            arc_planes: lines("arc_planes"),
            arc_centre_absolute: r.word("arc_centre") == Some("absolute"),
            surface_speed: lines("surface_speed"),
            fts_table: opt_text("fts_table"),
            fts_on: lines("fts_on"),
            fts_off: lines("fts_off"),
            arc_radius_tolerance: r.num("arc_radius_tolerance").unwrap_or(0.001),
            per_minute: opt_text("per_minute"),
            per_revolution: opt_text("per_revolution"),
            inverse_time: opt_text("inverse_time"),
            spindle_on: text("spindle_on", "M3"),
            spindle_ccw: text("spindle_ccw", "M4"),
            constant_rpm: opt_text("constant_rpm"),
            spindle_orient: lines("spindle_orient"),
            blank_form: lines("blank_form"),
            coolant_flood: opt_text("coolant_flood"),
            coolant_mist: opt_text("coolant_mist"),
            coolant_off: opt_text("coolant_off"),
            word_formats: written("word_formats"),
            spindle_off: text("spindle_off", "M5"),
            c_letter: text("c_letter", "C").chars().next().unwrap_or('C'),
            c_decimals: count("c_decimals").unwrap_or(5) as u32,
            max_decimals: count("max_decimals").map(|v| v as u32),
            max_digits: count("max_digits").map(|v| v as u32),
            max_line_length: count("max_line_length").map(|v| v as usize),
            line_numbers: count("line_numbers"),
            max_line_number: count("max_line_number"),
            block_end: text("block_end", ""),
            gcode_system: opt_text("gcode_system"),
            length_offset: text("length_offset", ""),
            surface_speed_per_revolution: r.word("surface_speed_feed") == Some("per_revolution"),
            nurbs: r.word("spline") == Some("nurbs"),
            bspline: r.word("spline") == Some("bspline"),
            spline_option: text("spline_option", ""),
            spline_by_default: r.word("interpolation") == Some("spline"),
            part_call: opt_text("part_call"),
            part_name: text("part_name", "{job}_{k}"),
            part_extension: opt_text("part_extension"),
            part_start: lines("part_start"),
            part_end: lines("part_end"),
            part_joins_continuous: r.word("part_joins") == Some("continuous"),
        }
    }
}

/// A dialect a machine offers, with where the machine names it.
#[derive(Clone, Debug)]
pub struct OfferedDialect<'a> {
    pub dialect: &'a Rc<Object>,
    pub file: FileId,
    pub span: Span,
}

impl OfferedDialect<'_> {
    /// The name it was declared under, or its kind's.
    pub fn name(&self) -> String {
        self.dialect
            .name
            .clone()
            .unwrap_or_else(|| self.dialect.kind.name.to_string())
    }
}

/// The dialects a machine offers: its `dialect`, then each of its
/// `other_dialects` (the machine parameters that name dialects).
pub fn offered_dialects(machine: &Object) -> Vec<OfferedDialect<'_>> {
    let r = Reader::new(&machine.fields);
    let mut offered = Vec::new();
    if let Some(f) = r.field("dialect")
        && let Value::Object(dialect) = &f.value
    {
        offered.push(OfferedDialect {
            dialect,
            file: f.file,
            span: f.span,
        });
    }
    if let Some(f) = r.field("other_dialects")
        && let Value::List(items) = &f.value
    {
        offered.extend(items.iter().filter_map(|(v, span)| match v {
            Value::Object(dialect) => Some(OfferedDialect {
                dialect,
                file: f.file,
                span: *span,
            }),
            _ => None,
        }));
    }
    offered
}
