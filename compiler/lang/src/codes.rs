//! Every diagnostic code the compiler emits, with what it means. Syntax
//! codes (E0001–E0009) live in `lensc_grammar::diagnostic::codes`. A code is
//! never reused for another meaning.

pub const UNKNOWN_NAME: &str = "E0100";
pub const DUPLICATE_NAME: &str = "E0101";
pub const UNKNOWN_MODULE: &str = "E0102";
pub const CANNOT_READ: &str = "E0103";
pub const IMPORT_CYCLE: &str = "E0104";
pub const NOT_IN_MODULE: &str = "E0105";
pub const SELF_REFERENCE: &str = "E0106";
/// A `use` (or the file given with `--root`) that resolves, after
/// symlinks, outside the project root.
pub const OUTSIDE_ROOT: &str = "E0107";
/// A path that names a FIFO, device, socket or directory, not a regular file.
pub const NOT_A_FILE: &str = "E0108";
/// A file over the size limit of what lensc reads (16 MiB).
pub const FILE_TOO_LARGE: &str = "E0109";
pub const UNKNOWN_UNIT: &str = "E0110";
pub const DIMENSION_MISMATCH: &str = "E0111";
pub const BAD_ARGUMENT_DIMENSION: &str = "E0112";
pub const ARGUMENT_COUNT: &str = "E0113";
pub const BAD_EXPONENT: &str = "E0114";
pub const MATH_DOMAIN: &str = "E0115";
pub const NOT_CALLABLE: &str = "E0116";
pub const FORMULA_DIMENSION: &str = "E0117";
pub const UNKNOWN_COORDINATE: &str = "E0118";
pub const WRONG_VALUE: &str = "E0119";
pub const UNKNOWN_PARAMETER: &str = "E0120";
pub const MISSING_PARAMETER: &str = "E0121";
pub const PARAMETER_DIMENSION: &str = "E0122";
pub const OUT_OF_RANGE: &str = "E0123";
pub const WRONG_KIND: &str = "E0124";
pub const DUPLICATE_PARAMETER: &str = "E0125";
pub const UNKNOWN_WORD: &str = "E0126";
pub const CONIC_DOMAIN: &str = "E0127";
pub const CONFLICTING_PARAMETERS: &str = "E0128";
pub const DECLARATION_KIND: &str = "E0129";
pub const NO_JOB: &str = "E0130";
pub const UNSUPPORTED_COMBINATION: &str = "E0131";
pub const EMPTY_FILE: &str = "E0132";
pub const OUTSIDE_APERTURE: &str = "E0133";
pub const WRAP_OVERLAP: &str = "E0134";
/// A strategy kind that no planner builds (the registry of strategies
/// lists no folder for it).
pub const NO_SUCH_STRATEGY: &str = "E0135";
pub const NOSE_TOO_LARGE: &str = "E0140";
pub const OUT_OF_TRAVEL: &str = "E0141";
pub const FEED_TOO_HIGH: &str = "E0142";
pub const SPINDLE_TOO_FAST: &str = "E0143";
pub const UNDEFINED_ON_PATH: &str = "E0144";
pub const CLEARANCE_TOO_SMALL: &str = "E0145";
pub const STROKE_EXCEEDED: &str = "E0146";
pub const ACCELERATION_EXCEEDED: &str = "E0147";
pub const DIALECT_NOT_OFFERED: &str = "E0148";
pub const SIMULATION_TOO_LARGE: &str = "E0149";
pub const NOT_PRINTABLE: &str = "E0150";
pub const CANNOT_WRITE: &str = "E0151";
/// A job asks for more points than lensc plans for one job.
pub const TOO_MANY_POINTS: &str = "E0160";
/// A job's program would be larger than `--max-program-size`.
pub const PROGRAM_TOO_LARGE: &str = "E0161";
/// Roughing passes (a stock) without their own feed.
pub const ROUGHING_NEEDS_FEED: &str = "E0170";
/// A raster's spindle: a rotating cutter without a speed, or a knife
/// (which cuts with the spindle held) given one.
pub const RASTER_SPINDLE: &str = "E0171";
/// A dialect's word format that does not read (`S5`, `X4.4`).
pub const BAD_WORD_FORMAT: &str = "E0172";
/// A tool call or coolant the job asks for that its dialect cannot write
/// (a tool number too long for the T word, no mist word).
pub const CANNOT_CALL_TOOL: &str = "E0173";
/// A machine that is not a mill naming a Klartext dialect.
pub const KLARTEXT_ON_A_LATHE: &str = "E0174";
/// A G-code system (`gcode_system`, Fanuc lathes' A, B or C) on a
/// dialect chosen for a machine that is not a lathe: the code systems are
/// a lathe control's.
pub const GCODE_SYSTEM_NOT_OFFERED: &str = "E0176";
/// Constant surface speed asked of a machine whose dialect has none
/// (no `surface_speed` lines).
pub const NO_SURFACE_SPEED: &str = "E0177";
/// A tool's control point the job's dialect cannot program (a tip on a
/// fast-tool-servo lathe whose servo table states the nose centre).
pub const CONTROL_POINT_NOT_EXPRESSIBLE: &str = "E0178";
/// A path tolerance finer than the machine's resolution can hold.
pub const TOLERANCE_BELOW_RESOLUTION: &str = "E0180";
/// `interpolation: spline` where lensc writes no spline: the dialect has
/// none (in the path's plane), or the strategy is not fitted yet.
pub const SPLINE_NOT_OFFERED: &str = "E0182";
/// `lensc fmt` refused to write a layout that would not parse back to the
/// same program (a formatter bug; the file is left as it is).
pub const FORMAT_WOULD_CHANGE_MEANING: &str = "E0185";
/// A number with no finite value: an overflow (`1e308 * 1e308`), an
/// infinity or NaN.
pub const NOT_FINITE: &str = "E0186";
/// A surface whose sag has no value (NaN or infinite) somewhere over its
/// aperture (the square root of a negative number, a conic that closes).
pub const SURFACE_UNDEFINED: &str = "E0187";
/// A dialect's extension that gives the program the name of another file
/// the build writes beside it (`JOB.report.json`, a servo table, a plot).
pub const OUTPUT_NAME_RESERVED: &str = "E0188";
/// A project whose `use`s would load more than `loader::MAX_FILES` files.
pub const TOO_MANY_FILES: &str = "E0189";
/// A file under the project root with more than one name (a hard link):
/// another of its names may lie outside the root.
pub const HARD_LINKED: &str = "E0191";
/// `lensc import`: the file is not a prescription lensc reads (not a
/// `.zmx` or optiland JSON file, or a value in it that is not a number).
pub const IMPORT_UNREADABLE: &str = "E0350";
/// `lensc import`: not one surface of the file can be imported.
pub const IMPORT_NOTHING: &str = "E0351";
/// `lensc import`: a non-sequential Zemax design.
pub const IMPORT_NON_SEQUENTIAL: &str = "E0352";
/// `lensc import`: a surface with a number that has no finite value in
/// lensc's terms (a curvature so small its radius overflows, a value that
/// is infinite).
pub const IMPORT_NOT_FINITE: &str = "E0353";
/// `lensc import`: the `.lens` text would be over the 16 MiB lensc reads.
pub const IMPORT_TOO_LARGE: &str = "E0354";
/// `lensc measure`: the measurement file is not one lensc reads (an
/// unknown format, a malformed header or value, a variant not read).
pub const MEASURE_UNREADABLE: &str = "E0360";
/// `lensc measure`: the measurement file ends before the data its header
/// promises.
pub const MEASURE_TRUNCATED: &str = "E0361";
/// `lensc measure`: a checksum the measurement file carries does not
/// match its data.
pub const MEASURE_CHECKSUM: &str = "E0362";
/// `lensc measure`: the invalid-point mask leaves less than the stated
/// share of the measured aperture.
pub const MEASURE_TOO_LITTLE: &str = "E0363";
/// `lensc measure`: the measurement does not fit the job's surface: most
/// of it lies outside the aperture, or it departs from the design far
/// more than a part of it could (other units, another surface).
pub const MEASURE_MISMATCH: &str = "E0364";
/// `lensc measure`: the registration to the design did not converge.
pub const MEASURE_NOT_CONVERGED: &str = "E0365";
/// A job's `compensate` block: the corrected surface curves more tightly
/// (concave) than the tool's nose or ball can follow.
pub const COMPENSATE_CURVATURE: &str = "E0366";
/// A job's `compensate` block: the measurement does not cover enough of
/// the aperture for a correction of the order its smoothing length asks.
pub const COMPENSATE_UNFITTED: &str = "E0367";
/// A round nose's `edge_profile`: the file is not a list of angle and
/// deviation pairs (a line of something else, too few samples, angles
/// that do not increase).
pub const EDGE_UNREADABLE: &str = "E0374";
/// A round nose's `edge_profile`: its angles reach beyond the nose's arc,
/// or do not cover the angles at which the cut meets the nose, or the
/// cut cannot be compensated for it (a profile with corners, a `search`).
pub const EDGE_ANGLES: &str = "E0375";
/// A round nose's `edge_profile`: a deviation at or beyond the stated
/// share of the nose radius (the edge is then no round nose).
pub const EDGE_DEVIATION: &str = "E0376";
/// `lensc measure --per-lenslet`: the job's surface is not an array of
/// lenslets, or the measurement is not a map.
pub const PER_LENSLET_UNAVAILABLE: &str = "E0368";
/// `lensc measure --lenslet`: the array has no such lenslet (an index, or
/// a row or column, past its last).
pub const LENSLET_NOT_IN_ARRAY: &str = "E0369";
/// `lensc measure --lenslet`: the map's valid pixels, placed where the
/// field was said to lie, cover less than the stated share of the
/// lenslet's aperture.
pub const FIELD_MISSES_LENSLET: &str = "E0370";

/// The simulated part misses one of its job's acceptance criteria (the
/// message names which, by how much and where); no program is written.
pub const ACCEPTANCE_MISSED: &str = "E0195";
/// A job's acceptance criterion that its simulation cannot measure (a
/// tool shape the height map does not model, no servo model); no program
/// is written unless the job says `accept: none`.
pub const ACCEPTANCE_UNMEASURED: &str = "E0196";

pub const UNUSED: &str = "W0001";
pub const WRAP_GAP: &str = "W0002";
pub const SEAM_LEFT_UNCUT: &str = "W0003";
pub const CENTRE_LEFT_UNCUT: &str = "W0004";
/// A servo's data period keeps a spiral's chords from meeting their share
/// of the path tolerance.
pub const CHORDS_OVER_TOLERANCE: &str = "W0005";
/// A wrapped design whose two ends do not meet where the roller closes.
pub const SEAM_STEP: &str = "W0006";
/// A cutting time over a day, the job stating no `max_cutting_time`.
pub const CUTTING_TIME_IMPLAUSIBLE: &str = "W0030";
/// An approach at the cutting feed longer than half a minute.
pub const LONG_APPROACH_AT_FEED: &str = "W0031";
/// A quarter or more of the time at feed spent approaching the cut.
pub const AIR_CUTTING: &str = "W0032";
/// A program larger than the machine's `delivery` allows whose file limit
/// is smaller than one part's own lines (its opening and closing lines,
/// the modal words it restates) and one block.
pub const FILE_LIMIT_BELOW_PART: &str = "E0380";
/// A program larger than the machine's `delivery` allows with no join the
/// dialect can make within the file limit: a cut longer than the limit
/// where the control stops between parts.
pub const NO_SAFE_JOIN: &str = "E0381";
/// A program larger than the machine's `delivery` allows in a dialect that
/// calls no parts (no `part_call`, or numbered blocks).
pub const CANNOT_SPLIT: &str = "E0382";
/// A split program whose set of parts does not read back as the whole
/// program did (a fault of lensc's splitter: nothing is written).
pub const SPLIT_READS_DIFFERENTLY: &str = "E0383";
/// A program consuming more bytes per second while it cuts than the
/// machine's link delivers: the control would starve and stop on the part.
pub const LINK_TOO_SLOW: &str = "W0050";
/// `lensc measure --per-lenslet`: a lenslet the map reaches but that
/// cannot be registered (too few valid points under the mask, or a
/// registration that does not settle); the others are measured.
pub const LENSLET_NOT_REGISTERED: &str = "W0036";
/// `lensc measure --lenslet`: the field's valid pixels cover less than
/// 95 % of the lenslet's aperture (but at least `--min-valid`): its
/// figures describe the part measured.
pub const FIELD_PART_OF_LENSLET: &str = "W0037";
/// E0195 under `lensc build --accept=warn`: the program is written.
pub const ACCEPTANCE_MISSED_WARNING: &str = "W0020";
/// E0196 under `lensc build --accept=warn`: the program is written.
pub const ACCEPTANCE_UNMEASURED_WARNING: &str = "W0021";
/// E0187 as `lensc analyse` and `lensc sample` report it: the points with
/// no value are shown as NaN, the rest analysed.
pub const SURFACE_UNDEFINED_WARNING: &str = "W0022";
/// `lensc verify`: the program's `.lens` file (and the files it uses) no
/// longer hash to the value its header carries.
pub const SOURCE_CHANGED_WARNING: &str = "W0023";
/// `lensc verify`: the program's `.lens` file could not be found or read,
/// so its header hash was not checked.
pub const SOURCE_UNCHECKED_WARNING: &str = "W0024";
/// `lensc import`: a surface of a type (or form) lensc does not import.
pub const IMPORT_UNSUPPORTED_SURFACE: &str = "W0015";
/// `lensc import`: a parameter of an imported surface that is not carried over.
pub const IMPORT_PARAMETER_DROPPED: &str = "W0016";
/// `lensc import`: a surface with power but no semi-diameter to make its aperture from.
pub const IMPORT_NO_SEMI_DIAMETER: &str = "W0017";
/// `lensc import`: a decentre or tilt (a coordinate break) that is not applied.
pub const IMPORT_POSITION_IGNORED: &str = "W0018";
/// `lensc import`: the last surface, taken as the image surface, is curved
/// (a lens surface of a file cut short?).
pub const IMPORT_IMAGE_CURVED: &str = "W0040";

/// All codes, for the uniqueness test and the book's reference
/// (docs/reference/codes.md, generated by `reference`).
// Programs read back from their text (`lensc verify`, and `lensc build`
// before it writes a program): one code per rule of
// `lensc_runtime::reader::Rule`, E0300–E0349.
/// A comment never closed on its line.
pub const PROGRAM_UNCLOSED_COMMENT: &str = "E0300";
/// A line over the dialect's length limit.
pub const PROGRAM_LINE_TOO_LONG: &str = "E0301";
/// A letter, code or keyword the controller does not read.
pub const PROGRAM_UNKNOWN_WORD: &str = "E0302";
/// A word with no number after its letter.
pub const PROGRAM_MALFORMED_NUMBER: &str = "E0303";
/// A number with more digits than the controller reads.
pub const PROGRAM_TOO_MANY_DIGITS: &str = "E0304";
/// A number with more decimals than the controller reads.
pub const PROGRAM_TOO_MANY_DECIMALS: &str = "E0305";
/// A decimal point in a word read as a whole number.
pub const PROGRAM_DECIMAL_POINT: &str = "E0306";
/// Two codes of one modal group in a block.
pub const PROGRAM_SAME_MODAL_GROUP: &str = "E0307";
/// One address twice in a block.
pub const PROGRAM_REPEATED_WORD: &str = "E0308";
/// A feed move before the feed mode (G93/G94/G95) is stated.
pub const PROGRAM_NO_FEED_MODE: &str = "E0309";
/// A feed move with the spindle stopped.
pub const PROGRAM_SPINDLE_STOPPED: &str = "E0310";
/// A feed move with no F in force (every one in inverse time).
pub const PROGRAM_NO_FEED_RATE: &str = "E0311";
/// A cut before a tool call.
pub const PROGRAM_NO_TOOL: &str = "E0312";
/// A move outside the machine's travel.
pub const PROGRAM_OUTSIDE_TRAVEL: &str = "E0313";
/// A feed above the machine's limit.
pub const PROGRAM_FEED_TOO_HIGH: &str = "E0314";
/// A rapid across or into the material cut so far.
pub const PROGRAM_RAPID_INTO_PART: &str = "E0315";
/// An arc whose start and end radii differ beyond the controller's limit.
pub const PROGRAM_ARC_RADII: &str = "E0316";
/// An arc of zero radius.
pub const PROGRAM_ZERO_RADIUS_ARC: &str = "E0317";
/// An arc that ends where it starts: a full circle.
pub const PROGRAM_FULL_CIRCLE: &str = "E0318";
/// An arc's centre words not those of its plane, or none.
pub const PROGRAM_ARC_WORDS: &str = "E0319";
/// A move before units, distance mode or plane are stated.
pub const PROGRAM_MODAL_UNSTATED: &str = "E0320";
/// Axis words with no motion mode in force.
pub const PROGRAM_NO_MOTION_MODE: &str = "E0321";
/// A spindle start before G96 or G97 is stated.
pub const PROGRAM_SPINDLE_SPEED_MODE: &str = "E0322";
/// A spindle start with no speed.
pub const PROGRAM_NO_SPINDLE_SPEED: &str = "E0323";
/// A spindle speed or cap above the machine's.
pub const PROGRAM_SPINDLE_TOO_FAST: &str = "E0324";
/// Constant surface speed with no spindle speed limit.
pub const PROGRAM_NO_SPEED_CAP: &str = "E0325";
/// A block number missing or above the controller's limit.
pub const PROGRAM_BLOCK_NUMBER: &str = "E0326";
/// A block without the dialect's block end.
pub const PROGRAM_BLOCK_END: &str = "E0327";
/// A program with no end.
pub const PROGRAM_END: &str = "E0328";
/// A comment opened inside a comment.
pub const PROGRAM_NESTED_COMMENT: &str = "E0329";
/// Klartext: a block number out of sequence.
pub const PROGRAM_BLOCK_SEQUENCE: &str = "E0330";
/// Klartext: an arc before any circle centre.
pub const PROGRAM_NO_CIRCLE_CENTRE: &str = "E0331";
/// Klartext: the program not framed by `BEGIN PGM` and `END PGM` of one name.
pub const PROGRAM_FRAME: &str = "E0332";
/// A parameter word no code of its block uses (LinuxCNC, Fanuc, Sinumerik, Heidenhain ISO).
pub const PROGRAM_UNUSED_WORD: &str = "E0333";
/// An arc from a point the program never stated.
pub const PROGRAM_POSITION_UNKNOWN: &str = "E0334";
/// A block after the program's end (M2, M30), which is never run.
pub const PROGRAM_BLOCK_AFTER_END: &str = "E0335";
/// A spline block the controller refuses (Fanuc G06.2: its rank, knots,
/// weights, a block without its knot, a curve cut short or not starting
/// where the tool is).
pub const PROGRAM_SPLINE_REFUSED: &str = "E0340";
/// M99 in a LinuxCNC main program: the program again from the top, for ever.
pub const PROGRAM_MAIN_LOOP: &str = "E0336";
/// A LinuxCNC NURBS block (G5.2) left without its G5.3: never cut.
pub const PROGRAM_NURBS_NOT_CUT: &str = "E0337";
/// A weight not above zero in the first block of a LinuxCNC NURBS block.
pub const PROGRAM_NURBS_WEIGHT: &str = "E0338";

/// A fast-tool-servo table (`lensc verify`) with a row that is not three
/// numbers C X W, or whose C runs backwards.
pub const SERVO_TABLE_ROW: &str = "E0190";
/// A fast tool servo with no feed-forward whose lead, the command lensc
/// writes for it, would exceed its stroke or drive it beyond its
/// acceleration.
pub const LEAD_REFUSED: &str = "E0192";

/// The code of a rule a program read back breaks.
pub fn program_rule(rule: lensc_runtime::reader::Rule) -> &'static str {
    use lensc_runtime::reader::Rule::*;
    match rule {
        UnclosedComment => PROGRAM_UNCLOSED_COMMENT,
        LineTooLong => PROGRAM_LINE_TOO_LONG,
        UnknownWord => PROGRAM_UNKNOWN_WORD,
        MalformedNumber => PROGRAM_MALFORMED_NUMBER,
        TooManyDigits => PROGRAM_TOO_MANY_DIGITS,
        TooManyDecimals => PROGRAM_TOO_MANY_DECIMALS,
        DecimalPoint => PROGRAM_DECIMAL_POINT,
        SameModalGroup => PROGRAM_SAME_MODAL_GROUP,
        RepeatedWord => PROGRAM_REPEATED_WORD,
        NoFeedMode => PROGRAM_NO_FEED_MODE,
        SpindleStopped => PROGRAM_SPINDLE_STOPPED,
        NoFeedRate => PROGRAM_NO_FEED_RATE,
        NoTool => PROGRAM_NO_TOOL,
        OutsideTravel => PROGRAM_OUTSIDE_TRAVEL,
        FeedTooHigh => PROGRAM_FEED_TOO_HIGH,
        RapidIntoPart => PROGRAM_RAPID_INTO_PART,
        ArcRadiusMismatch => PROGRAM_ARC_RADII,
        ZeroRadiusArc => PROGRAM_ZERO_RADIUS_ARC,
        FullCircle => PROGRAM_FULL_CIRCLE,
        ArcWords => PROGRAM_ARC_WORDS,
        ModalStateUnstated => PROGRAM_MODAL_UNSTATED,
        NoMotionMode => PROGRAM_NO_MOTION_MODE,
        SpindleSpeedMode => PROGRAM_SPINDLE_SPEED_MODE,
        NoSpindleSpeed => PROGRAM_NO_SPINDLE_SPEED,
        SpindleTooFast => PROGRAM_SPINDLE_TOO_FAST,
        NoSpeedCap => PROGRAM_NO_SPEED_CAP,
        BlockNumber => PROGRAM_BLOCK_NUMBER,
        BlockEnd => PROGRAM_BLOCK_END,
        ProgramEnd => PROGRAM_END,
        NestedComment => PROGRAM_NESTED_COMMENT,
        BlockSequence => PROGRAM_BLOCK_SEQUENCE,
        NoCircleCentre => PROGRAM_NO_CIRCLE_CENTRE,
        ProgramFrame => PROGRAM_FRAME,
        UnusedWord => PROGRAM_UNUSED_WORD,
        PositionUnknown => PROGRAM_POSITION_UNKNOWN,
        BlockAfterEnd => PROGRAM_BLOCK_AFTER_END,
        SplineRefused => PROGRAM_SPLINE_REFUSED,
        MainProgramLoop => PROGRAM_MAIN_LOOP,
        NurbsNotCut => PROGRAM_NURBS_NOT_CUT,
        NurbsWeight => PROGRAM_NURBS_WEIGHT,
    }
}

pub const ALL: &[&str] = &[
    UNKNOWN_NAME,
    DUPLICATE_NAME,
    UNKNOWN_MODULE,
    CANNOT_READ,
    IMPORT_CYCLE,
    NOT_IN_MODULE,
    SELF_REFERENCE,
    OUTSIDE_ROOT,
    NOT_A_FILE,
    FILE_TOO_LARGE,
    UNKNOWN_UNIT,
    DIMENSION_MISMATCH,
    BAD_ARGUMENT_DIMENSION,
    ARGUMENT_COUNT,
    BAD_EXPONENT,
    MATH_DOMAIN,
    NOT_CALLABLE,
    FORMULA_DIMENSION,
    UNKNOWN_COORDINATE,
    WRONG_VALUE,
    UNKNOWN_PARAMETER,
    MISSING_PARAMETER,
    PARAMETER_DIMENSION,
    OUT_OF_RANGE,
    WRONG_KIND,
    DUPLICATE_PARAMETER,
    UNKNOWN_WORD,
    CONIC_DOMAIN,
    CONFLICTING_PARAMETERS,
    DECLARATION_KIND,
    NO_JOB,
    UNSUPPORTED_COMBINATION,
    EMPTY_FILE,
    OUTSIDE_APERTURE,
    WRAP_OVERLAP,
    NO_SUCH_STRATEGY,
    WRAP_GAP,
    NOSE_TOO_LARGE,
    OUT_OF_TRAVEL,
    FEED_TOO_HIGH,
    SPINDLE_TOO_FAST,
    UNDEFINED_ON_PATH,
    CLEARANCE_TOO_SMALL,
    STROKE_EXCEEDED,
    ACCELERATION_EXCEEDED,
    DIALECT_NOT_OFFERED,
    SIMULATION_TOO_LARGE,
    NOT_PRINTABLE,
    CANNOT_WRITE,
    TOO_MANY_POINTS,
    PROGRAM_TOO_LARGE,
    ROUGHING_NEEDS_FEED,
    RASTER_SPINDLE,
    BAD_WORD_FORMAT,
    CANNOT_CALL_TOOL,
    KLARTEXT_ON_A_LATHE,
    GCODE_SYSTEM_NOT_OFFERED,
    NO_SURFACE_SPEED,
    CONTROL_POINT_NOT_EXPRESSIBLE,
    TOLERANCE_BELOW_RESOLUTION,
    SPLINE_NOT_OFFERED,
    ACCEPTANCE_MISSED,
    ACCEPTANCE_UNMEASURED,
    FILE_LIMIT_BELOW_PART,
    NO_SAFE_JOIN,
    CANNOT_SPLIT,
    SPLIT_READS_DIFFERENTLY,
    LINK_TOO_SLOW,
    UNUSED,
    SEAM_LEFT_UNCUT,
    CENTRE_LEFT_UNCUT,
    CHORDS_OVER_TOLERANCE,
    SEAM_STEP,
    CUTTING_TIME_IMPLAUSIBLE,
    LONG_APPROACH_AT_FEED,
    AIR_CUTTING,
    FORMAT_WOULD_CHANGE_MEANING,
    NOT_FINITE,
    SURFACE_UNDEFINED,
    OUTPUT_NAME_RESERVED,
    TOO_MANY_FILES,
    HARD_LINKED,
    IMPORT_UNREADABLE,
    IMPORT_NOTHING,
    IMPORT_NON_SEQUENTIAL,
    IMPORT_NOT_FINITE,
    IMPORT_TOO_LARGE,
    MEASURE_UNREADABLE,
    MEASURE_TRUNCATED,
    MEASURE_CHECKSUM,
    MEASURE_TOO_LITTLE,
    MEASURE_MISMATCH,
    MEASURE_NOT_CONVERGED,
    COMPENSATE_CURVATURE,
    COMPENSATE_UNFITTED,
    EDGE_UNREADABLE,
    EDGE_ANGLES,
    EDGE_DEVIATION,
    PER_LENSLET_UNAVAILABLE,
    LENSLET_NOT_IN_ARRAY,
    FIELD_MISSES_LENSLET,
    LENSLET_NOT_REGISTERED,
    FIELD_PART_OF_LENSLET,
    IMPORT_UNSUPPORTED_SURFACE,
    IMPORT_PARAMETER_DROPPED,
    IMPORT_NO_SEMI_DIAMETER,
    IMPORT_POSITION_IGNORED,
    IMPORT_IMAGE_CURVED,
    PROGRAM_UNCLOSED_COMMENT,
    PROGRAM_LINE_TOO_LONG,
    PROGRAM_UNKNOWN_WORD,
    PROGRAM_MALFORMED_NUMBER,
    PROGRAM_TOO_MANY_DIGITS,
    PROGRAM_TOO_MANY_DECIMALS,
    PROGRAM_DECIMAL_POINT,
    PROGRAM_SAME_MODAL_GROUP,
    PROGRAM_REPEATED_WORD,
    PROGRAM_NO_FEED_MODE,
    PROGRAM_SPINDLE_STOPPED,
    PROGRAM_NO_FEED_RATE,
    PROGRAM_NO_TOOL,
    PROGRAM_OUTSIDE_TRAVEL,
    PROGRAM_FEED_TOO_HIGH,
    PROGRAM_RAPID_INTO_PART,
    PROGRAM_ARC_RADII,
    PROGRAM_ZERO_RADIUS_ARC,
    PROGRAM_FULL_CIRCLE,
    PROGRAM_ARC_WORDS,
    PROGRAM_MODAL_UNSTATED,
    PROGRAM_NO_MOTION_MODE,
    PROGRAM_SPINDLE_SPEED_MODE,
    PROGRAM_NO_SPINDLE_SPEED,
    PROGRAM_SPINDLE_TOO_FAST,
    PROGRAM_NO_SPEED_CAP,
    PROGRAM_BLOCK_NUMBER,
    PROGRAM_BLOCK_END,
    PROGRAM_END,
    PROGRAM_NESTED_COMMENT,
    PROGRAM_BLOCK_SEQUENCE,
    PROGRAM_NO_CIRCLE_CENTRE,
    PROGRAM_FRAME,
    PROGRAM_UNUSED_WORD,
    PROGRAM_POSITION_UNKNOWN,
    PROGRAM_BLOCK_AFTER_END,
    PROGRAM_SPLINE_REFUSED,
    PROGRAM_MAIN_LOOP,
    PROGRAM_NURBS_NOT_CUT,
    PROGRAM_NURBS_WEIGHT,
    SERVO_TABLE_ROW,
    LEAD_REFUSED,
    ACCEPTANCE_MISSED_WARNING,
    ACCEPTANCE_UNMEASURED_WARNING,
    SURFACE_UNDEFINED_WARNING,
    SOURCE_CHANGED_WARNING,
    SOURCE_UNCHECKED_WARNING,
];

#[cfg(test)]
mod tests {
    #[test]
    fn codes_are_unique() {
        let mut all = super::ALL.to_vec();
        all.sort_unstable();
        let n = all.len();
        all.dedup();
        assert_eq!(n, all.len());
    }
}
