//! A controller's dialect as data: the lines around the moves, the words
//! and the limits of its number format.

use crate::moves::Plane;

/// How a dialect writes comments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommentStyle {
    /// `(text)`: RS274NGC, Fanuc, most ISO controllers.
    Parentheses,
    /// `; text`: Siemens, Heidenhain.
    Semicolon,
}

/// A controller's G-code dialect, as data (declared in `stdlib/dialects.lens`
/// or a shop's own file): the lines around the moves, the words, the
/// limits of its number format. Lines may hold `{job}`, `{JOB}`,
/// `{number}` and `{tolerance}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Dialect {
    pub name: String,
    /// Program file extension, without the dot.
    pub extension: String,
    pub comment: CommentStyle,
    /// Lines before the header comments.
    pub start: Vec<String>,
    pub program_number: u32,
    pub lathe_setup: Vec<String>,
    pub mill_setup: Vec<String>,
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
    pub spindle_on: String,
    pub spindle_off: String,
    pub c_letter: char,
    pub c_decimals: u32,
    pub max_decimals: Option<u32>,
    pub max_digits: Option<u32>,
    pub max_line_length: Option<usize>,
    /// Block numbers `N…` in steps of this.
    pub line_numbers: Option<u64>,
    pub max_line_number: Option<u64>,
    pub block_end: String,
}

impl Dialect {
    /// LinuxCNC's RS274NGC as `stdlib/dialects.lens` declares it, for the
    /// runtime's own tests and benchmarks.
    pub fn linuxcnc() -> Dialect {
        let lines = |l: &[&str]| l.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        Dialect {
            name: "linuxcnc".into(),
            extension: "ngc".into(),
            comment: CommentStyle::Parentheses,
            start: Vec::new(),
            program_number: 1,
            lathe_setup: lines(&["G18 G21 G90 G8 G40 G49 G80"]),
            mill_setup: lines(&["G17 G21 G90 G40 G49 G80"]),
            path_tolerance: lines(&["G64 P{tolerance}"]),
            c_axis_on: Vec::new(),
            c_axis_off: Vec::new(),
            surface_speed: vec!["G96 D{cap} S{speed}".into()],
            fts_table: None,
            fts_on: Vec::new(),
            fts_off: Vec::new(),
            end: lines(&["M2"]),
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
            spindle_off: "M5".into(),
            c_letter: 'C',
            c_decimals: 5,
            max_decimals: None,
            max_digits: None,
            max_line_length: Some(255),
            line_numbers: None,
            max_line_number: None,
            block_end: String::new(),
        }
    }
}
