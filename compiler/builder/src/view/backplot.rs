//! The backplot of a program: the moves the controller makes, read from
//! the program's text by the same reader as `lensc verify` and the build's
//! read-back, thinned for drawing to a bounded number of segments — every
//! rapid kept, every pass's first and last point kept, the cutting moves
//! between them kept where they lie at least `step` from the point kept
//! before (the step doubled whenever the budget is reached, so a program
//! of any length ends with at most `SEGMENT_BUDGET` cutting segments,
//! spread evenly along the path) — with the counts that say how much was
//! drawn of how much.

use std::io::BufRead;

use lensc_runtime::moves::Plane;
use lensc_runtime::reader::{Executed, Path, Reader};

use crate::output::ProgramText;
use crate::read_back::ReadBack;

/// The most cutting segments drawn (rapids and pass ends come on top).
pub const SEGMENT_BUDGET: usize = 200_000;
/// The most rapids drawn: past this the rest of the program is not drawn
/// (and the page says so).
pub const RAPID_CAP: usize = SEGMENT_BUDGET;
/// The most revolutions of a spindle's C axis drawn: past this, one
/// revolution in so many is drawn whole and the others left out (a
/// spiral's revolutions lie microns apart: no screen shows them all).
pub const REVOLUTION_CAP: usize = 400;
/// Pieces an arc is drawn in per quarter turn.
const ARC_PIECES_PER_QUARTER: f64 = 8.0;

/// What a point of the backplot ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reached {
    /// Nothing: the path starts here (the first point, or after a move
    /// whose position is unknown).
    Start = 0,
    /// A rapid (G0).
    Rapid = 1,
    /// A cutting move (line or arc), or several thinned into one.
    Feed = 2,
}

/// A program's moves, thinned for drawing.
#[derive(Clone, Debug, Default)]
pub struct Backplot {
    /// The points in order, in the part's frame (mm): a lathe's X, C and Z
    /// as x = X cos C, y = X sin C, z = Z; a mill's X, Y, Z.
    pub points: Vec<[f64; 3]>,
    /// What reaches each point from the one before.
    pub reached: Vec<Reached>,
    /// The index of each pass's first point (a pass: a run of cutting
    /// moves between rapids).
    pub passes: Vec<usize>,
    /// Moves the controller makes, as read: rapids and cutting moves.
    pub rapids: u64,
    pub feeds: u64,
    /// The least distance (mm) between two points kept inside a pass (0:
    /// every point kept).
    pub step: f64,
    /// One revolution of the C axis drawn in this many (1: all).
    pub revolution_stride: usize,
    /// The program had more than `RAPID_CAP` rapids: its rest is not
    /// drawn.
    pub truncated: bool,
}

impl Backplot {
    /// Segments drawn (every point but the starts).
    pub fn segments(&self) -> usize {
        self.reached
            .iter()
            .filter(|r| **r != Reached::Start)
            .count()
    }
}

/// The backplot of `program` read by `read`'s dialect and machine;
/// `revolutions`, the spindle revolutions its cut turns (a spiral's, from
/// its report), if known.
pub fn read(
    program: &ProgramText,
    read: &ReadBack,
    revolutions: Option<usize>,
) -> std::io::Result<Backplot> {
    let mut reader = Reader::new(&read.dialect, &read.machine);
    reader.keep_moves();
    let mut thin = Thinning::new(read.machine.lathe, SEGMENT_BUDGET);
    thin.out.revolution_stride = revolutions.map_or(1, |n| n.div_ceil(REVOLUTION_CAP).max(1));
    match program {
        ProgramText::Memory(text) => {
            let mut offset = 0;
            for line in text.split_inclusive('\n') {
                reader.line(line, offset);
                offset += line.len();
                thin.all(reader.take_moves());
            }
        }
        ProgramText::Spooled { file, .. } => {
            let mut input =
                std::io::BufReader::with_capacity(1 << 20, std::fs::File::open(file.path())?);
            let (mut line, mut offset) = (String::new(), 0);
            loop {
                line.clear();
                let n = input.read_line(&mut line)?;
                if n == 0 {
                    break;
                }
                reader.line(&line, offset);
                offset += n;
                thin.all(reader.take_moves());
            }
        }
    }
    Ok(thin.finish())
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The backplot as it is gathered, move by move.
struct Thinning {
    lathe: bool,
    budget: usize,
    out: Backplot,
    /// Cutting points kept.
    kept: usize,
    /// The last cutting move's end, if not kept (kept at the pass's end).
    pending: Option<[f64; 3]>,
    in_pass: bool,
    /// Degrees the C axis has turned in cutting moves.
    turned: f64,
    /// Moves left out since the last point drawn (a revolution not drawn).
    gap: bool,
}

impl Thinning {
    fn new(lathe: bool, budget: usize) -> Thinning {
        Thinning {
            lathe,
            budget,
            out: Backplot::default(),
            kept: 0,
            pending: None,
            in_pass: false,
            turned: 0.0,
            gap: false,
        }
    }

    /// The part-frame point of a machine position (X, Y, Z, C); `None`
    /// while a length axis is unknown.
    fn place(&self, p: [Option<f64>; 4]) -> Option<[f64; 3]> {
        if self.lathe {
            let (x, z) = (p[0]?, p[2]?);
            let c = p[3].unwrap_or(0.0).to_radians();
            Some([x * c.cos(), x * c.sin(), z])
        } else {
            Some([p[0]?, p[1].unwrap_or(0.0), p[2]?])
        }
    }

    fn push(&mut self, p: [f64; 3], r: Reached) {
        if r == Reached::Feed {
            self.kept += 1;
        }
        self.out.points.push(p);
        self.out.reached.push(r);
    }

    fn all(&mut self, moves: Vec<Executed>) {
        for m in moves {
            if self.out.truncated {
                return;
            }
            self.one(&m);
        }
    }

    fn end_pass(&mut self) {
        if let Some(p) = self.pending.take() {
            self.push(p, Reached::Feed);
        }
        self.in_pass = false;
    }

    fn one(&mut self, m: &Executed) {
        let (Some(from), Some(to)) = (self.place(m.from), self.place(m.to)) else {
            // A move from or to an unknown place: the path restarts at its
            // end, if known.
            self.end_pass();
            if let Some(to) = self.place(m.to) {
                self.push(to, Reached::Start);
            }
            return;
        };
        if self.out.points.is_empty() {
            self.push(from, Reached::Start);
        }
        match m.path {
            Path::Rapid => {
                self.out.rapids += 1;
                if self.out.rapids as usize > RAPID_CAP {
                    self.out.truncated = true;
                    return;
                }
                self.end_pass();
                if std::mem::take(&mut self.gap) {
                    self.push(from, Reached::Start);
                }
                self.push(to, Reached::Rapid);
            }
            _ if self.left_out(m) => {
                self.out.feeds += 1;
                if !self.in_pass {
                    self.in_pass = true;
                    self.out
                        .passes
                        .push(self.out.points.len().saturating_sub(1));
                }
                if let Some(p) = self.pending.take() {
                    self.push(p, Reached::Feed);
                }
                self.gap = true;
            }
            _ => {
                self.out.feeds += 1;
                if std::mem::take(&mut self.gap) {
                    // The path resumes after the revolutions left out: no
                    // line across them.
                    self.push(from, Reached::Start);
                }
                let pieces: Vec<[f64; 3]> = match m.path {
                    Path::Arc { .. } => arc_points(m),
                    _ => turning_points(m),
                }
                .into_iter()
                .filter_map(|q| self.place(q.map(Some)))
                .collect();
                self.feed(&pieces);
            }
        }
    }

    /// Whether cutting move `m` lies in a revolution not drawn (counting
    /// the C axis's turn).
    fn left_out(&mut self, m: &Executed) -> bool {
        if !self.lathe {
            return false;
        }
        if let (Some(a), Some(b)) = (m.from[3], m.to[3]) {
            self.turned += (b - a).abs();
        }
        let revolution = (self.turned / 360.0).floor() as usize;
        self.out.revolution_stride > 1 && !revolution.is_multiple_of(self.out.revolution_stride)
    }

    /// One cutting move through `points` (its end last).
    fn feed(&mut self, points: &[[f64; 3]]) {
        if !self.in_pass {
            self.in_pass = true;
            self.out
                .passes
                .push(self.out.points.len().saturating_sub(1));
        }
        for &p in points {
            let last = *self.out.points.last().expect("a pass starts at a point");
            if distance(p, last) >= self.out.step {
                self.pending = None;
                self.push(p, Reached::Feed);
            } else {
                self.pending = Some(p);
            }
        }
        if self.kept > self.budget {
            self.coarser();
        }
    }

    /// Doubles the step (or sets it, the first time, so that the path
    /// kept so far would fill half the budget) and thins the points kept
    /// so far by it.
    fn coarser(&mut self) {
        let o = &mut self.out;
        let length: f64 = (1..o.points.len())
            .filter(|&i| o.reached[i] == Reached::Feed)
            .map(|i| distance(o.points[i - 1], o.points[i]))
            .sum();
        o.step = (2.0 * o.step).max(2.0 * length / self.budget as f64);
        let n = o.points.len();
        let mut index = vec![usize::MAX; n];
        let (mut points, mut reached) = (Vec::new(), Vec::new());
        let mut kept = 0;
        for (i, slot) in index.iter_mut().enumerate() {
            let r = o.reached[i];
            // A pass's last point is kept; so is the last point while the
            // pass goes on (the next point is measured from it).
            let pass_end = i + 1 == n || o.reached[i + 1] != Reached::Feed;
            let keep = r != Reached::Feed
                || pass_end
                || distance(o.points[i], *points.last().expect("a start")) >= o.step;
            if keep {
                *slot = points.len();
                points.push(o.points[i]);
                reached.push(r);
                kept += usize::from(r == Reached::Feed);
            }
        }
        for p in &mut o.passes {
            *p = index[*p];
        }
        (o.points, o.reached) = (points, reached);
        self.kept = kept;
    }

    fn finish(mut self) -> Backplot {
        self.end_pass();
        if self.out.revolution_stride == 0 {
            self.out.revolution_stride = 1;
        }
        self.out
    }
}

/// The most degrees of C one drawn piece of a straight move turns: the
/// controller moves every axis linearly, so a move that turns C draws a
/// spiral arc on the part, not a chord.
const C_PIECE_DEG: f64 = 3.0;

/// Points along a straight move (machine X, Y, Z, C), its end last: one,
/// or pieces of at most `C_PIECE_DEG` where it turns C.
fn turning_points(m: &Executed) -> Vec<[f64; 4]> {
    let from = m.from.map(|v| v.unwrap_or(0.0));
    let to = m.to.map(|v| v.unwrap_or(0.0));
    let turn = match (m.from[3], m.to[3]) {
        (Some(a), Some(b)) => (b - a).abs(),
        _ => 0.0,
    };
    let n = (turn / C_PIECE_DEG).ceil().clamp(1.0, 3600.0) as usize;
    (1..=n)
        .map(|k| {
            if k == n {
                return to;
            }
            let f = k as f64 / n as f64;
            std::array::from_fn(|i| from[i] + f * (to[i] - from[i]))
        })
        .collect()
}

/// Points along an arc move (machine X, Y, Z, C), its end last: the
/// plane's two coordinates turned about the centre, the radius blended
/// from start to end as the controller blends it, the other axes
/// linear.
fn arc_points(m: &Executed) -> Vec<[f64; 4]> {
    let Path::Arc {
        plane,
        centre,
        cw,
        turn,
    } = m.path
    else {
        return Vec::new();
    };
    let from = m.from.map(|v| v.unwrap_or(0.0));
    let to = m.to.map(|v| v.unwrap_or(0.0));
    let (a, b) = Plane::axes(plane);
    let (r0, r1) = (
        (from[a] - centre.0).hypot(from[b] - centre.1),
        (to[a] - centre.0).hypot(to[b] - centre.1),
    );
    let start = (from[b] - centre.1).atan2(from[a] - centre.0);
    let sweep = if cw { -turn } else { turn };
    let n = (turn.abs() / std::f64::consts::FRAC_PI_2 * ARC_PIECES_PER_QUARTER)
        .ceil()
        .clamp(1.0, 256.0) as usize;
    (1..=n)
        .map(|k| {
            if k == n {
                return to;
            }
            let f = k as f64 / n as f64;
            let (t, r) = (start + f * sweep, r0 + f * (r1 - r0));
            let mut p: [f64; 4] = std::array::from_fn(|i| from[i] + f * (to[i] - from[i]));
            p[a] = centre.0 + r * t.cos();
            p[b] = centre.1 + r * t.sin();
            p
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mv(from: [f64; 3], to: [f64; 3], path: Path) -> Executed {
        Executed {
            from: [Some(from[0]), Some(from[1]), Some(from[2]), None],
            to: [Some(to[0]), Some(to[1]), Some(to[2]), None],
            path,
        }
    }

    #[test]
    fn thinning_keeps_rapids_and_pass_ends_and_bounds_the_rest() {
        let mut t = Thinning::new(false, 100);
        // Two passes of 950 cutting moves 0.01 mm long, each after a rapid.
        for pass in 0..2 {
            let y = pass as f64;
            t.one(&mv([0.0, y - 1.0, 1.0], [0.0, y, 1.0], Path::Rapid));
            for k in 0..950 {
                let x = k as f64 * 0.01;
                t.one(&mv([x, y, 0.0], [x + 0.01, y, 0.0], Path::Line));
            }
        }
        let b = t.finish();
        assert_eq!((b.rapids, b.feeds), (2, 1900));
        assert_eq!(b.passes.len(), 2);
        let feeds = b.reached.iter().filter(|r| **r == Reached::Feed).count();
        assert!((50..=100).contains(&feeds), "{feeds} cutting points kept");
        assert!(b.step > 0.01, "{}", b.step);
        let rapids = b.reached.iter().filter(|r| **r == Reached::Rapid).count();
        assert_eq!(rapids, 2);
        // Each pass ends where its last move ends.
        let rapid_at = b
            .reached
            .iter()
            .rposition(|r| *r == Reached::Rapid)
            .unwrap();
        assert!((b.points[rapid_at - 1][0] - 9.5).abs() < 1e-9);
        assert!((b.points.last().unwrap()[0] - 9.5).abs() < 1e-9);
        // A pass starts at the rapid's end.
        assert_eq!(b.points[b.passes[1]], [0.0, 1.0, 1.0]);
        assert_eq!(b.points[b.passes[0]], [0.0, 0.0, 1.0]);
        // Evenly: no two cutting points in a pass closer than the step,
        // but for a pass's last.
        for i in 1..b.points.len() - 1 {
            if b.reached[i] == Reached::Feed && b.reached[i + 1] == Reached::Feed {
                assert!(distance(b.points[i - 1], b.points[i]) >= b.step - 1e-12);
            }
        }
        assert!(!b.truncated);
    }

    #[test]
    fn a_spiral_is_drawn_one_revolution_in_so_many_with_no_line_across_the_rest() {
        let mut t = Thinning::new(true, 1000);
        t.out.revolution_stride = 3;
        // Ten revolutions of 36 moves of 10°, the radius falling 0.01 mm
        // a revolution.
        let at = |k: usize| {
            let c = 10.0 * k as f64;
            [Some(1.0 - c / 36_000.0), Some(0.0), Some(0.0), Some(c)]
        };
        for k in 0..360 {
            t.one(&Executed {
                from: at(k),
                to: at(k + 1),
                path: Path::Line,
            });
        }
        let b = t.finish();
        assert_eq!(b.feeds, 360);
        // Revolutions 0, 3, 6 and 9 drawn (the first move of each starts
        // it after a gap, but the very first).
        let starts = b.reached.iter().filter(|r| **r == Reached::Start).count();
        assert_eq!(starts, 4);
        // Revolution 0 ends a move early (its 36th move completes the
        // turn), 3, 6 and 9 have 36 moves each; each 10° move is drawn
        // in four pieces of at most `C_PIECE_DEG`.
        assert_eq!(b.segments(), 4 * (4 * 36 - 1));
        // No segment longer than a 10° chord of the unit circle.
        for i in 1..b.points.len() {
            if b.reached[i] == Reached::Feed {
                assert!(distance(b.points[i - 1], b.points[i]) < 0.18, "{i}");
            }
        }
    }

    #[test]
    fn a_move_that_turns_c_is_drawn_round_the_spindle() {
        // One revolution at X 2 in one straight move, as a spiral's first
        // moves are written (`G1 X.. C360.`).
        let mut t = Thinning::new(true, 1000);
        t.one(&Executed {
            from: [Some(2.0), None, Some(0.0), Some(0.0)],
            to: [Some(2.0), None, Some(0.0), Some(360.0)],
            path: Path::Line,
        });
        let b = t.finish();
        assert_eq!(b.segments(), 120);
        for p in &b.points {
            assert!((p[0].hypot(p[1]) - 2.0).abs() < 1e-12, "{p:?}");
        }
        let far = b.points.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
        assert!((far + 2.0).abs() < 1e-12, "reaches the far side: {far}");
    }

    #[test]
    fn a_short_program_is_drawn_whole() {
        let mut t = Thinning::new(false, 100);
        t.one(&mv([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], Path::Rapid));
        for k in 0..10 {
            let x = k as f64;
            t.one(&mv([x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], Path::Line));
        }
        let b = t.finish();
        assert_eq!(b.step, 0.0);
        assert_eq!(b.points.len(), 12);
        assert_eq!(b.segments(), 11);
    }

    #[test]
    fn an_arc_is_drawn_on_its_circle_and_ends_at_its_end() {
        // A quarter turn in ZX (Z, X order) about the origin, from X1 to Z1.
        let m = Executed {
            from: [Some(1.0), Some(0.0), Some(0.0), None],
            to: [Some(0.0), Some(0.0), Some(1.0), None],
            path: Path::Arc {
                plane: Plane::Zx,
                centre: (0.0, 0.0),
                cw: true,
                turn: std::f64::consts::FRAC_PI_2,
            },
        };
        let pts = arc_points(&m);
        assert_eq!(pts.len(), 8);
        for p in &pts {
            assert!((p[0].hypot(p[2]) - 1.0).abs() < 1e-12, "{p:?}");
        }
        assert_eq!(*pts.last().unwrap(), [0.0, 0.0, 1.0, 0.0]);
    }
}
