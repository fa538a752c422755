//! The controller's modal state, block by block: units, plane, absolute or
//! incremental, feed mode and feed, spindle (on, speed, constant surface
//! speed and its cap, position mode), the tool called, X as a diameter or
//! a radius; the words of each block sorted into their modal groups and
//! applied in the controller's order (modes, then spindle, then the move,
//! then the program's end). The moves themselves are `motion`'s.

use super::klartext::Klartext;
use super::lexer::{Block, Found, KeywordKind, Lexer, SiemensWord, Word};
use super::{Controller, MachineLimits, Rule};
use crate::dialect::Dialect;
use crate::moves::Plane;

mod fast;
mod nurbs_block;
mod word_use;

/// How F is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum FeedMode {
    PerMinute,
    PerRevolution,
    InverseTime,
}

/// The motion modes a program may leave in force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Motion {
    Rapid,
    Linear,
    Cw,
    Ccw,
    /// G80: canned cycles off, in LinuxCNC the motion mode "none".
    Cancel,
    /// LinuxCNC's G5 and G5.1 (`spline`).
    Spline(super::spline::Spline),
    /// Fanuc's G06.2 (`nurbs`), where the dialect has it.
    Nurbs,
    /// LinuxCNC's G5.2, its NURBS block open (`nurbs_block`).
    NurbsBlock,
    /// LinuxCNC's G5.3, which closes the NURBS block and leaves no motion
    /// mode in force.
    NurbsBlockEnd,
    /// Siemens' BSPLINE (`bspline.rs`).
    Bspline,
}

/// The modal group of a G code (value × 10, `G05.1` is 51).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum GGroup {
    Motion(Motion),
    Plane(Plane),
    Distance(bool),
    Feed(FeedMode),
    Units(bool),
    CutterComp,
    ToolLength,
    Diameter(bool),
    PathControl,
    SpindleMode(bool),
    SpindleCap,
    NonModal,
    WorkOffset,
    Cycle,
    /// G28 (reference point), G53 (machine coordinates): the move goes to
    /// a position of the machine's, not of the program's.
    MachineMove,
    /// Heidenhain ISO's G36 (cycle 13 ORIENTATION): the spindle stopped and
    /// held at the angle its S word gives (degrees, not a speed).
    Orient,
    /// Heidenhain ISO's G30 and G31: the workpiece blank's least and
    /// greatest corner (BLK FORM) for the graphic test run; their X Y Z
    /// are the blank's, not a move.
    BlankForm,
}

/// What an M code does, for this dialect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum MCode {
    SpindleOn,
    SpindleOff,
    PositionOn,
    PositionOff,
    /// Spindle orientation (M19 on LinuxCNC, Fanuc mills, Heidenhain):
    /// stopped and held at an angle, as a knife cuts.
    Orient,
    ToolChange,
    End,
    Stop,
    Coolant,
    Other,
    /// Heidenhain's M91: the block's coordinates are the machine's.
    MachinePosition,
    /// LinuxCNC's M99 in a main program: back to the first block, for
    /// ever; the reader reads no further (as at an end).
    Loop,
}

/// The state of a program being read.
pub(crate) struct State {
    pub lex: Lexer,
    pub machine: MachineLimits,
    pub arc_tolerance: f64,
    pub arc_planes: Vec<Plane>,
    pub arc_centre_absolute: bool,
    dialect_m: Vec<(i64, MCode)>,
    feed_codes: Vec<(i64, FeedMode)>,
    max_line_number: Option<u64>,
    numbered: bool,
    /// A Fanuc lathe's G-code system A: G90 and G94 are turning cycles,
    /// positions absolute by X Z (incremental U W).
    system_a: bool,
    /// Whether the spindle-speed mode must be stated before a start.
    css_capable: bool,
    // The modal state.
    pub metric: Option<bool>,
    pub plane: Option<Plane>,
    pub absolute: Option<bool>,
    pub feed_mode: Option<FeedMode>,
    pub motion: Option<Motion>,
    pub feed: Option<f64>,
    /// G96 (true) or G97 (false), once stated.
    pub css: Option<bool>,
    pub css_speed: Option<f64>,
    pub cap: Option<f64>,
    pub rpm: Option<f64>,
    pub spindle_on: bool,
    /// The spindle held in position control, turned by C moves.
    pub position_mode: bool,
    tool_selected: bool,
    pub tool_loaded: bool,
    pub diameter: bool,
    /// X (radius), Y, Z (mm), C (degrees), where known.
    pub pos: [Option<f64>; 4],
    /// The fast tool servo on its own letter (`MachineLimits::servo`),
    /// where the program has stated it (mm).
    pub servo_at: Option<f64>,
    /// The least and largest positions the program has given the servo on
    /// its own letter (mm).
    pub servo_span: Option<(f64, f64)>,
    /// The axis whose + leads out of the material (header).
    pub away: usize,
    /// Where the program's control point lies from the tool's centre (mm
    /// along X, Y, Z; header): taken off every position held against the
    /// machine's travel, which bounds the tool centre as the build's
    /// planner and simulation take it.
    pub control: [f64; 3],
    /// The highest point along `away` a feed move has reached.
    pub top: Option<f64>,
    /// A rapid down (or across) before the first cut, this line: the
    /// lowest point it reaches along `away` and its span in the line, for
    /// `Reader` to hold against the highest point the cuts reach.
    pub pre_cut_rapid: Option<(f64, (usize, usize))>,
    /// The P Q of the last G5 block, for a G5 that leaves out I J.
    pub last_spline_pq: Option<(f64, f64)>,
    /// Heidenhain ISO's circle centre (X Y Z from I J K, absolute), as the
    /// last block with I, J or K defined it.
    pub circle_centre: [Option<f64>; 3],
    /// The points of the last spline read, handed over as straight moves.
    pub spline_points: Vec<(f64, f64)>,
    /// The moves made so far, when they are asked for.
    pub moves: Option<Vec<super::Executed>>,
    /// Whether the dialect has NURBS interpolation (G06.2).
    nurbs_mode: bool,
    /// The NURBS curve being read, until its last knot.
    pub nurbs: Option<super::nurbs::Nurbs>,
    /// LinuxCNC's G5.2 curve being read (`nurbs_block`).
    pub nurbs_block: Option<nurbs_block::NurbsBlock>,
    /// The B spline being read (Siemens' BSPLINE), until a block leaves
    /// the mode.
    pub bspline: Option<super::bspline::Bspline>,
    ended: bool,
    /// A Klartext program's own reader, whose blocks become words.
    klartext: Option<Klartext>,
    /// Storage reused from line to line: the block, and its G and M codes
    /// with their groups (by index into its words).
    scratch: Block,
    groups: Vec<(GGroup, usize)>,
    ms: Vec<(MCode, usize)>,
    /// The common block's one-pass reading (`fast`), where the dialect
    /// allows it, and whether it is used (off: every line is read whole,
    /// for the tests and benchmarks that compare the two).
    fast: Option<fast::FastRules>,
    pub fast_on: bool,
    /// Lines the fast path has read.
    #[cfg(test)]
    fast_taken: usize,
}

/// The tool tip's position: `p` with the servo on its own letter (at
/// `servo`, where stated) added to Z.
pub(super) fn tip(p: [Option<f64>; 4], servo: Option<f64>) -> [Option<f64>; 4] {
    let mut t = p;
    if let (Some(z), Some(s)) = (t[2], servo) {
        t[2] = Some(z + s);
    }
    t
}

impl State {
    pub fn new(d: &Dialect, machine: &MachineLimits) -> State {
        let lex = Lexer::new(d);
        let mut dialect_m = Vec::new();
        for (lines, code) in [
            (&d.c_axis_on, MCode::PositionOn),
            (&d.c_axis_off, MCode::PositionOff),
            (&d.spindle_orient, MCode::Orient),
            (&d.fts_on, MCode::Other),
            (&d.fts_off, MCode::Other),
        ] {
            for w in lines.iter().flat_map(|l| l.split_whitespace()) {
                if let Some(n) = w.strip_prefix('M').and_then(|n| n.parse::<i64>().ok()) {
                    dialect_m.push((n, code));
                }
            }
        }
        let code = |w: &Option<String>| {
            w.as_deref()
                .and_then(|w| w.strip_prefix('G'))
                .and_then(|n| n.parse::<f64>().ok())
                .map(|v| (v * 10.0).round() as i64)
        };
        let system_a = d.gcode_system == Some(crate::dialect::GcodeSystem::A);
        // G94 is feed per minute everywhere but in Fanuc's system A.
        let mut feed_codes = if system_a {
            Vec::new()
        } else {
            vec![(940, FeedMode::PerMinute)]
        };
        for (w, m) in [
            (&d.per_minute, FeedMode::PerMinute),
            (&d.per_revolution, FeedMode::PerRevolution),
            (&d.inverse_time, FeedMode::InverseTime),
        ] {
            feed_codes.extend(code(w).map(|c| (c, m)));
        }
        let mut state = State {
            machine: machine.clone(),
            arc_tolerance: d.arc_radius_tolerance,
            arc_planes: d.arc_planes.clone(),
            arc_centre_absolute: d.arc_centre_absolute,
            dialect_m,
            feed_codes,
            max_line_number: d.max_line_number,
            system_a,
            numbered: matches!(
                lex.controller,
                Controller::HeidenhainIso | Controller::HeidenhainKlartext
            ) && d.line_numbers.is_some(),
            css_capable: machine.lathe || d.constant_rpm.is_some() || !d.surface_speed.is_empty(),
            metric: None,
            plane: None,
            // System A has no G90: X Z are absolute, U W incremental.
            absolute: system_a.then_some(true),
            feed_mode: None,
            motion: None,
            feed: None,
            css: None,
            css_speed: None,
            cap: None,
            rpm: None,
            spindle_on: false,
            position_mode: false,
            tool_selected: false,
            tool_loaded: false,
            diameter: machine.lathe && d.lathe_x_diameter,
            pos: [None; 4],
            servo_at: None,
            servo_span: None,
            away: 2,
            control: [0.0; 3],
            top: None,
            pre_cut_rapid: None,
            last_spline_pq: None,
            circle_centre: [None; 3],
            spline_points: Vec::new(),
            nurbs_mode: d.spline == Some(crate::dialect::SplineForm::Nurbs),
            nurbs: None,
            nurbs_block: None,
            bspline: None,
            moves: None,
            ended: false,
            klartext: (lex.controller == Controller::HeidenhainKlartext).then(Klartext::default),
            lex,
            scratch: Block::default(),
            groups: Vec::new(),
            ms: Vec::new(),
            fast: None,
            fast_on: true,
            #[cfg(test)]
            fast_taken: 0,
        };
        state.fast = fast::FastRules::of(&state.lex, state.numbered, |l| state.known_letter(l));
        state
    }

    /// Reads one line.
    pub fn line(&mut self, line: &str, out: &mut Vec<Found>) {
        if self.fast_line(line) {
            return;
        }
        let mut b = std::mem::take(&mut self.scratch);
        match &mut self.klartext {
            Some(k) => b = k.block(&self.lex, line, out),
            None => self.lex.block_into(line, out, &mut b),
        }
        let mut groups = std::mem::take(&mut self.groups);
        let mut ms = std::mem::take(&mut self.ms);
        self.block(&b, line, out, &mut groups, &mut ms);
        (self.scratch, self.groups, self.ms) = (b, groups, ms);
    }

    /// Runs one block: `groups` and `ms` are storage for its G and M codes.
    fn block(
        &mut self,
        b: &Block,
        line: &str,
        out: &mut Vec<Found>,
        groups: &mut Vec<(GGroup, usize)>,
        ms: &mut Vec<(MCode, usize)>,
    ) {
        for c in &b.comments {
            if let Some(a) = super::header::away_axis(c) {
                self.away = a;
            }
            if let Some(o) = super::header::control_offset(c) {
                self.control = o;
            }
        }
        self.block_number(b, line, out);
        if b.is_empty() {
            return;
        }
        if self.ended && !b.percent {
            out.push((
                Rule::BlockAfterEnd,
                (0, line.len()),
                "a block after the program's end: the controller never runs it".into(),
                Some("end the program with its last block".into()),
            ));
            return;
        }
        self.repeated(b, line, out);
        if !self.classify(b, line, out, groups, ms) {
            return;
        }
        if self.lex.controller == Controller::LinuxCnc {
            self.word_use(b, groups, line, out);
        } else {
            self.parameter_words(b, groups, line, out);
        }
        // A block leaving B spline mode ends the curve: it is moved along
        // before this block's own modes (its feed) take effect.
        if self.bspline.is_some()
            && (groups
                .iter()
                .any(|(g, _)| matches!(g, GGroup::Motion(_) | GGroup::MachineMove))
                || ms.iter().any(|(m, _)| *m == MCode::End))
        {
            self.bspline_end(line, out);
        }
        self.modes(b, groups, line, out);
        self.spindle_and_tool(b, groups, ms, line, out);
        // A move to a machine position (G28, G53, Siemens' SUPA,
        // Heidenhain's M91): where it ends is the machine's, not the
        // program's; the next move starts from an unknown position.
        let machine_move = groups.iter().any(|(g, _)| *g == GGroup::MachineMove)
            || b.keywords
                .iter()
                .any(|k| k.kind == KeywordKind::Word(SiemensWord::Supa))
            || ms.iter().any(|(m, _)| *m == MCode::MachinePosition);
        if machine_move {
            if let Some((GGroup::Motion(m), _)) =
                groups.iter().find(|(g, _)| matches!(g, GGroup::Motion(_)))
            {
                self.motion = Some(*m);
            }
            self.pos = [None; 4];
        } else if !groups.iter().any(|(g, _)| {
            matches!(
                g,
                GGroup::SpindleCap | GGroup::NonModal | GGroup::Orient | GGroup::BlankForm
            )
        }) {
            // G50 S, G4, G36 S and the blank's G30 G31 take their own
            // words; no move.
            let nurbs_code = |m: Motion| groups.iter().any(|(g, _)| *g == GGroup::Motion(m));
            let (opens, closes) = (
                nurbs_code(Motion::NurbsBlock),
                nurbs_code(Motion::NurbsBlockEnd),
            );
            if self.motion == Some(Motion::Bspline) {
                self.bspline_block(b, line, out);
            } else if (opens || closes || self.nurbs_block.is_some())
                && self.nurbs_block_line(b, opens, closes, out)
            {
                // A block of LinuxCNC's G5.2 curve, or its G5.3.
            } else if self.motion == Some(Motion::Nurbs) {
                let starts = groups
                    .iter()
                    .any(|(g, _)| *g == GGroup::Motion(Motion::Nurbs));
                self.nurbs_block(b, starts, line, out);
            } else {
                self.nurbs_cut_short(line, out);
                self.move_block(b, line, out);
            }
        }
        if ms.iter().any(|(m, _)| *m == MCode::End) {
            self.ended = true;
            self.spindle_on = false;
        }
        if let Some(&(_, w)) = ms.iter().find(|(m, _)| *m == MCode::Loop) {
            out.push((
                Rule::MainProgramLoop,
                b.words[w].span,
                "M99 in a main program: the controller starts the program again from its first block, for ever".into(),
                Some("end the program with M2 or M30".into()),
            ));
            // No block after it runs in this pass; the end is not missing.
            self.ended = true;
            self.spindle_on = false;
        }
    }

    /// A NURBS curve left before its last knot: the control refuses it.
    fn nurbs_cut_short(&mut self, line: &str, out: &mut Vec<Found>) {
        if let Some(n) = self.nurbs.take() {
            out.push((
                Rule::SplineRefused,
                (0, line.len()),
                format!(
                    "the NURBS curve ends before its last knot: {} control points need {} knot blocks after them, {} given",
                    n.points.len(),
                    n.order,
                    n.end_knots
                ),
                None,
            ));
        }
    }

    /// What is wrong once the whole program is read.
    pub fn finish(&mut self, out: &mut Vec<Found>) {
        self.nurbs_cut_short("", out);
        self.nurbs_block_left((0, 0), out);
        self.bspline_end("", out);
        if let Some(k) = &self.klartext {
            k.finish(out);
        }
        if !self.ended {
            out.push((
                Rule::ProgramEnd,
                (0, 0),
                "the program has no end (M2 or M30): the controller stops without resetting".into(),
                Some("end the program with M30 (M2 on LinuxCNC)".into()),
            ));
        }
    }

    fn block_number(&self, b: &Block, line: &str, out: &mut Vec<Found>) {
        match &b.number {
            None if self.numbered && !b.percent && !(b.is_empty() && b.comments.is_empty()) => {
                out.push((
                    Rule::BlockNumber,
                    (0, line.len().min(1)),
                    "this block has no block number; every block of this dialect is numbered"
                        .into(),
                    Some("start the block with N and its number".into()),
                ));
            }
            Some(n) if !b.percent => {
                if let Some(max) = self.max_line_number
                    && n.value > max as f64
                {
                    out.push((
                        Rule::BlockNumber,
                        n.span,
                        format!("block number {} is above the controller's {max}", n.value),
                        None,
                    ));
                }
            }
            _ => {}
        }
    }

    /// A letter other than G and M twice in one block.
    fn repeated(&self, b: &Block, line: &str, out: &mut Vec<Found>) {
        for (i, w) in b.words.iter().enumerate() {
            if matches!(w.letter, 'G' | 'M') {
                continue;
            }
            if b.words[..i].iter().any(|o| o.letter == w.letter) {
                out.push((
                    Rule::RepeatedWord,
                    w.span,
                    format!(
                        "a second {} word in one block (`{}`): the controller refuses it",
                        w.letter,
                        w.text(line)
                    ),
                    None,
                ));
            }
        }
    }

    /// The block's G and M codes with their groups, into `groups` and `ms`
    /// (by index into the block's words); unknown codes and two of one
    /// modal group are refused (`false`: the block is not run).
    fn classify(
        &self,
        b: &Block,
        line: &str,
        out: &mut Vec<Found>,
        groups: &mut Vec<(GGroup, usize)>,
        ms: &mut Vec<(MCode, usize)>,
    ) -> bool {
        let before = out.len();
        groups.clear();
        ms.clear();
        for (i, w) in b.words.iter().enumerate() {
            match w.letter {
                'G' => match self.g_code(w.value).and_then(|code| self.g_group(code)) {
                    Some(g) => {
                        let siemens = self.lex.controller == Controller::Siemens;
                        let linuxcnc = self.lex.controller == Controller::LinuxCnc;
                        if let Some(&(_, o)) = groups.iter().find(|(o, _)| {
                            if linuxcnc {
                                same_group_linuxcnc(*o, g)
                            } else {
                                same_group(*o, g, siemens)
                            }
                        }) {
                            out.push(conflict(w, &b.words[o], line));
                        }
                        groups.push((g, i));
                    }
                    None => out.push(unknown_code(w, line)),
                },
                'M' => match self
                    .m_code(w.value.round() as i64)
                    .filter(|_| !w.point || self.lex.controller == Controller::LinuxCnc)
                {
                    Some(m) => {
                        if let Some(&(_, o)) = ms.iter().find(|(o, _)| same_m_group(*o, m)) {
                            out.push(conflict(w, &b.words[o], line));
                        }
                        ms.push((m, i));
                    }
                    None if w.point => {}
                    None => out.push(unknown_code(w, line)),
                },
                l if self.known_letter(l) => {}
                _ => out.push((
                    Rule::UnknownWord,
                    w.span,
                    format!(
                        "`{}`: the controller has no {} word",
                        w.text(line),
                        w.letter
                    ),
                    None,
                )),
            }
        }
        out.len() == before
    }

    /// A G word's code in tenths: within 1e-9 of a tenth, or on LinuxCNC
    /// within 0.001 of one, as its interpreter reads it (`G1.0001` is G1,
    /// `G1.00011` "G-code out of range").
    pub(super) fn g_code(&self, value: f64) -> Option<i64> {
        if self.lex.controller != Controller::LinuxCnc {
            return g_tenths(value);
        }
        let scaled = value * 10.0;
        let code = round_to_integer(scaled);
        ((scaled - code as f64).abs() <= 0.001 + 1e-9).then_some(code)
    }

    fn known_letter(&self, l: char) -> bool {
        let letters = match self.lex.controller {
            Controller::Fanuc if self.system_a => "XYZCUWIJKRFSTDHPQLNO",
            Controller::Fanuc => "XYZCIJKRFSTDHPQLNO",
            Controller::UltraPrecision => "XYZCWIJKRFSTDHPQLNO",
            Controller::LinuxCnc => "XYZABCIJKRFSTDHPQLN",
            Controller::Siemens => "XYZABCIJKRFSTDHPLN",
            Controller::HeidenhainIso => "XYZABCIJKRFSTLPHN",
            Controller::HeidenhainKlartext => "XYZIJKFSTN",
        };
        // LinuxCNC reads U V W where the machine configures them as axes:
        // the fast tool servo's letter, where it is one.
        let servo = self.lex.controller == Controller::LinuxCnc
            && self.machine.servo.is_some_and(|s| s.letter == l);
        // Every letter listed is ASCII: a byte compare, not a char search.
        servo || (l.is_ascii() && letters.as_bytes().contains(&(l as u8)))
    }

    fn g_group(&self, code: i64) -> Option<GGroup> {
        use Controller::*;
        let c = self.lex.controller;
        let metric_codes = match c {
            LinuxCnc | Fanuc => (200, 210),
            _ => (700, 710),
        };
        Some(match code {
            0 => GGroup::Motion(Motion::Rapid),
            10 => GGroup::Motion(Motion::Linear),
            20 => GGroup::Motion(Motion::Cw),
            30 => GGroup::Motion(Motion::Ccw),
            170 => GGroup::Plane(Plane::Xy),
            180 => GGroup::Plane(Plane::Zx),
            190 => GGroup::Plane(Plane::Yz),
            // In Fanuc's system A, G90 is the outer-diameter turning cycle
            // and there is no G91: not codes lensc reads.
            900 | 910 if self.system_a => return None,
            900 => GGroup::Distance(true),
            910 => GGroup::Distance(false),
            280 if matches!(c, LinuxCnc | Fanuc | UltraPrecision) => GGroup::MachineMove,
            530 if matches!(c, LinuxCnc | Fanuc | Siemens | UltraPrecision) => GGroup::MachineMove,
            400 | 410 | 420 => GGroup::CutterComp,
            960 if c != HeidenhainIso && c != HeidenhainKlartext => GGroup::SpindleMode(true),
            970 if c != HeidenhainIso && c != HeidenhainKlartext => GGroup::SpindleMode(false),
            40 => GGroup::NonModal,
            540..=590 if code % 10 == 0 => GGroup::WorkOffset,
            c2 if c2 == metric_codes.0 => GGroup::Units(false),
            c2 if c2 == metric_codes.1 => GGroup::Units(true),
            7000 if c == Siemens => GGroup::Units(false),
            7100 if c == Siemens => GGroup::Units(true),
            800 if c == LinuxCnc => GGroup::Motion(Motion::Cancel),
            50 if c == LinuxCnc => GGroup::Motion(Motion::Spline(super::spline::Spline::Cubic)),
            51 if c == LinuxCnc => GGroup::Motion(Motion::Spline(super::spline::Spline::Quadratic)),
            52 if c == LinuxCnc => GGroup::Motion(Motion::NurbsBlock),
            53 if c == LinuxCnc => GGroup::Motion(Motion::NurbsBlockEnd),
            62 if self.nurbs_mode => GGroup::Motion(Motion::Nurbs),
            800 if c == Fanuc || c == UltraPrecision => GGroup::Cycle,
            430 | 490 if c == LinuxCnc || c == Fanuc => GGroup::ToolLength,
            70 if c == LinuxCnc => GGroup::Diameter(true),
            80 if c == LinuxCnc => GGroup::Diameter(false),
            610 | 640 if c == LinuxCnc => GGroup::PathControl,
            600 | 640 | 6410 | 6420 if c == Siemens => GGroup::PathControl,
            // The clamp: G50 S in Fanuc's system A, G92 S in B and C.
            500 if (c == Fanuc && self.system_a) || c == UltraPrecision => GGroup::SpindleCap,
            920 if c == Fanuc && !self.system_a => GGroup::SpindleCap,
            51 if c == Fanuc => GGroup::NonModal,
            360 if c == HeidenhainIso => GGroup::Orient,
            300 | 310 if c == HeidenhainIso => GGroup::BlankForm,
            _ => {
                return self
                    .feed_codes
                    .iter()
                    .find(|(f, _)| *f == code)
                    .map(|(_, m)| GGroup::Feed(*m));
            }
        })
    }

    fn m_code(&self, n: i64) -> Option<MCode> {
        if let Some((_, m)) = self.dialect_m.iter().find(|(c, _)| *c == n) {
            return Some(*m);
        }
        Some(match n {
            3 | 4 => MCode::SpindleOn,
            5 => MCode::SpindleOff,
            6 => MCode::ToolChange,
            2 | 30 => MCode::End,
            0 | 1 => MCode::Stop,
            // M60: the pallet change pause, a stop as M0 is; M99 in a main
            // program: the program again from the top (LinuxCNC's M-code
            // reference, docs/controllers/linuxcnc.md).
            60 if self.lex.controller == Controller::LinuxCnc => MCode::Stop,
            99 if self.lex.controller == Controller::LinuxCnc => MCode::Loop,
            7..=9 => MCode::Coolant,
            19 => MCode::Orient,
            91 if matches!(
                self.lex.controller,
                Controller::HeidenhainIso | Controller::HeidenhainKlartext
            ) =>
            {
                MCode::MachinePosition
            }
            _ => return None,
        })
    }

    /// Units, plane, distance, feed mode, diameter mode.
    fn modes(&mut self, b: &Block, groups: &[(GGroup, usize)], line: &str, out: &mut Vec<Found>) {
        // G80 beside another motion code (LinuxCNC): the other code wins.
        let moving = groups
            .iter()
            .any(|(g, _)| matches!(g, GGroup::Motion(m) if *m != Motion::Cancel));
        for (g, _) in groups {
            if moving && *g == GGroup::Motion(Motion::Cancel) {
                continue;
            }
            match *g {
                GGroup::Units(m) => self.metric = Some(m),
                GGroup::Plane(p) => self.plane = Some(p),
                GGroup::Distance(a) => self.absolute = Some(a),
                GGroup::Feed(m) => {
                    // LinuxCNC forgets F at every G93/G94/G95, the mode in
                    // force restated too ("Cannot do g1 with zero feed
                    // rate" after `G95` then `G1` with no F).
                    if self.feed_mode != Some(m) || self.lex.controller == Controller::LinuxCnc {
                        self.feed = None;
                    }
                    self.feed_mode = Some(m);
                    if self.lex.controller == Controller::Siemens {
                        // G94 G95 G96 G97 are one group (15) on a Sinumerik:
                        // a feed type cancels constant surface speed.
                        self.css = Some(false);
                    }
                }
                GGroup::SpindleMode(_) if self.lex.controller == Controller::Siemens => {
                    // G96 and G97 feed per revolution.
                    if self.feed_mode != Some(FeedMode::PerRevolution) {
                        self.feed = None;
                    }
                    self.feed_mode = Some(FeedMode::PerRevolution);
                }
                // LinuxCNC's interpreter knows no lathe from a mill: G7
                // reads X as a diameter on either.
                GGroup::Diameter(d) => {
                    self.diameter =
                        d && (self.machine.lathe || self.lex.controller == Controller::LinuxCnc)
                }
                // A length offset taken or dropped moves the program's
                // coordinates by the tool's length, which the reader does
                // not know: where the tool is becomes unknown.
                GGroup::ToolLength => self.pos = [None; 4],
                GGroup::Motion(m) => self.motion = Some(m),
                _ => {}
            }
        }
        for k in &b.keywords {
            use SiemensWord::*;
            match k.kind {
                KeywordKind::Word(Diamon | Diam90) => self.diameter = self.machine.lathe,
                KeywordKind::Word(Diamof) => self.diameter = false,
                KeywordKind::Word(Bspline) => self.motion = Some(Motion::Bspline),
                // A B spline's SD, PL and PW are `bspline_moves.rs`'.
                KeywordKind::Word(Sd | Pl | Pw) => {}
                // SPCON, SPCOF, SPOS and LIMS are `spindle_and_tool`'s, a
                // tool by name `tool`'s; the rest change nothing the reader
                // holds a program to.
                KeywordKind::Word(
                    Compcad | Compcurv | Compon | Compof | Spcon | Spcof | Spos | Ctol | Otol
                    | Atol | Lims | Soft | Brisk | Ffwon | Ffwof | Supa,
                )
                | KeywordKind::Text(_)
                | KeywordKind::Cycle832 => {}
            }
        }
        if let Some(f) = b.words.iter().find(|w| w.letter == 'F') {
            if f.value <= 0.0 {
                out.push((
                    Rule::NoFeedRate,
                    f.span,
                    format!("`{}`: a feed must be above zero", f.text(line)),
                    None,
                ));
            } else {
                self.feed = Some(f.value);
            }
        }
    }

    /// Spindle speed and its mode, the cap, spindle on and off, position
    /// mode, the tool call.
    fn spindle_and_tool(
        &mut self,
        b: &Block,
        groups: &[(GGroup, usize)],
        ms: &[(MCode, usize)],
        line: &str,
        out: &mut Vec<Found>,
    ) {
        let has = |g: GGroup| groups.iter().any(|(o, _)| *o == g);
        let s = b.words.iter().find(|w| w.letter == 'S');
        // The rpm and caps this block sets, to hold against the maximum.
        let mut speeds = Vec::new();
        if has(GGroup::Orient) {
            self.orient();
        } else if has(GGroup::SpindleCap) {
            self.cap = s.map(|s| s.value);
            speeds.extend(s.map(|s| (s.value, s.span)));
        } else if let Some(cap) = b
            .keywords
            .iter()
            .find(|k| k.kind == KeywordKind::Word(SiemensWord::Lims))
        {
            self.cap = cap.value;
            speeds.extend(cap.value.map(|v| (v, cap.span)));
        } else {
            if let Some(d) = b.words.iter().find(|w| w.letter == 'D')
                && has(GGroup::SpindleMode(true))
                && self.lex.controller == Controller::LinuxCnc
            {
                self.cap = Some(d.value);
                speeds.push((d.value, d.span));
            }
            if has(GGroup::SpindleMode(true)) {
                self.css = Some(true);
            } else if has(GGroup::SpindleMode(false)) {
                self.css = Some(false);
            }
            if let Some(s) = s {
                if self.css == Some(true) {
                    self.css_speed = Some(s.value);
                } else {
                    self.rpm = Some(s.value);
                    speeds.push((s.value, s.span));
                }
            }
        }
        if has(GGroup::SpindleMode(true)) && self.cap.is_none() {
            let &(_, w) = groups
                .iter()
                .find(|(g, _)| *g == GGroup::SpindleMode(true))
                .expect("found above");
            out.push((
                Rule::NoSpeedCap,
                b.words[w].span,
                "constant surface speed with no spindle speed limit: at the centre the spindle would run to its maximum".into(),
                Some("set the limit first (LinuxCNC: G96 D…; Fanuc: G50 S…; Siemens: LIMS=…)".into()),
            ));
        }
        self.speed_limits(&speeds, line, out);
        self.tool(b, ms);
        for k in &b.keywords {
            use SiemensWord::*;
            match k.kind {
                KeywordKind::Word(Spcon) => self.position_mode = true,
                KeywordKind::Word(Spcof) => self.position_mode = false,
                KeywordKind::Word(Spos) => {
                    // Stopped and held at an angle: as M19 elsewhere.
                    self.spindle_on = false;
                    self.position_mode = true;
                }
                // DIAMON, DIAM90 and DIAMOF are `modes`', LIMS is read
                // above, a tool by name in `tool`; the rest change nothing
                // the reader holds a program to.
                KeywordKind::Word(
                    Diamof | Diamon | Diam90 | Compcad | Compcurv | Compon | Compof | Ctol | Otol
                    | Atol | Lims | Soft | Brisk | Ffwon | Ffwof | Supa | Bspline | Sd | Pl | Pw,
                )
                | KeywordKind::Text(_)
                | KeywordKind::Cycle832 => {}
            }
        }
        for &(m, w) in ms {
            match m {
                MCode::SpindleOn => self.spindle_start(&b.words[w], out),
                MCode::SpindleOff => self.spindle_on = false,
                MCode::PositionOn | MCode::Orient => {
                    self.position_mode = true;
                    self.spindle_on = false;
                }
                MCode::PositionOff => self.position_mode = false,
                _ => {}
            }
        }
    }

    fn tool(&mut self, b: &Block, ms: &[(MCode, usize)]) {
        let t = b.words.iter().any(|w| w.letter == 'T')
            || b.keywords.iter().any(|k| k.kind == KeywordKind::Text('T'));
        if t {
            self.tool_selected = true;
        }
        let needs_change = match self.lex.controller {
            Controller::LinuxCnc => true,
            Controller::Fanuc | Controller::Siemens => !self.machine.lathe,
            _ => false,
        };
        if (!needs_change && t)
            || (needs_change
                && self.tool_selected
                && ms.iter().any(|(m, _)| *m == MCode::ToolChange))
        {
            self.tool_loaded = true;
        }
    }

    /// Heidenhain ISO's G36: the spindle stopped and held at the angle
    /// its S word gives (degrees: not a speed), as M19 holds it elsewhere.
    fn orient(&mut self) {
        self.spindle_on = false;
        self.position_mode = true;
    }

    /// The speeds this block sets (an rpm, or a cap) against the
    /// spindle's maximum.
    fn speed_limits(&self, speeds: &[(f64, (usize, usize))], line: &str, out: &mut Vec<Found>) {
        let Some(max) = self.machine.max_spindle_rpm else {
            return;
        };
        for &(v, span) in speeds {
            if v > max * (1.0 + 1e-12) {
                out.push((
                    Rule::SpindleTooFast,
                    span,
                    format!(
                        "`{}` asks {v} rpm of a spindle whose maximum is {max} rpm",
                        &line[span.0..span.1]
                    ),
                    None,
                ));
            }
        }
    }

    fn spindle_start(&mut self, w: &Word, out: &mut Vec<Found>) {
        if self.css.is_none() && self.css_capable {
            out.push((
                Rule::SpindleSpeedMode,
                w.span,
                "the spindle starts before G96 or G97 is stated: a G96 left by an earlier program would read S as a surface speed".into(),
                Some("state G97 (constant rpm) or G96 (constant surface speed) before the start".into()),
            ));
        }
        let speed = match self.css {
            Some(true) => self.css_speed,
            _ => self.rpm,
        };
        if !speed.is_some_and(|s| s > 0.0) {
            out.push((
                Rule::NoSpindleSpeed,
                w.span,
                "the spindle starts with no speed stated (S): it would not turn".into(),
                Some("give the speed with S in this block or before it".into()),
            ));
        }
        self.spindle_on = speed.is_some_and(|s| s > 0.0);
        self.position_mode = false;
    }
}

/// `v.round() as i64` (halves away from zero, saturating, NaN to 0)
/// without a call into libm: the truncation and the fraction it drops
/// are both exact in f64.
/// A G word's code in tenths (`G1` is 10, `G64.1` 641), if its value is
/// one within 1e-9 of a tenth.
pub(super) fn g_tenths(value: f64) -> Option<i64> {
    let scaled = value * 10.0;
    let code = round_to_integer(scaled);
    ((scaled - code as f64).abs() < 1e-9).then_some(code)
}

fn round_to_integer(v: f64) -> i64 {
    let t = v as i64;
    let fraction = v - t as f64;
    if fraction >= 0.5 {
        t.saturating_add(1)
    } else if fraction <= -0.5 {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// Whether two G codes are of one modal group (`siemens`: G94 G95 G96
/// G97 are one, group 15).
fn same_group(a: GGroup, b: GGroup, siemens: bool) -> bool {
    use GGroup::*;
    let feed_type = |g| matches!(g, Feed(_) | SpindleMode(_));
    if siemens && feed_type(a) && feed_type(b) {
        return true;
    }
    !matches!(a, NonModal | WorkOffset) && std::mem::discriminant(&a) == std::mem::discriminant(&b)
}

/// Whether two G codes are of one modal group on LinuxCNC, whose group 0
/// holds the non-modal codes (G4, G28, G53 …) and group 12 the work
/// offsets: two of either in a block are refused too.
fn same_group_linuxcnc(a: GGroup, b: GGroup) -> bool {
    use GGroup::*;
    // G80 beside another motion code is read, the other code winning
    // (`rs274 -g` runs `G80 G0` and `G0 G80`).
    let cancel = Motion(self::Motion::Cancel);
    if (a == cancel && matches!(b, Motion(_))) || (b == cancel && matches!(a, Motion(_))) {
        return false;
    }
    let group_0 = |g| matches!(g, NonModal | MachineMove);
    (group_0(a) && group_0(b)) || std::mem::discriminant(&a) == std::mem::discriminant(&b)
}

fn same_m_group(a: MCode, b: MCode) -> bool {
    use MCode::*;
    let group = |m| match m {
        SpindleOn | SpindleOff | PositionOn | PositionOff | Orient => 1,
        End | Stop | Loop => 2,
        ToolChange => 3,
        Coolant | Other | MachinePosition => 0,
    };
    group(a) != 0 && group(a) == group(b)
}

fn conflict(w: &Word, other: &Word, line: &str) -> Found {
    (
        Rule::SameModalGroup,
        w.span,
        format!(
            "`{}` and `{}` are of one modal group: a block may hold only one of them",
            other.text(line),
            w.text(line)
        ),
        Some("split them into two blocks in the order meant".into()),
    )
}

fn unknown_code(w: &Word, line: &str) -> Found {
    (
        Rule::UnknownWord,
        w.span,
        format!("`{}` is not a code this controller knows", w.text(line)),
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::round_to_integer;

    /// The same integer as `round() as i64` for halves, near-halves,
    /// integers beyond 2^53 and 2^63, infinities, NaN and a spread of
    /// bit patterns.
    #[test]
    fn rounds_as_round_does() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
            4503599627370495.5,
            -4503599627370495.5,
            9007199254740993.0,
            9.223372036854776e18,
            -9.223372036854776e18,
            1e30,
            -1e30,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            10.0 * 1.1,
            10.0 * 96.9,
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let v = f64::from_bits(state);
            values.push(v);
            // Tenths of codes as a program writes them (G1, G64.1, …).
            values.push((state % 20_000) as f64 / 10.0 * 10.0);
            values.push((state % 2_000_000) as f64 * 1e-3 - 1e3);
        }
        for v in values {
            let x = v.next_up();
            let y = v.next_down();
            for w in [v, x, y] {
                assert_eq!(round_to_integer(w), w.round() as i64, "{w:e}");
            }
        }
    }
}
