//! Rasters: a milling path to the move stream and a mill program.

use crate::dialect::Dialect;
use crate::moves::{self, Position};
use crate::plan::optimise::{self};
use crate::post::{ProgramError, ProgramWriter, Setup};

/// The move stream of a raster: each pass reached by rapids at the safe
/// height, a plunge at the feed, the cut, a retract.
pub fn raster_moves(path: &crate::plan::raster::RasterPath, feed: f64) -> Vec<moves::Move> {
    let safe = Position {
        z: path.safe_z,
        ..Position::KEEP
    };
    let mut out = vec![moves::Move::Rapid(safe)];
    for pass in &path.passes {
        let Some(first) = pass.first() else { continue };
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
            feed: Some(moves::Feed::PerTime(feed)),
        });
        out.extend(pass[1..].iter().map(|p| moves::Move::Linear {
            to: Position::xyz(p[0], p[1], p[2]),
            feed: None,
        }));
        out.push(moves::Move::Rapid(safe));
    }
    out
}

/// A program for a (optimised) move stream on a 3-axis mill, blending
/// held to the blending share of the path's tolerance `tolerance`.
pub fn emit_mill(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    stream: &[moves::Move],
    resolution: f64,
    tolerance: f64,
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
    w.write_all(stream)?;
    w.finish()
}
