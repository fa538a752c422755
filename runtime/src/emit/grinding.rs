//! Profile grinding: the wheel-centre path to a lathe program.

use crate::dialect::Dialect;
use crate::moves::{self, Position, Start};
use crate::plan::approach::Approach;
use crate::post::{ProgramError, ProgramWriter, Setup};

/// The move stream of a grinding pass: the work spindle started at
/// `spindle_speed` (rad/s), up to the safe height, over the first point
/// and down to it by `approach` (`plan::approach`: a rapid to a clearance
/// over the part's top, a feed through air, the last clearance at the
/// grinding feed), then the wheel centre's X and Z, each interval at the
/// feed that moves the contact point at v_f (the interval takes its
/// contact-x length over v_f).
pub fn grinding_moves(
    path: &crate::plan::grinding::GrindingPath,
    feed: f64,
    approach: Option<Approach>,
    spindle_speed: f64,
) -> Vec<moves::Move> {
    let (Some(first), Some(approach)) = (path.points.first(), approach) else {
        return Vec::new();
    };
    let safe_z = approach.safe_z;
    let mut out = vec![
        moves::Move::SpindleOn(spindle_speed),
        moves::Move::Rapid(Position {
            z: safe_z,
            ..Position::KEEP
        }),
        moves::Move::Rapid(Position::xz(first.x, safe_z)),
    ];
    out.extend(approach.moves(Some(moves::Feed::PerTime(feed)), moves::Feed::PerTime));
    for pair in path.points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let step = ((b.x - a.x).powi(2) + (b.z - a.z).powi(2)).sqrt();
        let dt = (b.contact_x - a.contact_x).abs() / feed;
        out.push(moves::Move::Linear {
            to: Position::xz(b.x, b.z),
            feed: Some(moves::Feed::PerTime(step / dt)),
        });
    }
    out.push(moves::Move::Rapid(Position {
        z: safe_z,
        ..Position::KEEP
    }));
    out.push(moves::Move::SpindleOff);
    out
}

/// A program for a grinding pass's move stream (`grinding_moves`): X and
/// Z of the wheel centre.
pub fn emit_grinding(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    stream: &[moves::Move],
    resolution: f64,
    start: &Start,
) -> Result<String, ProgramError> {
    // Wheel centres are exact at each interval: blending held to the
    // machine's resolution.
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Lathe,
        job,
        header,
        "XZ",
        resolution,
        resolution,
    )?;
    w.call_tool(start)?;
    w.write_all(stream)?;
    w.finish()
}
