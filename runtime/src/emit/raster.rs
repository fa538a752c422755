//! Rasters: a milling path to the move stream and a mill program.

use crate::dialect::Dialect;
use crate::moves::{self, Position, Start};
use crate::plan::optimise::{self};
use crate::post::{ProgramError, ProgramWriter, Setup};

/// How a raster's cutter is driven and its passes joined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterCut {
    /// The cutting feed (mm/s).
    pub feed: f64,
    /// The spindle's speed (rad/s) for a rotating cutter; `None`: a
    /// shaping knife, cutting with the spindle held still.
    pub spindle_speed: Option<f64>,
    /// Alternate passes reversed: each joined to the last by a short link
    /// at the feed rather than a retract to the safe height.
    pub zigzag: bool,
}

/// The move stream of a raster: the spindle started (or held, for a
/// knife), up to the safe height, then each pass reached by rapids at
/// the safe height, a plunge at the feed, the cut and a retract. A zigzag
/// joins each pass to the next with a link (`link`) when one is safe, so
/// the tool retracts only at the start and the end.
pub fn raster_moves(path: &crate::plan::raster::RasterPath, cut: RasterCut) -> Vec<moves::Move> {
    let safe = Position {
        z: path.safe_z,
        ..Position::KEEP
    };
    let feed = Some(moves::Feed::PerTime(cut.feed));
    // The spindle first: no approach before it runs (or is held).
    let mut out = vec![
        match cut.spindle_speed {
            Some(w) => moves::Move::SpindleOn(w),
            None => moves::Move::SpindleHeld,
        },
        moves::Move::Rapid(safe),
    ];
    // The steepest the tool-centre surface rises per mm in any direction.
    let gradient = path
        .max_slope_along
        .value
        .tan()
        .hypot(path.max_slope_across.value.tan());
    let mut at: Option<[f64; 3]> = None;
    for pass in &path.passes {
        let Some(first) = pass.first() else { continue };
        let linked = match at {
            Some(end) if cut.zigzag => link(end, *first, gradient, path.safe_z),
            _ => None,
        };
        match linked {
            Some(link) => out.extend(link.map(|to| moves::Move::Linear { to, feed })),
            None => {
                if at.is_some() {
                    out.push(moves::Move::Rapid(safe));
                }
                out.push(moves::Move::Rapid(Position {
                    x: first[0],
                    y: first[1],
                    ..Position::KEEP
                }));
                out.push(moves::Move::Linear {
                    to: Position {
                        z: first[2],
                        ..Position::KEEP
                    },
                    feed,
                });
            }
        }
        out.extend(pass[1..].iter().map(|p| moves::Move::Linear {
            to: Position::xyz(p[0], p[1], p[2]),
            feed: None,
        }));
        at = pass.last().copied();
    }
    out.push(moves::Move::Rapid(safe));
    out
}

/// The link from one zigzag pass's end `a` to the next pass's start `b`
/// (tool centres): up to a height above both ends by twice the most the
/// tool-centre surface can rise over the link's length (its steepest
/// gradient times the length: a margin of two for slopes measured only at
/// the planned contacts), across, and down to `b`, all at the feed. None
/// (retract to the safe height instead) where that height is not below
/// the safe height or the gradient is not finite.
fn link(a: [f64; 3], b: [f64; 3], gradient: f64, safe_z: f64) -> Option<[Position; 3]> {
    let length = (b[0] - a[0]).hypot(b[1] - a[1]);
    let over = a[2].max(b[2]) + 2.0 * gradient * length;
    (over.is_finite() && over < safe_z).then(|| {
        [
            Position {
                z: over,
                ..Position::KEEP
            },
            Position::xyz(b[0], b[1], over),
            Position {
                z: b[2],
                ..Position::KEEP
            },
        ]
    })
}

/// A program for a (optimised) move stream on a 3-axis mill, blending
/// held to the blending share of the path's tolerance `tolerance`.
pub fn emit_mill(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    stream: &[moves::Move],
    (resolution, tolerance): (f64, f64),
    start: &Start,
) -> Result<String, ProgramError> {
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Mill,
        job,
        header,
        "XYZ",
        resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.call_tool(start)?;
    w.write_all(stream)?;
    w.finish()
}

/// `emit_mill` for a program written with splines (`plan::spline`).
pub fn emit_mill_steps(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    steps: &[moves::Step],
    (resolution, tolerance): (f64, f64),
    start: &Start,
) -> Result<String, ProgramError> {
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Mill,
        job,
        header,
        "XYZ",
        resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.call_tool(start)?;
    for s in steps {
        w.write_step(s)?;
    }
    w.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::moves::Move;
    use crate::plan::raster::RasterPath;
    use crate::surface::analysis::Extremum;

    /// Four passes along x, 10 µm apart, alternate ones reversed, on a
    /// gently sloped part (slopes of 0.1 rad).
    fn zigzag_path() -> RasterPath {
        let pass = |y: f64, reverse: bool| {
            let mut p: Vec<[f64; 3]> = (0..=4).map(|i| [i as f64 * 0.1, y, -0.01 * y]).collect();
            if reverse {
                p.reverse();
            }
            p
        };
        let passes: Vec<_> = (0..4).map(|k| pass(k as f64 * 0.01, k % 2 == 1)).collect();
        let slope = Extremum {
            value: 0.1,
            x: 0.0,
            y: 0.0,
        };
        RasterPath {
            safe_z: 1.0,
            pass_count: passes.len(),
            point_count: 20,
            cut_length: 1.6,
            pass_lengths: vec![0.4; 4],
            max_slope_along: slope,
            max_slope_across: slope,
            min_concave_radius_along: None,
            passes,
        }
    }

    fn rapids_to_safe(stream: &[Move]) -> usize {
        stream
            .iter()
            .filter(|m| matches!(m, Move::Rapid(p) if p.z == 1.0))
            .count()
    }

    #[test]
    fn a_zigzag_links_its_passes_at_the_feed_and_retracts_only_at_its_ends() {
        let path = zigzag_path();
        let cut = RasterCut {
            feed: 1.0,
            spindle_speed: Some(100.0),
            zigzag: true,
        };
        let stream = raster_moves(&path, cut);
        assert_eq!(rapids_to_safe(&stream), 2, "{stream:?}");
        // Every link stays above both ends it joins.
        for pair in path.passes.windows(2) {
            let (a, b) = (pair[0][pair[0].len() - 1], pair[1][0]);
            let lifted = stream.iter().any(|m| {
                matches!(m, Move::Linear { to, .. }
                    if to.x == b[0] && to.y == b[1] && to.z > a[2].max(b[2]))
            });
            assert!(lifted, "no link over {a:?} → {b:?}");
        }
        let one_way = raster_moves(
            &path,
            RasterCut {
                zigzag: false,
                ..cut
            },
        );
        assert_eq!(rapids_to_safe(&one_way), 5);
    }

    #[test]
    fn the_spindle_starts_before_the_first_feed_move_or_is_held_for_a_knife() {
        let path = zigzag_path();
        for (speed, first) in [
            (Some(100.0), Move::SpindleOn(100.0)),
            (None, Move::SpindleHeld),
        ] {
            let stream = raster_moves(
                &path,
                RasterCut {
                    feed: 1.0,
                    spindle_speed: speed,
                    zigzag: false,
                },
            );
            let spindle = stream.iter().position(|m| *m == first).expect("spindle");
            let feed = stream
                .iter()
                .position(|m| matches!(m, Move::Linear { .. }))
                .expect("a cut");
            assert!(spindle < feed);
        }
    }
}
