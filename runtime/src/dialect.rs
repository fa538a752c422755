//! A controller's dialect as data: the lines around the moves, the words,
//! the format of each word's number, and how a program starts (modal
//! state, tool call, spindle, coolant) and ends.

use crate::moves::Plane;

/// How a dialect writes comments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommentStyle {
    /// `(text)`: RS274NGC, Fanuc, most ISO controllers.
    Parentheses,
    /// `; text`: Siemens, Heidenhain.
    Semicolon,
}

/// The language a dialect's programs are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Language {
    /// ISO 6983 address words (`G1 X1. F100.`): every dialect but one.
    #[default]
    GCode,
    /// Heidenhain's conversational language (`L X+1 R0 F100`,
    /// `CC X+0 Y+0`, `C X+1 Y+0 DR-`, `TOOL CALL 1 Z`, `BEGIN PGM`):
    /// TNC mills only. Blocks are numbered from 0 without a letter; the
    /// program opens with `BEGIN PGM {JOB} MM` (the `start` lines) and
    /// closes with `END PGM {JOB} MM` (the `trailer`), both numbered.
    Klartext,
}

/// A controller's G-code dialect, as data (declared in `stdlib/dialects.lens`
/// or a shop's own file): the lines around the moves, the words, the
/// limits of its number format. Lines may hold `{job}`, `{JOB}`,
/// `{number}` and `{tolerance}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Dialect {
    pub name: String,
    pub language: Language,
    /// Program file extension, without the dot.
    pub extension: String,
    pub comment: CommentStyle,
    /// Lines before the header comments.
    pub start: Vec<String>,
    pub program_number: u32,
    pub lathe_setup: Vec<String>,
    pub mill_setup: Vec<String>,
    /// Blocks that call the tool after the setup (`{tool}`, `{offset}`,
    /// `{tool:2}` and `{offset:2}` zero-padded to two digits).
    pub lathe_tool_call: Vec<String>,
    pub mill_tool_call: Vec<String>,
    /// Lines holding the controller's blending to `{tolerance}`.
    pub path_tolerance: Vec<String>,
    pub c_axis_on: Vec<String>,
    pub c_axis_off: Vec<String>,
    /// Blocks that set constant surface speed (`{speed}` in m/min,
    /// `{cap}` the spindle's limit in rpm), before the spindle-on word;
    /// none: the controller cannot.
    pub surface_speed: Vec<String>,
    /// The extension of a fast-tool-servo table file, if the controller
    /// takes the fast axis's motion as a table beside the program.
    pub fts_table: Option<String>,
    /// Blocks arming and releasing the servo's table (`{table}`: its file).
    pub fts_on: Vec<String>,
    pub fts_off: Vec<String>,
    /// Blocks that end the program (`M30`).
    pub end: Vec<String>,
    /// Lines after the last block, as written (`%`).
    pub trailer: Vec<String>,
    /// A lathe's X word is the diameter (arc centres stay radii).
    pub lathe_x_diameter: bool,
    pub rapid: String,
    pub linear: String,
    pub arc_cw: String,
    pub arc_ccw: String,
    pub arc_planes: Vec<Plane>,
    /// Arc centres in work coordinates rather than from the arc's start.
    pub arc_centre_absolute: bool,
    /// The most (mm) an arc's end radius may differ from its start radius,
    /// as the controller checks it after rounding.
    pub arc_radius_tolerance: f64,
    pub per_minute: Option<String>,
    pub per_revolution: Option<String>,
    pub inverse_time: Option<String>,
    /// Spindle on clockwise (M3) and counter-clockwise (M4).
    pub spindle_on: String,
    pub spindle_ccw: String,
    pub spindle_off: String,
    /// The word that cancels constant surface speed, written in the block
    /// of a constant-rpm start (`G97 S1000 M3`); none: the controller has
    /// no constant surface speed to cancel.
    pub constant_rpm: Option<String>,
    /// Blocks that stop the spindle at a fixed angle and hold it there,
    /// for a tool that cuts with the spindle still (a shaping knife).
    pub spindle_orient: Vec<String>,
    /// Blocks stating the workpiece blank for the control's graphic test
    /// run (`{x0}` `{y0}` `{z0}` its least corner, `{x1}` `{y1}` `{z1}` its
    /// greatest, mm), written after the setup where the program states a
    /// blank (`Start::blank`); Klartext writes `BLK FORM` itself.
    pub blank_form: Vec<String>,
    /// Coolant words: flood, mist and off; none: the controller has none.
    pub coolant_flood: Option<String>,
    pub coolant_mist: Option<String>,
    pub coolant_off: Option<String>,
    /// How each word's number is written (`S5`: an integer of at most five
    /// digits, no point; `X4.4`: at most four digits before the point and
    /// four after, the point always written). Words without one follow
    /// the writer's defaults.
    pub word_formats: Vec<WordFormat>,
    pub c_letter: char,
    pub c_decimals: u32,
    pub max_decimals: Option<u32>,
    pub max_digits: Option<u32>,
    pub max_line_length: Option<usize>,
    /// Block numbers `N…` in steps of this.
    pub line_numbers: Option<u64>,
    pub max_line_number: Option<u64>,
    pub block_end: String,
    /// Fanuc lathes: the G-code system (A, B or C) the control is set to;
    /// the reader takes its words (system A: G98/G99 feeds, G50 S clamp,
    /// G90 G92 G94 turning cycles; B and C: G94/G95 feeds, G92 S clamp,
    /// G90/G91 distance). None: not a Fanuc lathe's setting.
    pub gcode_system: Option<GcodeSystem>,
    /// Words that take the tool's length offset, written in the block of
    /// the first move that states Z after the tool call (`G43 H{offset}`
    /// on a Fanuc mill); empty: the tool call takes it.
    pub length_offset: String,
    /// Whether constant surface speed selects feed per revolution itself
    /// (Sinumerik: "G95 is activated automatically with G96", and G94 or
    /// G95 would switch it off): no feed-mode word is written while it is
    /// on, and a feed per minute under it is refused.
    pub surface_speed_per_revolution: bool,
    /// The spline the controller interpolates and lensc writes (none:
    /// lines and arcs only).
    pub spline: Option<SplineForm>,
    /// The control option the spline needs, for the header and the
    /// set-up sheet (empty: none named).
    pub spline_option: String,
    /// Whether a job that does not say writes splines (`interpolation:
    /// spline` as the dialect's default).
    pub spline_by_default: bool,
    /// How a program too large for the control is delivered as parts a
    /// main program calls (none: the controller calls no parts, and a
    /// program that does not fit is refused).
    pub parts: Option<PartCalls>,
}

/// How a dialect's main program calls the parts of a split program, and
/// how each part file opens and closes. Lines may hold `{part}` (the
/// part's name), `{PART}` (upper case), `{number}` (its program number:
/// the program's number plus the part's) and `{k}` (the part, from 1).
#[derive(Clone, Debug, PartialEq)]
pub struct PartCalls {
    /// The block of the main program that runs a part and returns
    /// (`M198 P{number}`, `EXTCALL "{PART}"`, `O<{part}> call`).
    pub call: String,
    /// A part's name (`{job}_{k}`; `{job}`, `{JOB}`, `{k}`, `{number}`).
    pub name: String,
    /// A part file's extension, without the dot.
    pub extension: String,
    /// The lines that open a part file.
    pub start: Vec<String>,
    /// The lines that close it (its return to the main program).
    pub end: Vec<String>,
    /// Whether the control passes from one part to the next without
    /// stopping the path (its look-ahead reads through the call and the
    /// return): then a part may end anywhere between two moves; if not,
    /// only where the tool is clear of the part, after a rapid.
    pub continuous: bool,
}

/// A controller's spline, as lensc writes and reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplineForm {
    /// Fanuc's NURBS interpolation, G06.2: rank P, knots K, weights R,
    /// control points in any of X, Y, Z (docs/controllers/fanuc.md).
    Nurbs,
    /// Siemens' B spline, BSPLINE: degree SD, knot spacing PL, weights
    /// PW, the tool's position the first control point
    /// (docs/controllers/siemens.md).
    Bspline,
}

/// A Fanuc lathe's G-code system (parameter-selected on the control).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GcodeSystem {
    A,
    B,
    C,
}

/// How one word's number is written, as a dialect states it (`S5`,
/// `X4.4`): its letter, the most digits before the point, and the most
/// after it, or `None` for an integer word written without a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WordFormat {
    pub letter: char,
    pub integer_digits: u32,
    pub decimals: Option<u32>,
}

impl WordFormat {
    /// Reads `S5` or `X4.4`, or says what is wrong with it.
    pub fn parse(text: &str) -> Result<WordFormat, String> {
        let mut chars = text.chars();
        let letter = chars
            .next()
            .filter(|c| c.is_ascii_uppercase())
            .ok_or_else(|| format!("`{text}` does not start with an upper-case word letter"))?;
        let rest = chars.as_str();
        let digits = |s: &str| {
            (!s.is_empty() && s.len() <= 2 && s.bytes().all(|b| b.is_ascii_digit()))
                .then(|| s.parse::<u32>().ok())
                .flatten()
        };
        let bad = || {
            format!(
                "`{text}` is not a word format: a letter, the most digits before the point and, for a word written with a point, `.` and the most after it (`S5`, `X4.4`)"
            )
        };
        let (integer_digits, decimals) = match rest.split_once('.') {
            None => (digits(rest).ok_or_else(bad)?, None),
            Some((i, d)) => (
                digits(i).ok_or_else(bad)?,
                Some(digits(d).filter(|&d| d <= 9).ok_or_else(bad)?),
            ),
        };
        if integer_digits == 0 || integer_digits > 18 {
            return Err(bad());
        }
        Ok(WordFormat {
            letter,
            integer_digits,
            decimals,
        })
    }
}

impl Dialect {
    /// The format the dialect gives the word `letter`, if any.
    pub fn format_of(&self, letter: char) -> Option<WordFormat> {
        self.word_formats
            .iter()
            .copied()
            .find(|f| f.letter == letter)
    }

    /// LinuxCNC's RS274NGC as `stdlib/dialects.lens` declares it, for the
    /// runtime's own tests and benchmarks.
    pub fn linuxcnc() -> Dialect {
        let lines = |l: &[&str]| l.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        Dialect {
            name: "linuxcnc".into(),
            language: Language::GCode,
            extension: "ngc".into(),
            comment: CommentStyle::Parentheses,
            start: Vec::new(),
            program_number: 1,
            lathe_setup: lines(&["G18 G21 G90 G8 G40 G49 G80 G94 G54"]),
            mill_setup: lines(&["G17 G21 G90 G40 G49 G80 G94 G54"]),
            lathe_tool_call: lines(&["T{tool} M6 G43"]),
            mill_tool_call: lines(&["T{tool} M6 G43 H{offset}"]),
            path_tolerance: lines(&["G64 P{tolerance}"]),
            c_axis_on: Vec::new(),
            c_axis_off: Vec::new(),
            surface_speed: vec!["G96 D{cap} S{speed}".into()],
            fts_table: None,
            fts_on: Vec::new(),
            fts_off: Vec::new(),
            end: lines(&["G53 G0 Z0", "M2"]),
            trailer: Vec::new(),
            lathe_x_diameter: false,
            rapid: "G0".into(),
            linear: "G1".into(),
            arc_cw: "G2".into(),
            arc_ccw: "G3".into(),
            arc_planes: vec![Plane::Xy, Plane::Zx, Plane::Yz],
            arc_centre_absolute: false,
            arc_radius_tolerance: 0.001,
            per_minute: Some("G94".into()),
            per_revolution: Some("G95".into()),
            inverse_time: Some("G93".into()),
            spindle_on: "M3".into(),
            spindle_ccw: "M4".into(),
            spindle_off: "M5".into(),
            constant_rpm: Some("G97".into()),
            spindle_orient: lines(&["M19 R0"]),
            blank_form: Vec::new(),
            coolant_flood: Some("M8".into()),
            coolant_mist: Some("M7".into()),
            coolant_off: Some("M9".into()),
            word_formats: ["S5", "T3", "M3", "H3"]
                .iter()
                .map(|f| WordFormat::parse(f).expect("LinuxCNC's word formats"))
                .collect(),
            c_letter: 'C',
            c_decimals: 5,
            max_decimals: None,
            max_digits: None,
            max_line_length: Some(252),
            line_numbers: None,
            max_line_number: None,
            block_end: String::new(),
            gcode_system: None,
            length_offset: String::new(),
            surface_speed_per_revolution: false,
            spline: None,
            spline_option: String::new(),
            spline_by_default: false,
            parts: None,
        }
    }
}
