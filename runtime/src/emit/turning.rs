//! Profile turning: the planned profile path to a lathe program.

use super::{Emitted, optimisation_words, tolerance_words, x_word};
use crate::moves::Move;
use crate::moves::{self, Position, Start};
use crate::plan::chords::ChordPlacement;
use crate::plan::optimise;
use crate::plan::turning::{Feed, PassRates, Toolpath, TurningJob};
use crate::post::header::{Provenance, duration, exact, exact_in, num};
use crate::post::{ProgramError, ProgramWriter, Setup};
use std::f64::consts::PI;

/// One m/min in mm/s, as a `.lens` file reads `m/min` (1000 × 60⁻¹).
const M_PER_MIN: f64 = 1000.0 / 60.0;

/// Writes a lathe program for a profile-turning path in the machine's
/// dialect for the tool's control point (`start.control`, stated in
/// words in the header's `control_point` line), optimised (lines merged, arcs fitted) within the fitting share
/// of the strategy's tolerance.
///
/// With `spline`, each run of straight cutting moves is written as the
/// dialect's spline where that takes fewer blocks than its lines and
/// arcs (`plan::spline`), and the header says so; the stream handed back
/// stays the planned moves, the path the fit is held to.
pub fn emit(
    job: &TurningJob,
    path: &Toolpath,
    prov: &Provenance,
    start: &Start,
    control_point: &str,
    spline: bool,
) -> Result<Emitted, ProgramError> {
    let centre_height = if job.tool.centre_height == 0.0 {
        String::new()
    } else {
        format!(
            ", edge {} mm off the spindle axis: X = sqrt[r² − h²] of the nose-centre radius r",
            exact(job.tool.centre_height)
        )
    };
    let header = [
        format!("lensc {}: job {}", prov.lensc_version, job.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        format!(
            "units mm; X is {}, Z along the spindle axis, +Z out of the material",
            x_word(&job.machine.dialect)
        ),
        format!("{control_point}; no cutter compensation"),
        format!("surface {}: {}", job.surface_name, job.surface.description),
        format!(
            "tool {}: round nose, nose radius {} mm{centre_height}{}",
            job.tool_name,
            exact(job.tool.nose_radius),
            match &job.tool.edge {
                Some(e) => format!(
                    ", edge profile {}: path offset by R + its deviation at each angle of contact",
                    e.source
                ),
                None => String::new(),
            }
        ),
        format!(
            "strategy {}: profile turning, {} points, {}{}{}",
            job.strategy_name,
            path.cut_points,
            tolerance_words(job.strategy.chord_tolerance),
            match job.strategy.surface_speed {
                Some(v) => format!(
                    ", constant surface speed {} m/min capped at {} rpm",
                    exact_in(v, M_PER_MIN),
                    exact_in(job.strategy.spindle_speed, 2.0 * PI / 60.0)
                ),
                None => String::new(),
            },
            roughing_words(job, path)
        ),
        format!(
            "machine {}: {} lathe",
            job.machine_name, job.machine.dialect.name
        ),
        format!("estimated cutting time {}", duration(path.cutting_time())),
    ];
    let tolerance = job.strategy.chord_tolerance;
    let dialect = &job.machine.dialect;
    let above = matches!(job.strategy.chords, ChordPlacement::Clear { .. });
    if spline {
        return emit_splines(job, path, start, &header, above);
    }
    // Points placed clear of the material are not fitted back into it.
    let (stream, summary) = optimise::optimise_within(
        &turning_moves(job, path),
        tolerance * optimise::FIT_SHARE,
        &dialect.arc_planes,
        above,
    );
    let mut header = header.to_vec();
    header.push(optimisation_words(&summary));
    let mut w = ProgramWriter::new(
        &job.machine.dialect,
        Setup::Lathe,
        &job.name,
        &header,
        "XZ",
        job.machine.resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.call_tool(start)?;
    w.write_all(&stream)?;
    Ok(Emitted {
        text: w.finish()?,
        stream,
        optimised: summary,
    })
}

/// The program written with the dialect's splines (`emit`'s `spline`).
fn emit_splines(
    job: &TurningJob,
    path: &Toolpath,
    start: &Start,
    header: &[String],
    above: bool,
) -> Result<Emitted, ProgramError> {
    use crate::plan::spline;
    let dialect = &job.machine.dialect;
    let tolerance = job.strategy.chord_tolerance;
    let decimals = crate::post::check_dialect(dialect, Setup::Lathe, job.machine.resolution)?;
    let fit = spline::SplineFit {
        tolerance: tolerance * optimise::FIT_SHARE,
        decimals,
        control: start.control,
        knots: spline::KnotSpacing::of(dialect),
    };
    let otherwise = spline::Otherwise {
        arc_planes: &dialect.arc_planes,
        above,
    };
    let stream = turning_moves(job, path);
    let (steps, fitted) = spline::fit_splines(&stream, &fit, Some(otherwise));
    let summary = optimise::Summary {
        moves_before: fitted.blocks_before,
        moves_after: fitted.blocks_after,
        arcs: 0,
        merged_lines: 0,
        max_deviation: fitted.max_deviation,
        tolerance: fitted.limit,
    };
    let mut header = header.to_vec();
    let at = header
        .iter()
        .position(|l| l.starts_with("machine "))
        .unwrap_or(header.len());
    header.insert(at, super::spline_words(dialect, &fitted));
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Lathe,
        &job.name,
        &header,
        "XZ",
        job.machine.resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.call_tool(start)?;
    for s in &steps {
        w.write_step(s)?;
    }
    Ok(Emitted {
        text: w.finish()?,
        stream,
        optimised: summary,
    })
}

/// The move stream of a profile-turning path: the spindle started, a
/// rapid up to the safe height before any other move, the planner's moves
/// (X corrected for an edge set off centre) at each pass's feed (an
/// approach's feed through air at its own), the
/// spindle switched to the finish's speed before the finish pass where
/// roughing runs at its own, and the spindle stopped.
pub fn turning_moves(job: &TurningJob, path: &Toolpath) -> Vec<moves::Move> {
    let finish = PassRates::finish(&job.strategy);
    let rough = PassRates::roughing(&job.strategy);
    let feed = |r: &PassRates| match r.feed {
        Feed::PerRevolution(f) => moves::Feed::PerRevolution(f),
        Feed::PerTime(v) => moves::Feed::PerTime(v),
    };
    let spindle = |r: &PassRates| match r.surface_speed {
        Some(v) => moves::Move::SpindleSurfaceSpeed {
            surface_speed: v,
            cap: r.spindle_speed,
        },
        None => moves::Move::SpindleOn(r.spindle_speed),
    };
    // An edge set h off the axis cuts radius sqrt(X² + h²).
    let h = job.tool.centre_height;
    let corrected = |x: f64| {
        if h == 0.0 {
            x
        } else {
            x.signum() * (x * x - h * h).max(0.0).sqrt()
        }
    };
    // Where the finish pass begins; every move before it is roughing.
    let finish_from = path
        .pass_starts
        .get(path.roughing_passes)
        .copied()
        .unwrap_or(0);
    let mut out = Vec::with_capacity(path.moves.len() + 4);
    out.push(spindle(if finish_from > 0 { &rough } else { &finish }));
    if let Some(Move::Rapid(to)) = path.moves.first() {
        out.push(Move::Rapid(Position {
            z: to.z,
            ..Position::KEEP
        }));
    }
    for (i, m) in path.moves.iter().enumerate() {
        if i == finish_from && i > 0 && spindle(&rough) != spindle(&finish) {
            out.push(spindle(&finish));
        }
        let rates = if i < finish_from { &rough } else { &finish };
        out.push(match *m {
            Move::Rapid(to) => Move::Rapid(Position::xz(corrected(to.x), to.z)),
            // The planner's own feed (an approach through air) kept.
            Move::Linear { to, feed: f } => Move::Linear {
                to: Position::xz(corrected(to.x), to.z),
                feed: Some(f.unwrap_or_else(|| feed(rates))),
            },
            other => other,
        });
    }
    out.push(moves::Move::SpindleOff);
    out
}

/// ", after N roughing passes from …" for a job with stock, else "".
fn roughing_words(job: &TurningJob, path: &Toolpath) -> String {
    use crate::plan::turning::Stock;
    let Some(r) = job.strategy.roughing else {
        return String::new();
    };
    let stock = match r.stock {
        Stock::Flat { top } => format!("flat stock at Z{}", exact(top)),
        Stock::Offset { allowance } => format!("stock {} mm over the surface", exact(allowance)),
    };
    let feed = match r.feed {
        Feed::PerRevolution(f) => format!("{} mm/rev", num(f * 2.0 * PI)),
        Feed::PerTime(v) => format!("{} mm/min", num(v * 60.0)),
    };
    let speed = r.spindle_speed.map_or(String::new(), |w| {
        format!(" at {} rpm", num(w * 60.0 / (2.0 * PI)))
    });
    format!(
        ", after {} roughing passes from {stock}, at most {} mm each at {feed}{speed}, {} mm left for the finish",
        path.roughing_passes,
        exact(r.depth_of_cut),
        exact(r.finish_allowance)
    )
}
