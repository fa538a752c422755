//! The move of a block, as the controller would make it from the modal
//! state: where it ends, whether it may be made at all (tool, spindle,
//! feed mode and feed), whether it stays in the machine's travel and under
//! its feed, whether a rapid crosses material already cut, and whether an
//! arc is one the controller accepts.
//!
//! Rapids and the material: the reader knows no stock, so it takes the
//! highest point any feed move has reached so far, along the axis the
//! header names as out of the material (`+Z out of the material`; X on a
//! roller), as the top of the material. A rapid that moves across (any
//! other axis, C included) while either end is below that top, or that
//! plunges below it, is refused. This is conservative: a rapid beside the
//! part below its top is refused too.
//!
//! Arcs, by each controller's rule:
//! - LinuxCNC (`interp_arc.cc`, `arc_data_ijk`, with its default
//!   `CENTER_ARC_RADIUS_TOLERANCE_MM` = 2 × 0.01 × √2 mm and the relative
//!   0.1 %): refused when the radii differ by more than 100 times that, or
//!   by more than it and 0.1 % of the radius; a radius under 0.00127 mm is
//!   a zero-radius arc;
//! - Siemens 840D (MD 21000 `CIRCLE_ERROR_CONST` 0.01 mm, MD 21010
//!   `CIRCLE_ERROR_FACTOR` 0.001): refused beyond the larger of 0.01 mm and
//!   0.1 % of the radius (alarm 14095);
//! - Fanuc (parameter 3410, alarm PS0020), Heidenhain and the
//!   ultra-precision lathes: the dialect's `arc_radius_tolerance`, as the
//!   controller's setting.
//!
//! An arc that ends where it starts is a full circle on every one of them.

use super::chord::chord;
use super::lexer::{Block, Found, Word};
use super::modal::{FeedMode, Motion, State, tip};
use super::{Controller, Executed, Path, Rule};
use crate::moves::Plane;

const LETTERS: [char; 4] = ['X', 'Y', 'Z', 'C'];
const AXIS: [&str; 4] = ["X", "Y", "Z", "C"];

impl State {
    /// The block's move, if it has one.
    pub(crate) fn move_block(&mut self, b: &Block, line: &str, out: &mut Vec<Found>) {
        let centre: Vec<&Word> = b
            .words
            .iter()
            .filter(|w| matches!(w.letter, 'I' | 'J' | 'K' | 'R'))
            .collect();
        // Heidenhain ISO: I, J, K define the circle centre, wherever they
        // are; a block of them alone moves nothing, in an arc mode too
        // ("The only effect of I, J, K is to define a position as a circle
        // center — the tool does not move to the position": TNC
        // 426/425/415 B/407 ISO Programming User's Manual, "Circle center
        // I, J, K", pp. 5-16 to 5-17; docs/controllers/heidenhain.md).
        let iso = self.lex.controller == Controller::HeidenhainIso;
        if iso {
            let unit = self.mm_per_unit();
            for w in b
                .words
                .iter()
                .filter(|w| matches!(w.letter, 'I' | 'J' | 'K'))
            {
                let i = (w.letter as u8 - b'I') as usize;
                self.circle_centre[i] = Some(w.value * unit);
            }
        }
        // Centre words alone make a move only in an arc mode (a full
        // circle); elsewhere they belong to their block (`M19 R0`).
        let arc_mode = matches!(self.motion, Some(Motion::Cw | Motion::Ccw)) && !iso;
        let servo_word = self.servo_word(b);
        let Some(first) = axes(b)
            .next()
            .or(servo_word)
            .or(centre.first().copied().filter(|_| arc_mode))
        else {
            return;
        };
        let last = b.words.last().expect("a word");
        let span = (first.span.0, last.span.1);
        let Some(motion) = self.motion.filter(|m| *m != Motion::Cancel) else {
            out.push((
                Rule::NoMotionMode,
                first.span,
                format!(
                    "`{}` with no motion mode in force (G0, G1, G2, G3): the controller refuses it",
                    first.text(line)
                ),
                None,
            ));
            return;
        };
        self.stated(span, out);
        let start = self.pos;
        let end = self.end_point(b);
        // The servo on its own letter: where it goes, and the tool tip
        // (Z plus the servo) at each end of the move.
        let servo_start = self.servo_at;
        let servo_end = match servo_word {
            Some(w) => self.servo_end(w.value),
            None => servo_start,
        };
        let (tip_start, tip_end) = (tip(start, servo_start), tip(end, servo_end));
        if let Some(w) = servo_word {
            self.servo_stroke(w, servo_end, out);
        }
        if self.lex.controller == Controller::LinuxCnc && axes(b).any(|w| w.letter == 'C') {
            // LinuxCNC drives the spindle as the rotary axis C.
            self.position_mode = true;
        }
        self.travel(&end, b, out);
        if !matches!(motion, Motion::Spline(_)) {
            self.last_spline_pq = None;
        }
        let path = match motion {
            Motion::Rapid => {
                self.rapid(&tip_start, &tip_end, span, out);
                Some(Path::Rapid)
            }
            _ => {
                let path = self.feed_move(motion, b, &start, &end, &centre, span, line, out);
                self.servo_limit(b, &start, &end, (servo_start, servo_end), span, out);
                if let Some(v) = tip_end[self.away].filter(|_| self.away == 2) {
                    // The highest point cut is the tip's.
                    self.top = Some(self.top.map_or(v, |t| t.max(v)));
                }
                path
            }
        };
        let slide_end = end;
        let (start, end) = (tip_start, tip_end);
        if let (Some(moves), Some(path)) = (&mut self.moves, path) {
            if matches!(motion, Motion::Spline(_)) {
                // A spline's straight moves, X and Y along its points.
                let points = std::mem::take(&mut self.spline_points);
                for pair in points.windows(2) {
                    let mut from = start;
                    let mut to = end;
                    (from[0], from[1]) = (Some(pair[0].0), Some(pair[0].1));
                    (to[0], to[1]) = (Some(pair[1].0), Some(pair[1].1));
                    moves.push(Executed { from, to, path });
                }
            } else {
                moves.push(Executed {
                    from: start,
                    to: end,
                    path,
                });
            }
        }
        self.pos = slide_end;
        self.servo_at = servo_end;
    }

    /// The block's word of the fast tool servo's own letter, on a
    /// LinuxCNC machine that has one (`MachineLimits::servo`).
    fn servo_word<'b>(&self, b: &'b Block) -> Option<&'b Word> {
        let letter = self.machine.servo.map(|s| s.letter)?;
        (self.lex.controller == Controller::LinuxCnc)
            .then(|| b.words.iter().find(|w| w.letter == letter))
            .flatten()
    }

    /// A servo word (`w`, ending at `end` mm) that widens the span of the
    /// servo's positions beyond its stroke: no zero of the servo reaches
    /// them all. Said at each move that widens it further.
    fn servo_stroke(&mut self, w: &Word, end: Option<f64>, out: &mut Vec<Found>) {
        let (Some(axis), Some(v)) = (self.machine.servo, end) else {
            return;
        };
        let (lo, hi) = self
            .servo_span
            .map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v)));
        let widened = self.servo_span != Some((lo, hi));
        self.servo_span = Some((lo, hi));
        if widened && hi - lo > axis.stroke + 1e-9 {
            out.push((
                Rule::OutsideTravel,
                w.span,
                format!(
                    "this move takes the fast tool servo's axis {} to {} mm: the program moves it over {} .. {} mm, {} mm, more than its {} mm stroke",
                    axis.letter,
                    num(v),
                    num(lo),
                    num(hi),
                    num(hi - lo),
                    num(axis.stroke)
                ),
                None,
            ));
        }
    }

    /// Where the servo ends for its word's `value` in the program's units:
    /// incremental values added to where it is (unknown if it is).
    fn servo_end(&self, value: f64) -> Option<f64> {
        let v = value * self.mm_per_unit();
        if self.absolute == Some(false) {
            self.servo_at.map(|p| p + v)
        } else {
            Some(v)
        }
    }

    /// A feed move that drives the servo on its own letter (from `servo.0`
    /// to `servo.1`, mm) faster than its velocity limit. Its time is the
    /// move's by LinuxCNC's feed rule (`over_limits`): in inverse time
    /// 1/F; per minute the slides' X Y Z length at F where they move, else
    /// the servo's own travel at F (the U V W rule); per revolution the
    /// same at F times the spindle's speed.
    fn servo_limit(
        &self,
        b: &Block,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        servo: (Option<f64>, Option<f64>),
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) {
        let (Some(axis), (Some(s0), Some(s1))) = (self.machine.servo, servo) else {
            return;
        };
        let (Some(f), Some(mode)) = (self.feed, self.feed_mode) else {
            return;
        };
        let travel = (s1 - s0).abs();
        if travel == 0.0 {
            return;
        }
        let unit = self.mm_per_unit();
        let slides = chord(start, end).unwrap_or(0.0);
        let along = |rate: f64| {
            if slides > 0.0 {
                travel * rate / slides
            } else {
                rate
            }
        };
        let velocity = match mode {
            FeedMode::InverseTime => Some(travel * f),
            FeedMode::PerMinute => Some(along(f * unit)),
            FeedMode::PerRevolution => self
                .revolutions(start, end)
                .map(|rpm| along(f * unit * rpm)),
        };
        let Some(v) = velocity.filter(|&v| v > axis.max_velocity * (1.0 + 1e-9)) else {
            return;
        };
        let fspan = feed_span(b, span);
        out.push((
            Rule::FeedTooHigh,
            fspan,
            format!(
                "this move drives the fast tool servo's axis {} at {} mm/min, above its {} mm/min",
                axis.letter,
                num(v),
                num(axis.max_velocity)
            ),
            None,
        ));
    }

    /// Units and distance mode must be stated before the first move.
    fn stated(&self, span: (usize, usize), out: &mut Vec<Found>) {
        let mut missing = Vec::new();
        if self.metric.is_none() {
            missing.push("units (G21 or G71)");
        }
        if self.absolute.is_none() {
            missing.push("absolute or incremental (G90 or G91)");
        }
        if !missing.is_empty() {
            out.push((
                Rule::ModalStateUnstated,
                span,
                format!(
                    "a move before the program states {}: the controller would use whatever an earlier program left",
                    missing.join(" and ")
                ),
                None,
            ));
        }
    }

    pub(super) fn end_point(&self, b: &Block) -> [Option<f64>; 4] {
        let mut end = self.pos;
        for w in axes(b) {
            let i = LETTERS
                .iter()
                .position(|l| *l == w.letter)
                .expect("an axis");
            end[i] = self.axis_end(i, w.value);
        }
        end
    }

    /// Millimetres per unit of the program's lengths: 25.4 after G20
    /// (inch), else 1.
    pub(super) fn mm_per_unit(&self) -> f64 {
        if self.metric == Some(false) {
            25.4
        } else {
            1.0
        }
    }

    /// Where axis `i` (X Y Z C) ends for a word's `value` in the program's
    /// units (C in degrees): a diameter halved to a radius, an incremental
    /// value added to where the axis is (unknown if it is).
    pub(super) fn axis_end(&self, i: usize, value: f64) -> Option<f64> {
        let mut v = value;
        if i != 3 {
            v *= self.mm_per_unit();
        }
        if i == 0 && self.diameter {
            v /= 2.0;
        }
        if self.absolute == Some(false) {
            self.pos[i].map(|p| p + v)
        } else {
            Some(v)
        }
    }

    fn travel(&self, end: &[Option<f64>; 4], b: &Block, out: &mut Vec<Found>) {
        for (i, w) in axes(b).map(|w| (LETTERS.iter().position(|l| *l == w.letter), w)) {
            let i = i.expect("an axis");
            if let Some((v, lo, hi, unit)) = self.outside_travel(i, end[i]) {
                out.push((
                    Rule::OutsideTravel,
                    w.span,
                    format!(
                        "this move takes {}{} to {}{unit}, outside the machine's travel {} .. {}{unit}",
                        if i < 3 && self.control[i] != 0.0 {
                            "the tool centre's "
                        } else {
                            ""
                        },
                        AXIS[i],
                        num(v),
                        num(lo),
                        num(hi)
                    ),
                    None,
                ));
            }
        }
    }

    /// Where axis `i`'s tool centre ends (`v`, the control point's
    /// position, less the header's control offset) if that is outside the
    /// machine's travel:
    /// the end and the travel as a message gives them (C in degrees), and
    /// their unit.
    pub(super) fn outside_travel(
        &self,
        i: usize,
        v: Option<f64>,
    ) -> Option<(f64, f64, f64, &'static str)> {
        let (Some(v), Some((lo, hi))) = (v, self.machine.travel[i]) else {
            return None;
        };
        // The tool centre's position: the control point less its offset.
        let v = v - self.control.get(i).copied().unwrap_or(0.0);
        let (v, lo, hi, unit) = if i == 3 {
            (v, lo.to_degrees(), hi.to_degrees(), "°")
        } else {
            (v, lo, hi, " mm")
        };
        (v < lo - 1e-9 || v > hi + 1e-9).then_some((v, lo, hi, unit))
    }

    /// A rapid may not cross or plunge into the material cut so far.
    fn rapid(
        &mut self,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) {
        let a = self.away;
        if self.top.is_none()
            && let Some(q) = end[a]
        {
            // Before the first cut the top of the material is not known
            // yet: the rapid is held against the highest point the cuts
            // reach, once the program is read (`Reader::finish`).
            let across = (0..4).any(|i| i != a && end[i].is_some() && end[i] != start[i]);
            let low = start[a].map_or(q, |p| if across { p.min(q) } else { q });
            let down = start[a].is_none_or(|p| q < p) || across;
            if down {
                self.pre_cut_rapid = Some((low, span));
            }
        }
        let (Some(top), Some(p), Some(q)) = (self.top, start[a], end[a]) else {
            return;
        };
        let across = (0..4).any(|i| i != a && end[i].is_some() && end[i] != start[i]);
        let low = p.min(q);
        let bad = if across {
            low < top - 1e-7
        } else {
            q < p && q < top - 1e-7
        };
        if bad {
            out.push((
                Rule::RapidIntoPart,
                span,
                format!(
                    "a rapid {} at {}{} mm, below the highest point cut so far ({} mm): it would run the tool through the part",
                    if across { "across" } else { "down" },
                    AXIS[a],
                    num(low.min(q)),
                    num(top)
                ),
                Some(format!(
                    "retract along +{} above {} mm before moving across",
                    AXIS[a],
                    num(top)
                )),
            ));
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn feed_move(
        &mut self,
        motion: Motion,
        b: &Block,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        centre: &[&Word],
        span: (usize, usize),
        line: &str,
        out: &mut Vec<Found>,
    ) -> Option<Path> {
        self.may_cut(b, span, out);
        let (length, path) = match motion {
            Motion::Cw | Motion::Ccw => {
                let turns = b.words.iter().find(|w| w.letter == 'P');
                let cw = motion == Motion::Cw;
                match self.arc(cw, start, end, centre, turns, span, line, out) {
                    Some((length, arc)) => (Some(length), Some(arc)),
                    None => (None, None),
                }
            }
            Motion::Spline(kind) => {
                let (Some(sx), Some(sy), Some(ex), Some(ey)) = (start[0], start[1], end[0], end[1])
                else {
                    out.push((
                        Rule::PositionUnknown,
                        span,
                        "a spline from a point the program never stated (its X or Y is unknown here)".into(),
                        Some("move to a stated position, absolute, before the spline".into()),
                    ));
                    return None;
                };
                let points = self.spline(kind, b, (sx, sy), (ex, ey), span, out)?;
                let length: f64 = points
                    .windows(2)
                    .map(|p| (p[1].0 - p[0].0).hypot(p[1].1 - p[0].1))
                    .sum();
                self.spline_points = points;
                (Some(length), Some(Path::Line))
            }
            _ => (chord(start, end), Some(Path::Line)),
        };
        if let Some(length) = length {
            self.feed_limit(b, start, end, length, span, out);
        }
        // (With a servo on its own letter the tip's Z is the top's,
        // `move_block`.)
        if let Some(v) = end[self.away].filter(|_| self.machine.servo.is_none() || self.away != 2) {
            self.top = Some(self.top.map_or(v, |t| t.max(v)));
        }
        path
    }

    /// Tool, spindle, feed mode and feed, before any cut.
    pub(super) fn may_cut(&self, b: &Block, span: (usize, usize), out: &mut Vec<Found>) {
        if !self.tool_loaded {
            out.push((
                Rule::NoTool,
                span,
                "a cut before any tool is called: the controller cuts with whatever tool and offset it holds".into(),
                Some(match self.lex.controller {
                    Controller::LinuxCnc => "call the tool first: T… M6 (and G43)".into(),
                    Controller::HeidenhainKlartext => "call the tool first: TOOL CALL … Z".into(),
                    _ => "call the tool and its offset first (T…)".into(),
                }),
            ));
        }
        if !(self.spindle_on || self.position_mode) {
            out.push((
                Rule::SpindleStopped,
                span,
                "a feed move with the spindle stopped: the tool would plunge into a standing part"
                    .into(),
                Some("start the spindle (S… M3) before the first feed move".into()),
            ));
        }
        if self.feed_mode.is_none() {
            out.push((
                Rule::NoFeedMode,
                span,
                "a feed move before the feed mode is stated (G94, G95 or G93): F would be read in whatever mode an earlier program left".into(),
                None,
            ));
        }
        let has_f = b.words.iter().any(|w| w.letter == 'F');
        if self.feed.is_none() || (self.feed_mode == Some(FeedMode::InverseTime) && !has_f) {
            out.push((
                Rule::NoFeedRate,
                span,
                if self.feed_mode == Some(FeedMode::InverseTime) && self.feed.is_some() {
                    "in inverse time (G93) every feed move carries its own F".into()
                } else {
                    "a feed move with no feed (F) stated in the feed mode in force".into()
                },
                None,
            ));
        }
    }

    /// The feed of the move (mm/min) against the machine's, and in inverse
    /// time C's speed against the spindle's.
    pub(super) fn feed_limit(
        &self,
        b: &Block,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        length: f64,
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) {
        let (feed, turning) = self.over_limits(self.feed, start, end, length);
        if feed.is_none() && turning.is_none() {
            return;
        }
        let fspan = feed_span(b, span);
        if let Some((rate, max)) = feed {
            out.push((
                Rule::FeedTooHigh,
                fspan,
                format!(
                    "this move feeds at {} mm/min, above the machine's {} mm/min",
                    num(rate),
                    num(max)
                ),
                None,
            ));
        }
        if let Some((rpm, max)) = turning {
            out.push((
                Rule::SpindleTooFast,
                fspan,
                format!(
                    "this move turns C at {} rpm, above the spindle's {} rpm",
                    num(rpm),
                    num(max)
                ),
                None,
            ));
        }
    }

    /// A move of `length` (mm) at `feed` in the feed mode in force: its
    /// feed (mm/min) where it is above the machine's, and in inverse time
    /// C's speed (rpm) where it is above the spindle's, each with the
    /// limit.
    pub(super) fn over_limits(
        &self,
        feed: Option<f64>,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        length: f64,
    ) -> (Over, Over) {
        let (Some(f), Some(mode)) = (feed, self.feed_mode) else {
            return (None, None);
        };
        let unit = self.mm_per_unit();
        let rate = match mode {
            FeedMode::PerMinute => Some(f * unit),
            FeedMode::InverseTime => Some(length * f),
            FeedMode::PerRevolution => self.revolutions(start, end).map(|rpm| f * unit * rpm),
        };
        let feed = match (rate, self.machine.max_feed) {
            (Some(rate), Some(max)) if rate > max * (1.0 + 1e-9) => Some((rate, max)),
            _ => None,
        };
        let mut turning = None;
        if mode == FeedMode::InverseTime
            && let (Some(c0), Some(c1), Some(max)) =
                (start[3], end[3], self.machine.max_spindle_rpm)
        {
            let rpm = (c1 - c0).abs() * f / 360.0;
            if rpm > max * (1.0 + 1e-9) {
                turning = Some((rpm, max));
            }
        }
        (feed, turning)
    }

    /// The spindle's speed (rpm) over a move: the stated rpm, or at
    /// constant surface speed the speed at its smaller radius, capped.
    fn revolutions(&self, start: &[Option<f64>; 4], end: &[Option<f64>; 4]) -> Option<f64> {
        if self.css != Some(true) {
            return self.rpm;
        }
        let v = self.css_speed?;
        let r = start[0]?.abs().min(end[0]?.abs());
        let rpm = 1000.0 * v / (2.0 * std::f64::consts::PI * r);
        // Uncapped, the speed at the centre is unbounded: `NoSpeedCap`.
        self.cap.map(|cap| rpm.min(cap))
    }

    /// An arc's words, radii and length (mm), by the controller's rules,
    /// and the arc as the controller makes it.
    #[allow(clippy::too_many_arguments)]
    fn arc(
        &self,
        cw: bool,
        start: &[Option<f64>; 4],
        end: &[Option<f64>; 4],
        centre: &[&Word],
        turns: Option<&Word>,
        span: (usize, usize),
        line: &str,
        out: &mut Vec<Found>,
    ) -> Option<(f64, Path)> {
        let Some(plane) = self.plane else {
            out.push((
                Rule::ModalStateUnstated,
                span,
                "an arc before the plane is stated (G17, G18 or G19)".into(),
                None,
            ));
            return None;
        };
        let (a, b, letters, third) = match plane {
            Plane::Xy => (0, 1, ['I', 'J'], 2),
            Plane::Zx => (2, 0, ['K', 'I'], 1),
            Plane::Yz => (1, 2, ['J', 'K'], 0),
        };
        let mut arc_words = |msg: String, s| out.push((Rule::ArcWords, s, msg, None));
        if !self.arc_planes.contains(&plane) {
            arc_words(
                format!("this dialect has no arcs in the {plane:?} plane"),
                span,
            );
            return None;
        }
        // The radius format (`G2 X… Z… R…`): LinuxCNC's (doc 11.5.5.3) and
        // Fanuc's (an assumption, docs/controllers/fanuc.md: the same
        // convention, R < 0 for more than half a turn); elsewhere R is not
        // a centre word (Sinumerik writes `CR=`).
        let linuxcnc = matches!(
            self.lex.controller,
            Controller::LinuxCnc | Controller::Fanuc
        );
        let radius = centre.iter().find(|w| w.letter == 'R' && linuxcnc);
        let centre: Vec<&Word> = centre
            .iter()
            .copied()
            .filter(|w| !(w.letter == 'R' && linuxcnc))
            .collect();
        if let (Some(r), Some(w)) = (radius, centre.first()) {
            arc_words(
                format!(
                    "`{}` and `{}`: an arc is given by its centre or by its radius, not both",
                    w.text(line),
                    r.text(line)
                ),
                r.span,
            );
            return None;
        }
        if let Some(w) = centre.iter().find(|w| !letters.contains(&w.letter)) {
            arc_words(
                format!(
                    "`{}` in an arc of the {} plane, whose centre words are {} and {}",
                    w.text(line),
                    plane_name(plane),
                    letters[0],
                    letters[1]
                ),
                w.span,
            );
            return None;
        }
        // Heidenhain ISO: an arc without I J K goes about the circle centre
        // an earlier block defined (p. 5-18: "The circle center I, J, K
        // must have been previously defined in the program").
        let defined = (self.lex.controller == Controller::HeidenhainIso
            && self.arc_centre_absolute
            && centre.is_empty()
            && radius.is_none())
        .then(|| (self.circle_centre[a], self.circle_centre[b]));
        let defined = match defined {
            Some((Some(ca), Some(cb))) => Some((ca, cb)),
            _ => None,
        };
        if centre.is_empty() && radius.is_none() && defined.is_none() {
            arc_words("an arc with no centre (I, J or K)".into(), span);
            return None;
        }
        let turns = self.turns(turns, line, out)?;
        let (Some(sa), Some(sb), Some(ea), Some(eb)) = (start[a], start[b], end[a], end[b]) else {
            out.push((
                Rule::PositionUnknown,
                span,
                format!(
                    "an arc from a point the program never stated (its {} or {} is unknown here): its centre and radius depend on where the tool happens to stand",
                    AXIS[a], AXIS[b]
                ),
                Some("move to a stated position, absolute, before the arc".into()),
            ));
            return None;
        };
        let unit = self.mm_per_unit();
        let word = |l: char| {
            centre
                .iter()
                .find(|w| w.letter == l)
                .map(|w| w.value * unit)
        };
        let (ca, cb) = if let Some(r) = radius {
            self.radius_centre(cw, (sa, sb), (ea, eb), r.value * unit, r.span, out)?
        } else if let Some((ca, cb)) = defined {
            (ca, cb)
        } else if self.arc_centre_absolute {
            (
                word(letters[0]).unwrap_or(sa),
                word(letters[1]).unwrap_or(sb),
            )
        } else {
            (
                sa + word(letters[0]).unwrap_or(0.0),
                sb + word(letters[1]).unwrap_or(0.0),
            )
        };
        let r1 = (sa - ca).hypot(sb - cb);
        let r2 = (ea - ca).hypot(eb - cb);
        self.arc_radii(r1, r2, (sa, sb) == (ea, eb), span, out);
        let turn = {
            let t = (eb - cb).atan2(ea - ca) - (sb - cb).atan2(sa - ca);
            let tau = std::f64::consts::TAU;
            let t = if cw {
                (-t).rem_euclid(tau)
            } else {
                t.rem_euclid(tau)
            };
            (if t == 0.0 { tau } else { t }) + tau * (turns - 1) as f64
        };
        let rise = match (start[third], end[third]) {
            (Some(p), Some(q)) => q - p,
            _ => 0.0,
        };
        let arc = Path::Arc {
            plane,
            centre: (ca, cb),
            cw,
            turn,
        };
        Some(((0.5 * (r1 + r2) * turn).hypot(rise), arc))
    }

    /// The turns an arc's P word asks (LinuxCNC, doc 11.5.5: a whole
    /// number, 1 or more; 1 when there is none); `None`, refused, for any
    /// other P.
    fn turns(&self, p: Option<&Word>, line: &str, out: &mut Vec<Found>) -> Option<u32> {
        let Some(p) = p else {
            return Some(1);
        };
        let whole = (p.value - p.value.round()).abs() < 1e-4;
        if self.lex.controller == Controller::LinuxCnc && whole && p.value >= 1.0 {
            return Some(p.value.round().min(1e6) as u32);
        }
        out.push((
            Rule::ArcWords,
            p.span,
            format!(
                "`{}`: an arc's P is its number of turns, a whole number from 1",
                p.text(line)
            ),
            None,
        ));
        None
    }

    /// The centre of a radius-format arc from `s` to `e` (in the plane's
    /// order) of radius `r` (mm): LinuxCNC's `arc_data_r` — on the right
    /// of the chord for G2 and a positive R (under half a turn), on the
    /// left for G3, the other side for a negative R. Refused: an end at
    /// the start, or a radius too small to reach the end (beyond 0.0001).
    fn radius_centre(
        &self,
        cw: bool,
        s: (f64, f64),
        e: (f64, f64),
        r: f64,
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) -> Option<(f64, f64)> {
        let (dx, dy) = (e.0 - s.0, e.1 - s.1);
        let half = 0.5 * dx.hypot(dy);
        if half == 0.0 {
            out.push((
                Rule::ArcWords,
                span,
                "a radius-format arc that ends where it starts: it has no centre, and the controller refuses it".into(),
                Some("give a full circle by its centre (I, J, K)".into()),
            ));
            return None;
        }
        if r.abs() < half - 1e-4 || !r.is_finite() {
            out.push((
                Rule::ArcRadiusMismatch,
                span,
                format!(
                    "R {} mm cannot reach the arc's end, {} mm away: the controller refuses it",
                    num(r),
                    num(2.0 * half)
                ),
                None,
            ));
            return None;
        }
        let h = (r * r - half * half).max(0.0).sqrt();
        // The chord's unit vector, turned a quarter to its right.
        let (ux, uy) = (dx / (2.0 * half), dy / (2.0 * half));
        let right = if cw == (r > 0.0) { 1.0 } else { -1.0 };
        let mid = (s.0 + 0.5 * dx, s.1 + 0.5 * dy);
        Some((mid.0 + right * h * uy, mid.1 - right * h * ux))
    }

    fn arc_radii(
        &self,
        r1: f64,
        r2: f64,
        closed: bool,
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) {
        let zero = match self.lex.controller {
            Controller::LinuxCnc => 0.00127,
            _ => 1e-6,
        };
        if r1 < zero || r2 < zero {
            out.push((
                Rule::ZeroRadiusArc,
                span,
                format!(
                    "an arc of radius {} mm: the controller refuses a zero-radius arc",
                    num(r1.min(r2))
                ),
                None,
            ));
            return;
        }
        if closed {
            out.push((
                Rule::FullCircle,
                span,
                format!("this arc ends where it starts: the controller cuts a full circle of radius {} mm", num(r1)),
                Some("an arc meant to have no length should be left out".into()),
            ));
        }
        let diff = (r1 - r2).abs();
        let (bad, limit) = match self.lex.controller {
            Controller::LinuxCnc => {
                let abs = 2.0 * 0.01 * std::f64::consts::SQRT_2;
                let rel = diff / r1.max(r2);
                (diff > abs * 100.0 || (rel > 0.001 && diff > abs), abs)
            }
            Controller::Siemens => {
                let limit = 0.01f64.max(0.001 * r1.max(r2));
                (diff > limit, limit)
            }
            _ => (diff > self.arc_tolerance, self.arc_tolerance),
        };
        if bad {
            out.push((
                Rule::ArcRadiusMismatch,
                span,
                format!(
                    "the arc's radius is {} mm at its start and {} mm at its end; the controller allows {} mm",
                    num(r1),
                    num(r2),
                    num(limit)
                ),
                None,
            ));
        }
    }
}

/// A figure above its limit, with the limit.
pub(super) type Over = Option<(f64, f64)>;

/// The block's axis words (X, Y, Z, C), in order.
fn axes(b: &Block) -> impl Iterator<Item = &Word> {
    b.words.iter().filter(|w| LETTERS.contains(&w.letter))
}

fn plane_name(p: Plane) -> &'static str {
    match p {
        Plane::Xy => "XY (G17)",
        Plane::Zx => "ZX (G18)",
        Plane::Yz => "YZ (G19)",
    }
}

/// A figure for a message: up to 7 decimals, no trailing zeros.
fn num(v: f64) -> String {
    let s = format!("{v:.7}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

impl State {
    /// The points (X, Y in mm) of the spline of block `b` from `s` to `e`,
    /// its first point `s` and its last `e`; `None` (with the finding)
    /// where the controller refuses the block.
    pub(crate) fn spline(
        &mut self,
        kind: super::spline::Spline,
        b: &Block,
        s: (f64, f64),
        e: (f64, f64),
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) -> Option<Vec<(f64, f64)>> {
        let unit = self.mm_per_unit();
        let word = |l: char| {
            b.words
                .iter()
                .find(|w| w.letter == l)
                .map(|w| w.value * unit)
        };
        let mut refuse = |msg: &str| {
            out.push((Rule::ArcWords, span, msg.to_string(), None));
            None
        };
        if self.plane != Some(crate::moves::Plane::Xy) {
            return refuse("G5 and G5.1 are splines in the XY plane (G17) only");
        }
        if b.words.iter().any(|w| {
            !matches!(
                w.letter,
                'G' | 'X' | 'Y' | 'I' | 'J' | 'P' | 'Q' | 'F' | 'S' | 'T' | 'M' | 'N'
            )
        }) {
            return refuse("a spline moves X and Y only: another axis word is refused");
        }
        let (i, j) = (word('I'), word('J'));
        let first = match kind {
            // The manual refuses I and J both left out or zero; `rs274`
            // 2.9 runs it, as a straight line.
            super::spline::Spline::Quadratic => (s.0 + i.unwrap_or(0.0), s.1 + j.unwrap_or(0.0)),
            super::spline::Spline::Cubic => match (i, j, self.last_spline_pq) {
                (Some(i), Some(j), _) => (s.0 + i, s.1 + j),
                (None, None, Some((p, q))) => (s.0 - p, s.1 - q),
                // The manual refuses I and J left out in the first G5 of a
                // series; `rs274` 2.9 runs it with I0 J0.
                (None, None, None) => s,
                _ => return refuse("G5 with one of I and J: give both or neither"),
            },
        };
        let points = match kind {
            super::spline::Spline::Quadratic => {
                self.last_spline_pq = None;
                super::spline::bezier(&[s, first, e])
            }
            super::spline::Spline::Cubic => {
                let (Some(p), Some(q)) = (word('P'), word('Q')) else {
                    return refuse("G5 needs both P and Q");
                };
                self.last_spline_pq = Some((p, q));
                super::spline::bezier(&[s, first, (e.0 + p, e.1 + q), e])
            }
        };
        Some(points)
    }
}

/// Where a feed finding points: the block's F word, else the whole move
/// (`span`), whose feed was modal from an earlier block.
fn feed_span(b: &Block, span: (usize, usize)) -> (usize, usize) {
    b.words
        .iter()
        .find(|w| w.letter == 'F')
        .map_or(span, |w| w.span)
}
