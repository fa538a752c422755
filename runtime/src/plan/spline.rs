//! Splines in the move stream: runs of straight cutting moves refitted as
//! clamped cubic B-splines (order 4, unit weights) of the form Fanuc's
//! G06.2 takes (docs/controllers/fanuc.md): the first control point is
//! where the run starts, the last where it ends, the first four knots
//! equal and the last four equal. Each run is fitted by least squares
//! with its two ends held (Piegl and Tiller, *The NURBS Book*, 2nd ed.,
//! 1997, §9.4.1, eqs. 9.63–9.69: chord-length parameters, knots by
//! averaging so every span holds points), with as few control points as
//! hold the fit within its share of the tolerance, found by doubling and
//! then halving the interval. Knots and control points are rounded as the
//! program prints them (the dialect's decimals, the control point's
//! offset added first) and the fit is checked again after rounding: every
//! planned point, and the middle of each chord's arc (the circle through
//! the chord's ends and a neighbour, standing for the exact path between
//! planned points), must lie within the share plus the rounding the same
//! points get when printed as lines. A run that cannot be held, or whose
//! spline would take as many blocks as its lines, stays lines. The
//! controller's evaluation of the curve is not this file's: the reader
//! evaluates it from the program's text (`reader/nurbs.rs`).

use crate::moves::{ControlOffset, Feed, Move, Position, Spline, Step};

/// Order (degree + 1) of the splines written.
pub const ORDER: usize = 4;
const DEGREE: usize = ORDER - 1;

/// The fewest straight moves a run needs to be fitted: below it a spline
/// (at least four control points and four knot blocks) saves nothing.
pub const FEWEST_LINES: usize = 16;

/// Consecutive moves turning more than this (cosine of the angle, 25°)
/// break a run: a corner (a plunge, a lift) is kept sharp.
const CORNER_COS: f64 = 0.906;

/// What a fit is held to.
#[derive(Clone, Copy, Debug)]
pub struct SplineFit {
    /// The fit's share of the path tolerance (mm).
    pub tolerance: f64,
    /// Decimals of the printed axes and knots.
    pub decimals: u32,
    /// The control point's offset from the tool centre, added before
    /// rounding as the writer adds it.
    pub control: ControlOffset,
    /// How the interior knots are placed.
    pub knots: KnotSpacing,
}

/// Where a fit's interior knots go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KnotSpacing {
    /// By averaging the points' parameters (Piegl and Tiller eq. 9.69),
    /// each knot printed (Fanuc's G06.2 states every knot, K).
    Averaged,
    /// Equally spaced, the spacing rounded to the printed decimals:
    /// Siemens' BSPLINE states a knot spacing PL per block, and which
    /// knot interval a block's PL sets is not stated in the manual; with
    /// every spacing equal the curve is the same whichever it is
    /// (docs/controllers/siemens.md).
    Uniform,
}

impl KnotSpacing {
    /// How `dialect`'s spline places its knots: Fanuc's G06.2 states each
    /// knot, Siemens' BSPLINE one spacing (PL) that lensc keeps equal.
    pub fn of(dialect: &crate::dialect::Dialect) -> KnotSpacing {
        match dialect.spline {
            Some(crate::dialect::SplineForm::Bspline) => KnotSpacing::Uniform,
            _ => KnotSpacing::Averaged,
        }
    }
}

impl SplineFit {
    /// The rounding a printed point gets: half a unit of the last decimal
    /// on each of three axes.
    pub fn rounding(&self) -> f64 {
        0.5 * 10f64.powi(-(self.decimals as i32)) * 3f64.sqrt()
    }
}

/// What the fitting did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Program blocks of the moves before (one each) and after (a spline
    /// takes one block per control point and one per end knot).
    pub blocks_before: usize,
    pub blocks_after: usize,
    pub splines: usize,
    /// Straight moves the splines replaced.
    pub lines_replaced: usize,
    /// The largest distance (mm) of a planned point or chord's arc middle
    /// from its spline as printed (rounded).
    pub max_deviation: f64,
    /// What that distance was held to (mm): the share plus the rounding.
    pub limit: f64,
}

/// The lines and arcs a run would be written as otherwise: the
/// optimiser's fit (`plan::optimise`) of the run, its arcs only in
/// `arc_planes`, held above the polyline with `above`. A spline is written
/// only where it takes fewer blocks than these.
#[derive(Clone, Copy, Debug)]
pub struct Otherwise<'a> {
    pub arc_planes: &'a [crate::moves::Plane],
    pub above: bool,
}

/// Fits every run of straight cutting moves of `moves` it can; with
/// `otherwise`, every run is written as the optimiser's lines and arcs
/// where those take no more blocks than its spline (or it has none).
///
/// The runs are fitted in parallel (rayon), each from where the moves
/// before it leave the tool; the steps are put together in order, and a
/// run whose start the steps before it do not leave where the moves do
/// is fitted again from there: the steps are the same, to the bit,
/// whatever the threads (`fit_splines_serial` fits one run after the
/// other, as the tests compare).
pub fn fit_splines(
    moves: &[Move],
    fit: &SplineFit,
    otherwise: Option<Otherwise<'_>>,
) -> (Vec<Step>, Summary) {
    use rayon::prelude::*;
    let start = start_of(moves);
    // Where each run starts (its first move and where the tool is), the
    // tool followed through the moves as they are.
    let mut runs = Vec::new();
    let (mut i, mut at) = (0, start);
    while i < moves.len() {
        let (end, _) = run(moves, i, at);
        if end > i {
            runs.push((i, at));
        }
        let next = end.max(i + 1);
        for m in &moves[i..next] {
            if let Move::Rapid(to) | Move::Linear { to, .. } | Move::Arc { to, .. } = m {
                at = merged(at, to);
            }
        }
        i = next;
    }
    if runs.len() < 2 {
        return fit_splines_serial(moves, fit, otherwise);
    }
    let no_y = !start[1].is_nan();
    let pieces: Vec<Piece> = runs
        .par_iter()
        .map(|&(i, at)| piece(moves, i, at, no_y, fit, otherwise))
        .collect();
    let mut taken = runs.iter().zip(pieces).peekable();
    assemble(
        moves,
        fit,
        start,
        |i, at| {
            while taken.next_if(|((j, _), _)| *j < i).is_some() {}
            match taken.peek() {
                Some(((j, a), _)) if *j == i && same(*a, at) => taken.next().map(|(_, p)| p),
                _ => None,
            }
        },
        otherwise,
    )
}

/// `fit_splines` one run after the other, on this thread.
pub fn fit_splines_serial(
    moves: &[Move],
    fit: &SplineFit,
    otherwise: Option<Otherwise<'_>>,
) -> (Vec<Step>, Summary) {
    assemble(moves, fit, start_of(moves), |_, _| None, otherwise)
}

/// Whether two positions are the same to the bit (an unknown axis, NaN,
/// the same as another).
fn same(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Whether no move of `moves` states Y (a lathe's).
fn no_y(moves: &[Move]) -> bool {
    moves.iter().all(|m| match m {
        Move::Rapid(to) | Move::Linear { to, .. } | Move::Arc { to, .. } => to.y.is_nan(),
        _ => true,
    })
}

/// Where the tool is before `moves`: unknown, but in Y = 0 if no move
/// states Y (a lathe's moves: the curve lies in Y = 0).
fn start_of(moves: &[Move]) -> [f64; 3] {
    let mut at = [f64::NAN; 3];
    if no_y(moves) {
        at[1] = 0.0;
    }
    at
}

/// What one run (or one move that is no run) is written as: where it
/// ends in the moves (exclusive), its steps, where they leave the tool,
/// and its spline's straight moves replaced and deviation, if fitted.
struct Piece {
    end: usize,
    steps: Vec<Step>,
    at: [f64; 3],
    fitted: Option<(usize, f64)>,
}

/// The steps from `start`, run by run, each taken from `ready` (fitted
/// ahead, from the move it starts at and where the tool is) or fitted
/// here.
fn assemble(
    moves: &[Move],
    fit: &SplineFit,
    start: [f64; 3],
    mut ready: impl FnMut(usize, [f64; 3]) -> Option<Piece>,
    otherwise: Option<Otherwise<'_>>,
) -> (Vec<Step>, Summary) {
    let mut out = Vec::with_capacity(moves.len() / 4);
    let mut summary = Summary {
        blocks_before: moves.len(),
        limit: fit.tolerance + fit.rounding(),
        ..Summary::default()
    };
    let no_y = !start[1].is_nan();
    let mut at = start;
    let mut i = 0;
    while i < moves.len() {
        let p = ready(i, at).unwrap_or_else(|| piece(moves, i, at, no_y, fit, otherwise));
        if let Some((lines, deviation)) = p.fitted {
            summary.splines += 1;
            summary.lines_replaced += lines;
            summary.max_deviation = summary.max_deviation.max(deviation);
        }
        out.extend(p.steps);
        at = p.at;
        i = p.end;
    }
    summary.blocks_after = out
        .iter()
        .map(|s| match s {
            Step::Move(_) => 1,
            Step::Spline(s) => s.points.len() + s.order,
        })
        .sum();
    (out, summary)
}

/// The run of straight cutting moves starting at `moves[i]` (from `at`)
/// as a spline, or as lines and arcs, or as it is (or the one move that is
/// no run).
fn piece(
    moves: &[Move],
    i: usize,
    at: [f64; 3],
    no_y: bool,
    fit: &SplineFit,
    otherwise: Option<Otherwise<'_>>,
) -> Piece {
    let (run_end, feed) = run(moves, i, at);
    // The run as lines and arcs, where those are the other way.
    let lines_arcs = otherwise.filter(|_| run_end > i).map(|o| {
        let mut stream = Vec::with_capacity(run_end - i + 1);
        stream.push(Move::Rapid(if no_y {
            Position::xz(at[0], at[2])
        } else {
            Position::xyz(at[0], at[1], at[2])
        }));
        stream.extend_from_slice(&moves[i..run_end]);
        // The optimiser starts a run at a stated feed: a run that
        // keeps the feed in force is given one for the fit (any: one
        // feed for the whole run), and keeps the one in force again.
        let first_feed = match moves[i] {
            Move::Linear { feed, .. } => feed,
            _ => None,
        };
        if let Some(Move::Linear { feed, .. }) = stream.get_mut(1)
            && feed.is_none()
        {
            *feed = Some(Feed::PerTime(1.0));
        }
        let (mut opt, _) =
            super::optimise::optimise_within(&stream, fit.tolerance, o.arc_planes, o.above);
        opt.remove(0);
        if let Some(Move::Linear { feed, .. } | Move::Arc { feed, .. }) = opt.first_mut() {
            *feed = first_feed;
        }
        opt
    });
    if run_end - i >= FEWEST_LINES && !fed_per_revolution(moves, i, feed) {
        let mut points = Vec::with_capacity(run_end - i + 1);
        points.push(at);
        let mut p = at;
        for m in &moves[i..run_end] {
            if let Move::Linear { to, .. } = m {
                p = merged(p, to);
                points.push(p);
            }
        }
        // A spline of n control points takes n + ORDER blocks: fewer
        // than the lines and arcs' if n is below this.
        let fewer = lines_arcs
            .as_ref()
            .map_or(usize::MAX, |l| l.len().saturating_sub(ORDER));
        if let Some((spline, deviation)) = fit_run(&points, fit, fewer)
            && spline.points.len() < fewer
        {
            return Piece {
                end: run_end,
                steps: vec![Step::Spline(Spline { feed, ..spline })],
                at: p,
                fitted: Some((run_end - i, deviation)),
            };
        }
    }
    // Not fitted: the run as lines and arcs, or as it is (or the one
    // move that is no run).
    let kept = lines_arcs
        .as_deref()
        .unwrap_or(&moves[i..run_end.max(i + 1)]);
    let mut at = at;
    for &m in kept {
        if let Move::Rapid(to) | Move::Linear { to, .. } | Move::Arc { to, .. } = m {
            at = merged(at, &to);
        }
    }
    Piece {
        end: run_end.max(i + 1),
        steps: kept.iter().map(|&m| Step::Move(m)).collect(),
        at,
        fitted: None,
    }
}

/// Whether the run starting at `moves[i]` with the feed `feed` (its own,
/// if it states one) is fed per revolution, stated or in force (the last
/// feed stated before it): a spline is written fed per minute only (the
/// writer's `spline_blocks`), so such a run is written as lines and arcs.
fn fed_per_revolution(moves: &[Move], i: usize, feed: Option<Feed>) -> bool {
    let in_force = feed.or_else(|| {
        moves[..i].iter().rev().find_map(|m| match m {
            Move::Linear { feed, .. } | Move::Arc { feed, .. } => *feed,
            _ => None,
        })
    });
    matches!(in_force, Some(Feed::PerRevolution(_)))
}

/// `at` moved to `to` (an axis `to` leaves alone stays).
fn merged(at: [f64; 3], to: &Position) -> [f64; 3] {
    let mut p = at;
    for (v, t) in p.iter_mut().zip([to.x, to.y, to.z]) {
        if !t.is_nan() {
            *v = t;
        }
    }
    p
}

/// Where the run of straight cutting moves starting at `moves[i]` (from
/// `at`) ends (exclusive), and its feed: one feed (per minute or per
/// revolution: only the first is fitted as a spline, the second is still
/// a run of lines and arcs), no C, a known start, no corner.
fn run(moves: &[Move], i: usize, at: [f64; 3]) -> (usize, Option<Feed>) {
    if at.iter().any(|v| v.is_nan()) {
        return (i, None);
    }
    let mut feed = None;
    let mut prev = at;
    let mut dir: Option<[f64; 3]> = None;
    let mut j = i;
    while let Some(Move::Linear { to, feed: f }) = moves.get(j) {
        if !to.c.is_nan() {
            break;
        }
        match (f, feed) {
            (Some(f @ (Feed::PerTime(_) | Feed::PerRevolution(_))), _) if j == i => feed = Some(*f),
            (None, _) => {}
            (Some(f), Some(g)) if *f == g => {}
            _ => break,
        }
        let p = merged(prev, to);
        let d = [p[0] - prev[0], p[1] - prev[1], p[2] - prev[2]];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if len == 0.0 {
            break;
        }
        let d = [d[0] / len, d[1] / len, d[2] / len];
        if let Some(e) = dir
            && d[0] * e[0] + d[1] * e[1] + d[2] * e[2] < CORNER_COS
        {
            break;
        }
        dir = Some(d);
        prev = p;
        j += 1;
    }
    (j, feed)
}

/// The spline with the fewest control points that holds `points` within
/// the fit's limits, and its largest deviation; none if it would not save
/// blocks. The search stops, with none, once what it would find takes
/// `fewer` control points or more (where the run's lines and arcs would
/// be written instead); what it finds otherwise is the same.
fn fit_run(points: &[[f64; 3]], fit: &SplineFit, fewer: usize) -> Option<(Spline, f64)> {
    let lines = points.len() - 1;
    // A spline of n control points takes n + 4 blocks: it must take fewer
    // than half the lines' blocks to be worth writing.
    let most = (lines / 2).checked_sub(ORDER)?;
    if most < ORDER {
        return None;
    }
    let params = chord_params(points);
    let arcs = arc_middles(points);
    let try_n = |n: usize| fitted(points, &params, &arcs, n, fit);
    // Doubling, then halving the interval between a failure and a success:
    // what is found takes more control points than the last failure.
    let mut fail = ORDER - 1;
    let too_many = |fail: usize| fail + 1 >= fewer;
    if too_many(fail) {
        return None;
    }
    let mut n = ORDER;
    let mut best = loop {
        if let Some(b) = try_n(n) {
            break b;
        }
        fail = n;
        if n == most || too_many(fail) {
            return None;
        }
        n = (n * 2).min(most);
    };
    let mut ok = n;
    while ok - fail > 1 {
        let mid = (ok + fail) / 2;
        match try_n(mid) {
            Some(b) => {
                best = b;
                ok = mid;
            }
            None if too_many(mid) => return None,
            None => fail = mid,
        }
    }
    Some(best)
}

/// Chord-length parameters of the points (mm from the first, along the
/// polyline).
fn chord_params(points: &[[f64; 3]]) -> Vec<f64> {
    let mut u = Vec::with_capacity(points.len());
    let mut s = 0.0;
    u.push(0.0);
    for w in points.windows(2) {
        s += dist(w[0], w[1]);
        u.push(s);
    }
    u
}

/// For each chord, the middle of the circle's arc through its ends and a
/// neighbouring point (the next, or for the last chord the one before):
/// where the exact path between two planned points is taken to run.
fn arc_middles(points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    (0..points.len() - 1)
        .map(|k| {
            let (a, b) = (points[k], points[k + 1]);
            let c = if k + 2 < points.len() {
                points[k + 2]
            } else if k > 0 {
                points[k - 1]
            } else {
                return mid(a, b);
            };
            circle_arc_middle(a, b, c).unwrap_or_else(|| mid(a, b))
        })
        .collect()
}

fn mid(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        (a[0] + b[0]) / 2.0,
        (a[1] + b[1]) / 2.0,
        (a[2] + b[2]) / 2.0,
    ]
}

/// The middle of the arc from `a` to `b` of the circle through `a`, `b`
/// and `c`, on the side away from `c`'s arc; none for three points in a
/// line.
fn circle_arc_middle(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[f64; 3]> {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let n = cross(ab, ac);
    let nn = dot(n, n);
    if nn <= 1e-30 * dot(ab, ab) * dot(ac, ac) {
        return None;
    }
    // Circumcentre of a, b, c.
    let t = add(
        scale(cross(n, ab), dot(ac, ac)),
        scale(cross(ac, n), dot(ab, ab)),
    );
    let centre = add(a, scale(t, 0.5 / nn));
    let r = dist(centre, a);
    let m = mid(a, b);
    let d = sub(m, centre);
    let dl = dot(d, d).sqrt();
    if dl == 0.0 {
        return None;
    }
    // The minor arc from a to b (c lies beyond b, on the same circle).
    Some(add(centre, scale(d, r / dl)))
}

/// The fit with `n` control points, rounded, if it holds.
fn fitted(
    points: &[[f64; 3]],
    params: &[f64],
    arcs: &[[f64; 3]],
    n: usize,
    fit: &SplineFit,
) -> Option<(Spline, f64)> {
    let m = points.len() - 1;
    let unit = 10f64.powi(-(fit.decimals as i32));
    let round = |v: f64| (v / unit).round() * unit;
    let length = params[m];
    let end = round(length);
    if end <= 0.0 {
        return None;
    }
    // Parameters scaled onto the printed knots' range.
    let u: Vec<f64> = params.iter().map(|p| p * end / length).collect();
    let knots = match fit.knots {
        KnotSpacing::Averaged => knots(&u, n, round)?,
        KnotSpacing::Uniform => uniform_knots(end, n, round)?,
    };
    // The curve's parameter range as its knots end (a uniform spacing,
    // rounded, times the spans, need not be the path's length).
    let last = knots[knots.len() - 1];
    let u: Vec<f64> = if last == end {
        u
    } else {
        u.iter().map(|v| v * last / end).collect()
    };
    let ctrl = least_squares(points, &u, &knots, n)?;
    let o = [fit.control.x, fit.control.y, fit.control.z];
    let check = |ctrl: &[[f64; 3]], limit| deviation(ctrl, &knots, points, &u, arcs, limit);
    if check(&ctrl, fit.tolerance) > fit.tolerance {
        return None;
    }
    let printed: Vec<[f64; 3]> = ctrl
        .iter()
        .map(|p| std::array::from_fn(|i| round(p[i] + o[i]) - o[i]))
        .collect();
    let worst = check(&printed, fit.tolerance + fit.rounding());
    (worst <= fit.tolerance + fit.rounding()).then_some((
        Spline {
            order: ORDER,
            points: printed,
            knots,
            feed: None,
        },
        worst,
    ))
}

/// The clamped knot vector of `n` control points over parameters `u`,
/// interior knots by averaging (Piegl and Tiller eq. 9.69), each rounded
/// to the printed decimals; none if two interior knots round together or
/// onto an end (a span with no length).
fn knots(u: &[f64], n: usize, round: impl Fn(f64) -> f64) -> Option<Vec<f64>> {
    let m = u.len() - 1;
    let end = u[m];
    let mut k = vec![0.0; ORDER];
    let d = (m + 1) as f64 / (n - DEGREE) as f64;
    for j in 1..n - DEGREE {
        let jd = j as f64 * d;
        let i = jd.floor() as usize;
        let a = jd - i as f64;
        let v = round((1.0 - a) * u[i.saturating_sub(1)] + a * u[i.min(m)]);
        if v <= *k.last().expect("a knot") || v >= end {
            return None;
        }
        k.push(v);
    }
    k.extend([end; ORDER]);
    Some(k)
}

/// The clamped knot vector of `n` control points with equally spaced
/// interior knots: the spacing `end / spans` rounded to the printed
/// decimals, the end at `spans` times it; none if it rounds to zero.
fn uniform_knots(end: f64, n: usize, round: impl Fn(f64) -> f64) -> Option<Vec<f64>> {
    let spans = n - DEGREE;
    let spacing = round(end / spans as f64);
    if spacing <= 0.0 {
        return None;
    }
    let mut k = vec![0.0; ORDER];
    k.extend((1..spans).map(|j| j as f64 * spacing));
    k.extend([spans as f64 * spacing; ORDER]);
    Some(k)
}

/// The span holding `t` (index of the knot at or before it, at most the
/// last non-empty span's).
fn span(knots: &[f64], n: usize, t: f64) -> usize {
    if t >= knots[n] {
        return n - 1;
    }
    // Largest s in DEGREE..n with knots[s] <= t.
    let mut lo = DEGREE;
    let mut hi = n;
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if knots[mid] <= t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The four non-zero cubic basis functions at `t` in span `s` (Piegl and
/// Tiller algorithm A2.2): values for control points s−3 … s.
fn basis(knots: &[f64], s: usize, t: f64) -> [f64; ORDER] {
    let mut n = [0.0; ORDER];
    let mut left = [0.0; ORDER];
    let mut right = [0.0; ORDER];
    n[0] = 1.0;
    for j in 1..ORDER {
        left[j] = t - knots[s + 1 - j];
        right[j] = knots[s + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let tmp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        n[j] = saved;
    }
    n
}

/// The curve's point at `t`.
fn point(ctrl: &[[f64; 3]], knots: &[f64], t: f64) -> [f64; 3] {
    #[cfg(test)]
    tests::EVALUATIONS.with(|c| c.set(c.get() + 1));
    let s = span(knots, ctrl.len(), t);
    let b = basis(knots, s, t);
    let mut p = [0.0; 3];
    for (r, w) in b.iter().enumerate() {
        let c = ctrl[s - DEGREE + r];
        for i in 0..3 {
            p[i] += w * c[i];
        }
    }
    p
}

/// Interior control points by least squares, the ends held at the run's
/// ends (Piegl and Tiller eqs. 9.63–9.67); none if the normal equations
/// are singular.
fn least_squares(points: &[[f64; 3]], u: &[f64], knots: &[f64], n: usize) -> Option<Vec<[f64; 3]>> {
    let m = points.len() - 1;
    let (q0, qm) = (points[0], points[m]);
    let inner = n - 2;
    // Banded normal matrix: a[i][d] = entry (i, i + d), d = 0..=DEGREE.
    let mut a = vec![[0.0f64; ORDER]; inner];
    let mut rhs = vec![[0.0f64; 3]; inner];
    for k in 1..m {
        let s = span(knots, n, u[k]);
        let b = basis(knots, s, u[k]);
        let first = s - DEGREE;
        let mut r = points[k];
        for (j, w) in b.iter().enumerate() {
            let idx = first + j;
            if idx == 0 {
                r = sub(r, scale(q0, *w));
            } else if idx == n - 1 {
                r = sub(r, scale(qm, *w));
            }
        }
        for (j, wj) in b.iter().enumerate() {
            let ij = first + j;
            if ij == 0 || ij == n - 1 {
                continue;
            }
            let row = ij - 1;
            for c in 0..3 {
                rhs[row][c] += wj * r[c];
            }
            for (l, wl) in b.iter().enumerate().skip(j) {
                let il = first + l;
                if il == 0 || il == n - 1 {
                    continue;
                }
                a[row][il - ij] += wj * wl;
            }
        }
    }
    // Banded Cholesky: a = L Lᵀ, L stored in place as l[i][d] = L(i + d, i).
    for i in 0..inner {
        for d in 0..ORDER {
            let j = i + d;
            if j >= inner {
                break;
            }
            let mut v = a[i][d];
            for k in 1..ORDER - d {
                if k > i {
                    break;
                }
                v -= a[i - k][k] * a[i - k][k + d];
            }
            if d == 0 {
                if v <= 1e-300 {
                    return None;
                }
                a[i][0] = v.sqrt();
            } else {
                a[i][d] = v / a[i][0];
            }
        }
    }
    // L y = rhs, then Lᵀ x = y.
    let mut x = rhs;
    for i in 0..inner {
        for k in 1..ORDER {
            if k > i {
                break;
            }
            let l = a[i - k][k];
            let before = x[i - k];
            x[i] = sub(x[i], scale(before, l));
        }
        x[i] = scale(x[i], 1.0 / a[i][0]);
    }
    for i in (0..inner).rev() {
        for d in 1..ORDER {
            if i + d >= inner {
                break;
            }
            let l = a[i][d];
            let after = x[i + d];
            x[i] = sub(x[i], scale(after, l));
        }
        x[i] = scale(x[i], 1.0 / a[i][0]);
    }
    let mut ctrl = Vec::with_capacity(n);
    ctrl.push(q0);
    ctrl.extend(x);
    ctrl.push(qm);
    ctrl.iter().flatten().all(|v| v.is_finite()).then_some(ctrl)
}

/// The largest distance from the curve of the planned points and of the
/// chords' arc middles, each found by a few Newton steps on the distance
/// from its parameter (the curve's derivatives by central differences);
/// once it is known to exceed `limit`, any distance above `limit` (the
/// fit fails whatever the rest are).
///
/// A point's Newton steps only lower its distance from the one at its
/// own parameter, so a point no farther there than the worst already
/// found cannot raise the worst: the points are taken farthest first and
/// the steps stop at the first that cannot (the worst is the same, to the
/// bit, as stepping every point).
fn deviation(
    ctrl: &[[f64; 3]],
    knots: &[f64],
    points: &[[f64; 3]],
    u: &[f64],
    arcs: &[[f64; 3]],
    limit: f64,
) -> f64 {
    let end = u[u.len() - 1];
    let h = end * 1e-5;
    // The distance from q of the curve's nearest point, from `t0` (where
    // the curve is `first` from q) within [lo, hi].
    let nearest = |q: [f64; 3], t0: f64, first: f64, lo: f64, hi: f64| {
        let mut t = t0;
        let mut p = point(ctrl, knots, t);
        let mut best = first;
        for _ in 0..4 {
            let (a, b) = ((t - h).max(0.0), (t + h).min(end));
            let (pa, pb) = (point(ctrl, knots, a), point(ctrl, knots, b));
            let d1 = scale(sub(pb, pa), 1.0 / (b - a));
            let d2 = scale(add(sub(pb, scale(p, 2.0)), pa), 4.0 / ((b - a) * (b - a)));
            let e = sub(p, q);
            let g = dot(e, d1);
            let gp = dot(d1, d1) + dot(e, d2);
            if gp <= 0.0 {
                break;
            }
            t = (t - g / gp).clamp(lo, hi);
            p = point(ctrl, knots, t);
            let d = dist(p, q);
            if d >= best {
                break;
            }
            best = d;
        }
        best
    };
    let last = u.len() - 1;
    // Each point with its parameter, its Newton bounds and its distance
    // at the parameter.
    let mut starts: Vec<([f64; 3], f64, f64, f64, f64)> = points
        .iter()
        .enumerate()
        .map(|(k, &q)| (q, u[k], u[k.saturating_sub(1)], u[(k + 1).min(last)]))
        .chain(
            arcs.iter()
                .enumerate()
                .map(|(k, &q)| (q, (u[k] + u[k + 1]) / 2.0, u[k], u[k + 1])),
        )
        .map(|(q, t0, lo, hi)| (q, t0, dist(point(ctrl, knots, t0), q), lo, hi))
        .collect();
    starts.sort_unstable_by(|a, b| b.2.total_cmp(&a.2));
    let mut worst: f64 = 0.0;
    for (q, t0, first, lo, hi) in starts {
        if first <= worst {
            break;
        }
        worst = worst.max(nearest(q, t0, first, lo, hi));
        if worst > limit {
            break;
        }
    }
    worst
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

#[cfg(test)]
mod tests;
