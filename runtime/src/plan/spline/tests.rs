use super::*;
use crate::moves::{Feed, Move, Position};
use std::cell::Cell;

thread_local! {
    /// The fitter's evaluations of a curve on this thread (`point`).
    pub(super) static EVALUATIONS: Cell<usize> = const { Cell::new(0) };
}

const FIT: SplineFit = SplineFit {
    tolerance: 30e-6,
    decimals: 4,
    control: ControlOffset::CENTRE,
    knots: KnotSpacing::Averaged,
};

/// A raster-like pass: lines along X over a circle of radius `r` in XZ,
/// `n` chords from x = −w to w, from a start at the pass's first point.
fn pass(r: f64, w: f64, n: usize) -> Vec<Move> {
    let z = |x: f64| (r * r - x * x).sqrt() - r;
    let mut moves = vec![Move::Rapid(Position::xyz(-w, 0.5, z(-w)))];
    for k in 1..=n {
        let x = -w + 2.0 * w * k as f64 / n as f64;
        moves.push(Move::Linear {
            to: Position::xyz(x, 0.5, z(x)),
            feed: (k == 1).then_some(Feed::PerTime(100.0 / 60.0)),
        });
    }
    moves
}

/// The exact circle's distance from the spline, sampled densely along it
/// (the curve evaluated here by de Boor's algorithm, not the fitter's
/// basis functions).
fn worst_from_circle(s: &Spline, r: f64) -> f64 {
    let k = &s.knots;
    let end = k[k.len() - 1];
    let mut worst: f64 = 0.0;
    for i in 0..=4000 {
        let t = end * i as f64 / 4000.0;
        let p = de_boor(s, t);
        let d = (p[0].hypot(p[2] + r) - r).abs();
        worst = worst.max(d);
    }
    worst
}

fn de_boor(s: &Spline, t: f64) -> [f64; 3] {
    let (k, p, deg) = (&s.knots, &s.points, s.order - 1);
    let n = p.len();
    let mut j = deg;
    while j + 1 < n && k[j + 1] <= t {
        j += 1;
    }
    let mut d: Vec<[f64; 3]> = (0..=deg).map(|r| p[j - deg + r]).collect();
    for r in 1..=deg {
        for q in (r..=deg).rev() {
            let i = j - deg + q;
            let a = (t - k[i]) / (k[i + deg + 1 - r] - k[i]);
            let (before, here) = (d[q - 1], d[q]);
            d[q] = std::array::from_fn(|c| (1.0 - a) * before[c] + a * here[c]);
        }
    }
    d[deg]
}

#[test]
fn a_smooth_pass_becomes_one_spline_within_its_limit() {
    let moves = pass(1.0, 0.7, 400);
    let (steps, summary) = fit_splines(&moves, &FIT, None);
    let splines: Vec<&Spline> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Spline(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(splines.len(), 1, "{summary:?}");
    let s = splines[0];
    assert_eq!(s.knots.len(), s.points.len() + ORDER);
    assert_eq!(s.feed, Some(Feed::PerTime(100.0 / 60.0)));
    // Starts where the pass starts, ends where it ends.
    assert!((s.points[0][0] + 0.7).abs() < 1e-12);
    assert!((s.points[s.points.len() - 1][0] - 0.7).abs() < 1e-4);
    assert!(summary.max_deviation <= summary.limit, "{summary:?}");
    // The exact circle, not only the planned points, within the limit.
    let worst = worst_from_circle(s, 1.0);
    assert!(worst <= summary.limit, "{worst:e} over {:e}", summary.limit);
    // A fraction of the blocks.
    assert!(
        summary.blocks_after * 5 <= summary.blocks_before,
        "{summary:?}"
    );
}

/// The fit's deviation check steps only the points that can raise the
/// worst: a fit of a 400-chord pass (801 points and chords' arc middles,
/// checked as fitted and as printed) takes at most 1.5 evaluations of the
/// curve per point checked (measured: 2043 and 1845, for 40 and 8 control
/// points); stepping every point took about 10 per point checked
/// (`the_pruned_check_finds_the_worst_of_every_point` counts both).
#[test]
fn the_fit_checks_a_pass_with_few_evaluations_per_point() {
    let moves = pass(1.0, 0.7, 400);
    let run = |n: usize| {
        let points: Vec<[f64; 3]> = moves
            .iter()
            .map(|m| match m {
                Move::Rapid(to) | Move::Linear { to, .. } => [to.x, to.y, to.z],
                _ => unreachable!(),
            })
            .collect();
        let params = chord_params(&points);
        let arcs = arc_middles(&points);
        EVALUATIONS.with(|c| c.set(0));
        let fitted = fitted(&points, &params, &arcs, n, &FIT);
        (fitted.is_some(), EVALUATIONS.with(|c| c.get()))
    };
    for n in [40, 8] {
        let (holds, evaluations) = run(n);
        eprintln!("{n} control points: holds {holds}, {evaluations} evaluations");
        assert!(evaluations <= 2 * 3 * 401, "{n}: {evaluations}");
    }
}

/// The pruned check finds the same worst, to the bit, as stepping every
/// point, for fits that hold and fits that do not.
#[test]
fn the_pruned_check_finds_the_worst_of_every_point() {
    for (r, w, chords) in [(1.0, 0.7, 400), (0.5, 0.45, 120), (3.0, 1.0, 300)] {
        let moves = pass(r, w, chords);
        let points: Vec<[f64; 3]> = moves
            .iter()
            .map(|m| match m {
                Move::Rapid(to) | Move::Linear { to, .. } => [to.x, to.y, to.z],
                _ => unreachable!(),
            })
            .collect();
        let params = chord_params(&points);
        let arcs = arc_middles(&points);
        for n in [5, 8, 13, 21, 34, 55] {
            let end = params[params.len() - 1];
            let knots = knots(&params, n, |v| v).expect("knots");
            let Some(ctrl) = least_squares(&points, &params, &knots, n) else {
                continue;
            };
            EVALUATIONS.with(|c| c.set(0));
            let pruned = deviation(&ctrl, &knots, &points, &params, &arcs, f64::INFINITY);
            let pruned_evaluations = EVALUATIONS.with(|c| c.replace(0));
            // Every point stepped, as the fitter did before pruning.
            let h = end * 1e-5;
            let nearest = |q: [f64; 3], t0: f64, lo: f64, hi: f64| {
                let mut t = t0;
                let mut best = dist(point(&ctrl, &knots, t), q);
                for _ in 0..4 {
                    let (a, b) = ((t - h).max(0.0), (t + h).min(end));
                    let (pa, pb, p) = (
                        point(&ctrl, &knots, a),
                        point(&ctrl, &knots, b),
                        point(&ctrl, &knots, t),
                    );
                    let d1 = scale(sub(pb, pa), 1.0 / (b - a));
                    let d2 = scale(add(sub(pb, scale(p, 2.0)), pa), 4.0 / ((b - a) * (b - a)));
                    let e = sub(p, q);
                    let g = dot(e, d1);
                    let gp = dot(d1, d1) + dot(e, d2);
                    if gp <= 0.0 {
                        break;
                    }
                    t = (t - g / gp).clamp(lo, hi);
                    let d = dist(point(&ctrl, &knots, t), q);
                    if d >= best {
                        break;
                    }
                    best = d;
                }
                best
            };
            let last = params.len() - 1;
            let mut every: f64 = 0.0;
            for (k, &q) in points.iter().enumerate() {
                let (lo, hi) = (params[k.saturating_sub(1)], params[(k + 1).min(last)]);
                every = every.max(nearest(q, params[k], lo, hi));
            }
            for (k, &q) in arcs.iter().enumerate() {
                every = every.max(nearest(
                    q,
                    (params[k] + params[k + 1]) / 2.0,
                    params[k],
                    params[k + 1],
                ));
            }
            let every_evaluations = EVALUATIONS.with(|c| c.get());
            assert_eq!(pruned.to_bits(), every.to_bits(), "r {r}, n {n}");
            // And with a fraction of the evaluations.
            eprintln!(
                "r {r}, n {n}: {pruned_evaluations} evaluations pruned, {every_evaluations} stepping every point"
            );
            assert!(
                pruned_evaluations * 3 < every_evaluations,
                "r {r}, n {n}: {pruned_evaluations} against {every_evaluations}"
            );
            // Held to a limit below the worst, the check says so.
            assert!(deviation(&ctrl, &knots, &points, &params, &arcs, every / 2.0) > every / 2.0);
        }
    }
}

#[test]
fn control_points_and_knots_are_printed_values() {
    let fit = SplineFit {
        control: ControlOffset {
            x: 0.0,
            y: 0.0,
            z: -0.085_03,
        },
        ..FIT
    };
    let (steps, _) = fit_splines(&pass(1.0, 0.7, 400), &fit, None);
    let Some(Step::Spline(s)) = steps.iter().find(|s| matches!(s, Step::Spline(_))) else {
        panic!("no spline");
    };
    let on_grid = |v: f64| ((v * 1e4) - (v * 1e4).round()).abs() < 1e-6;
    assert!(s.knots.iter().all(|&k| on_grid(k)));
    assert!(
        s.points[1..]
            .iter()
            .all(|p| on_grid(p[0]) && on_grid(p[1]) && on_grid(p[2] - 0.085_03))
    );
}

/// Down `n` steps of 0.05 mm to Z0, then along X `n` steps.
fn corner(n: usize) -> Vec<Move> {
    let mut moves = vec![Move::Rapid(Position::xyz(0.0, 0.0, n as f64 * 0.05))];
    for k in 1..=n {
        moves.push(Move::Linear {
            to: Position::xyz(0.0, 0.0, (n - k) as f64 * 0.05),
            feed: (k == 1).then_some(Feed::PerTime(1.0)),
        });
    }
    for k in 1..=n {
        moves.push(Move::Linear {
            to: Position::xyz(k as f64 * 0.05, 0.0, 0.0),
            feed: None,
        });
    }
    moves
}

#[test]
fn short_runs_stay_lines() {
    let moves = corner(10);
    let (steps, summary) = fit_splines(&moves, &FIT, None);
    assert_eq!(summary.splines, 0);
    assert_eq!(steps.len(), moves.len());
}

#[test]
fn a_corner_is_kept() {
    let (steps, summary) = fit_splines(&corner(30), &FIT, None);
    assert_eq!(summary.splines, 2, "{summary:?}");
    let ends: Vec<([f64; 3], [f64; 3])> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Spline(s) => Some((s.points[0], s.points[s.points.len() - 1])),
            _ => None,
        })
        .collect();
    // The first ends at the corner, the second starts there.
    assert!(ends[0].1.iter().all(|v| v.abs() < 1e-12), "{ends:?}");
    assert!(ends[1].0.iter().all(|v| v.abs() < 1e-12), "{ends:?}");
}

#[test]
fn a_pass_too_coarse_to_hold_stays_lines() {
    // Chords 0.1 mm long over a 0.2 mm radius: no cubic through few
    // enough points to save blocks holds 30 nm of every chord's arc.
    let mut moves = vec![Move::Rapid(Position::xyz(0.2, 0.0, 0.0))];
    for k in 1..=40 {
        let a = k as f64 * 0.35;
        moves.push(Move::Linear {
            to: Position::xyz(0.2 * a.cos(), 0.0, 0.2 * a.sin()),
            feed: (k == 1).then_some(Feed::PerTime(1.0)),
        });
    }
    let (steps, summary) = fit_splines(&moves, &FIT, None);
    assert_eq!(summary.splines, 0, "{summary:?}");
    assert_eq!(steps.len(), moves.len());
}

/// Where the optimiser writes a run in fewer blocks (a circle: one arc),
/// the run is written as its lines and arcs, not as a spline.
#[test]
fn a_run_the_optimiser_writes_shorter_stays_lines_and_arcs() {
    use crate::moves::Plane;
    let moves = pass(1.0, 0.7, 400);
    let planes = [Plane::Zx];
    let o = Otherwise {
        arc_planes: &planes,
        above: false,
    };
    EVALUATIONS.with(|c| c.set(0));
    let (steps, summary) = fit_splines(&moves, &FIT, Some(o));
    assert_eq!(summary.splines, 0, "{summary:?}");
    assert!(
        steps
            .iter()
            .any(|s| matches!(s, Step::Move(Move::Arc { .. })))
    );
    assert!(steps.len() < 8, "{}", steps.len());
    // No spline can take fewer blocks than so few: none is fitted.
    assert_eq!(EVALUATIONS.with(|c| c.get()), 0);
    // Without arcs the spline is the shorter.
    let o = Otherwise {
        arc_planes: &[],
        above: false,
    };
    let (_, summary) = fit_splines(&moves, &FIT, Some(o));
    assert_eq!(summary.splines, 1, "{summary:?}");
}

/// A pass after a plunge keeps the plunge's feed (its first move states
/// none): it is weighed against its lines and arcs all the same, and the
/// whole stream comes out as the optimiser writes it (one arc).
#[test]
fn a_run_keeping_the_feed_in_force_is_weighed_too() {
    use crate::moves::Plane;
    let mut moves = pass(4.0, 0.7, 400);
    let Move::Rapid(p) = moves[0] else {
        panic!("a rapid first")
    };
    moves[0] = Move::Rapid(Position::xyz(p.x, p.y, 0.5));
    moves.insert(
        1,
        Move::Linear {
            to: Position::xyz(p.x, p.y, p.z),
            feed: Some(Feed::PerTime(1.0)),
        },
    );
    if let Move::Linear { feed, .. } = &mut moves[2] {
        *feed = None;
    }
    let planes = [Plane::Xy, Plane::Zx, Plane::Yz];
    let o = Otherwise {
        arc_planes: &planes,
        above: false,
    };
    let (steps, summary) = fit_splines(&moves, &FIT, Some(o));
    let (opt, _) = crate::plan::optimise::optimise_within(&moves, FIT.tolerance, &planes, false);
    assert_eq!(summary.splines, 0, "{summary:?}");
    let written: Vec<Move> = steps
        .iter()
        .map(|s| match s {
            Step::Move(m) => *m,
            Step::Spline(_) => unreachable!(),
        })
        .collect();
    // NaN (an axis left alone) is never equal to itself: compare as text.
    assert_eq!(format!("{written:?}"), format!("{opt:?}"));
}

/// Siemens' knot spacing: every interior span the same printed length,
/// the curve still within the limit of the exact circle, a fraction of
/// the blocks.
#[test]
fn uniform_knots_are_equally_spaced_and_hold_the_circle() {
    let fit = SplineFit {
        knots: KnotSpacing::Uniform,
        ..FIT
    };
    let (steps, summary) = fit_splines(&pass(1.0, 0.7, 400), &fit, None);
    let [Step::Move(_), Step::Spline(s)] = &steps[..] else {
        panic!("one spline: {summary:?}");
    };
    let k = &s.knots;
    assert!(k[..ORDER].iter().all(|v| *v == 0.0));
    let spacing = k[ORDER] - k[ORDER - 1];
    assert!(spacing > 0.0);
    // Printed to four decimals.
    assert!((spacing * 1e4 - (spacing * 1e4).round()).abs() < 1e-6);
    for w in k[ORDER - 1..k.len() - ORDER + 1].windows(2) {
        assert!((w[1] - w[0] - spacing).abs() < 1e-12, "{k:?}");
    }
    assert!(k[k.len() - ORDER..].iter().all(|v| *v == k[k.len() - 1]));
    let worst = worst_from_circle(s, 1.0);
    assert!(worst <= summary.limit, "{worst:e} over {:e}", summary.limit);
    assert!(
        summary.blocks_after * 5 <= summary.blocks_before,
        "{summary:?}"
    );
}

/// A lathe's profile states X and Z only (Y never): it is fitted all the
/// same, in Y = 0 (before, every run needed a known Y and none was found).
#[test]
fn a_lathe_profile_without_y_is_fitted_in_y_zero() {
    let moves: Vec<Move> = pass(1.0, 0.7, 400)
        .into_iter()
        .map(|m| match m {
            Move::Rapid(to) => Move::Rapid(Position::xz(to.x, to.z)),
            Move::Linear { to, feed } => Move::Linear {
                to: Position::xz(to.x, to.z),
                feed,
            },
            other => other,
        })
        .collect();
    let fit = SplineFit {
        knots: KnotSpacing::Uniform,
        ..FIT
    };
    let (steps, summary) = fit_splines(&moves, &fit, None);
    let [Step::Move(_), Step::Spline(s)] = &steps[..] else {
        panic!("one spline: {summary:?}");
    };
    assert!(s.points.iter().all(|p| p[1] == 0.0));
    let worst = worst_from_circle(s, 1.0);
    assert!(worst <= summary.limit, "{worst:e} over {:e}", summary.limit);
}

/// A profile fed per revolution (a lathe's G95, every move stating its
/// feed as the turning planner gives it): the writer's splines are fed per
/// minute only, so no spline is fitted, but the run is still written as
/// the optimiser's lines and arcs (it was left as 400 lines, 25 times the
/// program `lines_arcs` writes).
#[test]
fn a_run_fed_per_revolution_is_lines_and_arcs_never_a_spline() {
    use crate::moves::Plane;
    let mut moves = pass(4.0, 0.7, 400);
    for m in &mut moves {
        if let Move::Linear { feed, .. } = m {
            *feed = Some(Feed::PerRevolution(3e-3 / std::f64::consts::TAU));
        }
    }
    let planes = [Plane::Zx];
    let o = Otherwise {
        arc_planes: &planes,
        above: false,
    };
    let (steps, summary) = fit_splines(&moves, &FIT, Some(o));
    assert_eq!(summary.splines, 0, "{summary:?}");
    let (opt, _) = crate::plan::optimise::optimise_within(&moves, FIT.tolerance, &planes, false);
    assert!(opt.len() < 8, "{}", opt.len());
    let written: Vec<Move> = steps
        .iter()
        .map(|s| match s {
            Step::Move(m) => *m,
            Step::Spline(_) => unreachable!(),
        })
        .collect();
    assert_eq!(format!("{written:?}"), format!("{opt:?}"));
    // Without arcs it stays lines: still no spline.
    let o = Otherwise {
        arc_planes: &[],
        above: false,
    };
    let (_, summary) = fit_splines(&moves, &FIT, Some(o));
    assert_eq!(summary.splines, 0, "{summary:?}");
}

/// Many passes, some fitted, some kept as lines and arcs, some too short
/// or too coarse: the runs fitted in parallel come out as fitted one
/// after the other, to the bit, on one thread or four.
#[test]
fn runs_fitted_in_parallel_are_the_runs_fitted_in_order() {
    use crate::moves::Plane;
    let mut moves = Vec::new();
    for k in 0..24 {
        let (r, w, n) = match k % 4 {
            0 => (1.0, 0.7, 400),
            1 => (0.5, 0.45, 120),
            2 => (3.0, 1.0, 10),
            _ => (0.2, 0.19, 30),
        };
        let mut pass = pass(r, w, n);
        // Each pass a little further along Y, after a lift.
        for m in &mut pass {
            if let Move::Rapid(to) | Move::Linear { to, .. } = m {
                to.y += k as f64 * 0.01;
            }
        }
        moves.push(Move::Rapid(Position::xyz(-w, 0.5 + k as f64 * 0.01, 1.0)));
        moves.extend(pass);
    }
    let planes = [Plane::Zx];
    for o in [
        None,
        Some(Otherwise {
            arc_planes: &[],
            above: false,
        }),
        Some(Otherwise {
            arc_planes: &planes,
            above: true,
        }),
    ] {
        let serial = fit_splines_serial(&moves, &FIT, o);
        assert!(serial.1.splines >= 6, "{:?}", serial.1);
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let parallel = pool.install(|| fit_splines(&moves, &FIT, o));
            // Compared as printed (a move's unstated C is NaN, which no
            // NaN equals): every step and figure, to the last digit.
            let (p, s) = (format!("{parallel:?}"), format!("{serial:?}"));
            assert!(p == s, "{threads} threads: the steps differ");
        }
    }
}
