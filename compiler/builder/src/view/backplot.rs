//! The backplot of a program: the moves the controller makes, read from
//! the program's text by the same reader as `lensc verify` and the build's
//! read-back, thinned for drawing to a bounded number of segments — every
//! rapid kept, every pass's first and last point kept, the cutting moves
//! between them taken one in `stride` — with the counts that say how much
//! was drawn of how much.

use std::io::BufRead;

use lensc_runtime::moves::Plane;
use lensc_runtime::reader::{Executed, Path, Reader};

use crate::output::ProgramText;
use crate::read_back::ReadBack;

/// The most cutting segments drawn (rapids and pass ends come on top).
pub const SEGMENT_BUDGET: usize = 200_000;
/// The most points of a backplot whatever the program: past this the rest
/// of the program is not drawn (and the page says so).
pub const POINT_CAP: usize = 2 * SEGMENT_BUDGET;
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
    /// Cutting moves drawn as one segment (1: every one drawn).
    pub stride: usize,
    /// The program was longer than `POINT_CAP` points: its rest is not
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
/// `lines` (the program's, or an upper bound) sets the stride.
pub fn read(program: &ProgramText, read: &ReadBack, lines: usize) -> std::io::Result<Backplot> {
    let mut reader = Reader::new(&read.dialect, &read.machine);
    reader.keep_moves();
    let mut thin = Thinning::new(read.machine.lathe, stride(lines));
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

/// Cutting moves per drawn segment for a program of `lines` lines.
pub fn stride(lines: usize) -> usize {
    lines.div_ceil(SEGMENT_BUDGET).max(1)
}

/// The backplot as it is gathered, move by move.
struct Thinning {
    lathe: bool,
    out: Backplot,
    /// Cutting moves since the last point kept in this pass.
    since_kept: usize,
    /// The last cutting move's end, if not kept (kept at the pass's end).
    pending: Option<[f64; 3]>,
    in_pass: bool,
}

impl Thinning {
    fn new(lathe: bool, stride: usize) -> Thinning {
        Thinning {
            lathe,
            out: Backplot {
                stride,
                ..Backplot::default()
            },
            since_kept: 0,
            pending: None,
            in_pass: false,
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
        if self.out.points.len() >= POINT_CAP {
            self.out.truncated = true;
            return;
        }
        self.out.points.push(p);
        self.out.reached.push(r);
    }

    fn all(&mut self, moves: Vec<Executed>) {
        for m in moves {
            self.one(&m);
        }
    }

    fn end_pass(&mut self) {
        if let Some(p) = self.pending.take() {
            self.push(p, Reached::Feed);
        }
        self.in_pass = false;
        self.since_kept = 0;
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
                self.end_pass();
                self.push(to, Reached::Rapid);
            }
            Path::Line => {
                self.out.feeds += 1;
                self.feed(vec![to]);
            }
            Path::Arc { .. } => {
                self.out.feeds += 1;
                let pieces = arc_points(m)
                    .into_iter()
                    .filter_map(|q| self.place(q.map(Some)))
                    .collect();
                self.feed(pieces);
            }
        }
    }

    /// One cutting move through `points` (its end last).
    fn feed(&mut self, points: Vec<[f64; 3]>) {
        if !self.in_pass {
            self.in_pass = true;
            self.out
                .passes
                .push(self.out.points.len().saturating_sub(1));
        }
        self.since_kept += 1;
        if self.since_kept >= self.out.stride {
            self.since_kept = 0;
            self.pending = None;
            // A thinned run ends on an arc: its pieces, the run's last.
            for p in points {
                self.push(p, Reached::Feed);
            }
        } else {
            self.pending = points.last().copied();
        }
    }

    fn finish(mut self) -> Backplot {
        self.end_pass();
        self.out
    }
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
        let mut t = Thinning::new(false, 10);
        // Two passes of 95 cutting moves, each after a rapid.
        for pass in 0..2 {
            let y = pass as f64;
            t.one(&mv([0.0, y - 1.0, 1.0], [0.0, y, 1.0], Path::Rapid));
            for k in 0..95 {
                let x = k as f64;
                t.one(&mv([x, y, 0.0], [x + 1.0, y, 0.0], Path::Line));
            }
        }
        let b = t.finish();
        assert_eq!((b.rapids, b.feeds), (2, 190));
        assert_eq!(b.passes.len(), 2);
        // Per pass: 9 points every 10 moves and the pass's last (95).
        let feeds = b.reached.iter().filter(|r| **r == Reached::Feed).count();
        assert_eq!(feeds, 2 * 10);
        let rapids = b.reached.iter().filter(|r| **r == Reached::Rapid).count();
        assert_eq!(rapids, 2);
        // Each pass ends where its last move ends.
        let rapid_at = b
            .reached
            .iter()
            .rposition(|r| *r == Reached::Rapid)
            .unwrap();
        assert_eq!(b.points[rapid_at - 1], [95.0, 0.0, 0.0]);
        assert_eq!(*b.points.last().unwrap(), [95.0, 1.0, 0.0]);
        // A pass starts at the rapid's end.
        assert_eq!(b.points[b.passes[1]], [0.0, 1.0, 1.0]);
        assert!(!b.truncated);
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

    #[test]
    fn the_stride_holds_the_budget() {
        assert_eq!(stride(10), 1);
        assert_eq!(stride(SEGMENT_BUDGET), 1);
        assert_eq!(stride(11_000_000), 55);
    }
}
