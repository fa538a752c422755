//! The `gcode` dialect kind: everything a post-processor needs to know
//! about a controller, as data.

use super::{Category, Check, Kind, LENGTH, NUMBER, Param, Ty, opt, req};

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
