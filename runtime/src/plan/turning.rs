//! Profile turning: the tool-nose centre path is the surface profile offset
//! by the nose radius along its normal, sampled so that the chords between
//! points stay within the chord tolerance of the exact offset curve.

use nalgebra::Vector2;

use crate::machine::Lathe;
use crate::machine::edge::Nose;
use crate::machine::tool::RoundNoseTool;
use crate::moves::{Move, Position};
use crate::plan::approach;
use crate::plan::chords::{self, Band, ChordPlacement};
use crate::plan::count;
use crate::plan::envelope::{self, Pieces};
use crate::surface::Profile;
use crate::surface::SurfaceInfo;

/// One job with every parameter in internal units (mm, rad, s).
#[derive(Clone, Debug, PartialEq)]
pub struct TurningJob {
    pub name: String,
    /// Names the user gave each part, for the program header.
    pub surface_name: String,
    pub tool_name: String,
    pub machine_name: String,
    pub strategy_name: String,
    /// The surface as the header states it; its geometry reaches the
    /// planner as a `Profile`.
    pub surface: SurfaceInfo,
    pub tool: RoundNoseTool,
    pub machine: Lathe,
    pub strategy: ProfileTurning,
}

/// Feed as the user gave it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feed {
    /// mm per radian of spindle rotation (mm/rev ÷ 2π).
    PerRevolution(f64),
    /// mm/s.
    PerTime(f64),
}

/// A facing cut across the profile, from `start_radius` to `end_radius`.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileTurning {
    pub feed: Feed,
    /// Spindle speed (rad/s): constant, or the cap under constant surface
    /// speed.
    pub spindle_speed: f64,
    /// Constant surface speed at the tool (mm/s), the spindle turning at
    /// v/r up to `spindle_speed`.
    pub surface_speed: Option<f64>,
    /// The path's tolerance T (mm): the most the program, as the machine
    /// runs it, may stray from the exact tool-centre curve. The chords take
    /// `optimise::CHORD_SHARE` of it, arc fitting and blending the rest.
    pub chord_tolerance: f64,
    /// Radius (mm) where the cut starts; the aperture edge if `None`.
    pub start_radius: Option<f64>,
    /// Radius (mm) where the cut ends (0: the centre).
    pub end_radius: f64,
    /// Height (mm) above the highest tool-centre point for rapid moves.
    pub retract: f64,
    /// How the nose-centre height is found.
    pub location: ToolLocation,
    /// Roughing passes before the finish pass, if the stock is given.
    pub roughing: Option<Roughing>,
    /// Where the finish pass's points sit across the curve of the path
    /// (`plan::chords`), each moved along Z by the bands of its chords.
    pub chords: ChordPlacement,
}

/// What the part is before cutting, and how much each pass removes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughing {
    pub stock: Stock,
    /// Most material (mm) one roughing pass removes.
    pub depth_of_cut: f64,
    /// Material (mm, along the normal) the last roughing pass leaves for
    /// the finish pass.
    pub finish_allowance: f64,
    /// The roughing passes' own feed.
    pub feed: Feed,
    /// Their own constant spindle speed (rad/s); `None`: the finish's
    /// (its constant speed, or its constant surface speed and cap).
    pub spindle_speed: Option<f64>,
}

/// The stock a job starts from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stock {
    /// A flat face at height `top` (mm).
    Flat { top: f64 },
    /// The design surface offset by `allowance` (mm) along its normal (a
    /// moulded or pre-ground blank).
    Offset { allowance: f64 },
}

/// How profile turning finds the nose-centre height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToolLocation {
    /// Exact: the normal offset on a smooth profile; where the profile has
    /// corners, the envelope of nose circles, piece by piece by Newton.
    Exact,
    /// Lei et al.'s sequential search (reference): the profile discretised
    /// every `spacing` mm, the nose lowered in steps of `step` mm.
    Sequential { spacing: f64, step: f64 },
    /// Lei et al.'s binary search (reference): the profile discretised every
    /// `spacing` mm, the height halved down to `tolerance` mm.
    Binary { spacing: f64, tolerance: f64 },
}

/// A concave corner of the profile the nose cannot reach into: the cut
/// there is the envelope, and material is left above the design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seam {
    /// Where (radius, mm).
    pub at_radius: f64,
    /// Material left above the design at the corner (mm).
    pub depth: f64,
    /// The angle the profile turns through at the corner (rad).
    pub angle: f64,
}

/// A planned path and what planning learned about the part.
#[derive(Clone, Debug, PartialEq)]
pub struct Toolpath {
    /// The nose centre's path in X and Z: rapids out of the material and
    /// cutting moves (`Linear` with no feed: `emit` gives them the job's).
    pub moves: Vec<Move>,
    /// Tool-centre points of the cut (the feed moves), in cutting order.
    pub cut_points: usize,
    /// Length (mm) of the cutting moves.
    pub cut_length: f64,
    /// Cutting feed as a speed (mm/s), at the spindle's highest speed.
    pub feed_speed: f64,
    /// Time (s) of the cutting moves, the spindle's speed at each move's
    /// radius under constant surface speed.
    pub cutting_time: f64,
    /// Cutting time (s) of each pass, roughing passes first, the finish
    /// pass last; they sum to `cutting_time`.
    pub pass_times: Vec<f64>,
    /// Smallest concave radius of curvature on the profile and where (r, mm).
    pub min_concave_radius: Option<(f64, f64)>,
    /// Steepest profile slope (rad) and where (r, mm).
    pub max_slope: (f64, f64),
    /// Concave corners the nose cannot follow, in radius order.
    pub seams: Vec<Seam>,
    /// Roughing passes before the finish pass.
    pub roughing_passes: usize,
    /// Where each pass begins in `moves` (its rapid above the first
    /// point), roughing passes first.
    pub pass_starts: Vec<usize>,
}

impl Toolpath {
    /// Estimated cutting time (s), rapids excluded.
    pub fn cutting_time(&self) -> f64 {
        self.cutting_time
    }
}

/// Why a job cannot be planned as given. Each carries the figures a
/// diagnostic needs; the compiler turns them into user errors.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanError {
    /// The nose is larger than the smallest concave radius of curvature:
    /// it cannot reach the bottom of the bowl without cutting its sides.
    NoseTooLarge {
        nose_radius: f64,
        min_radius: f64,
        at_radius: f64,
    },
    /// The path leaves an axis's travel.
    OutOfTravel {
        axis: char,
        value: f64,
        min: f64,
        max: f64,
    },
    /// The cutting feed exceeds the machine's maximum (mm/s).
    FeedTooHigh { feed: f64, max: f64 },
    /// The spindle speed exceeds the machine's maximum (rad/s).
    SpindleTooFast { speed: f64, max: f64 },
    /// The surface is undefined (or the offset not finite) at this radius.
    Undefined { at_radius: f64 },
    /// The tool's measured edge does not cover the angles (rad, from the
    /// tool's axis towards +X) at which the cut meets it: `needed` the
    /// least and greatest contact angle, `measured` the profile's.
    EdgeNotCovering {
        needed: (f64, f64),
        measured: (f64, f64),
        at_radius: f64,
    },
    /// A measured edge is compensated only on the exact offset of a
    /// smooth profile: not on a profile with corners (at this radius) nor
    /// with Lei's searches (`corner_at` None).
    EdgeNotCompensated { corner_at: Option<f64> },
    /// Lei's searches would take more than [`MAX_SEARCH_COUNT`]: the
    /// profile discretised every `step` mm over `span` mm (`parameter`
    /// `search_spacing`), or the sequential search's descent in steps of
    /// `step` mm over `span` mm at each centre (`search_step`); `count`
    /// is the span over the step (infinite or NaN where it is no number).
    SearchTooFine {
        parameter: &'static str,
        span: f64,
        step: f64,
        count: f64,
    },
}

/// The most points Lei's searches discretise a profile into, and the most
/// steps the sequential search descends at one centre: 200 million, the
/// most points lensc plans for one job (its up-front estimate's limit),
/// 3.2 GB of discretised points. A finer `search_spacing` aborted on its
/// allocation; a finer `search_step` descended for ever.
pub const MAX_SEARCH_COUNT: usize = 200_000_000;

/// Number of radii at which the profile is scanned for curvature and slope.
const SCAN_POINTS: usize = 4096;

/// What the scan of a profile over the cut finds before any path is
/// planned: its smallest concave radius of curvature and its steepest
/// slope, each with the radius (mm) where it occurs, and the feed speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileScan {
    /// (radius of curvature, at radius), mm.
    pub min_concave: Option<(f64, f64)>,
    /// (slope in rad, at radius mm).
    pub max_slope: (f64, f64),
    /// The cutting feed (mm/s).
    pub feed_speed: f64,
    /// The profile's lowest and highest z over the cut (mm).
    pub sag: (f64, f64),
}

/// Checks a turning job against its profile before planning: the profile
/// is defined over the cut, the nose fits its smallest concave radius of
/// curvature, the feed and the spindle speed are within the machine's
/// limits. The compiler's lowering runs it so `lensc check` reports these;
/// the planner runs it again as its precondition. Every reason found, or
/// the scan.
pub fn check_profile_turning(
    job: &TurningJob,
    profile: &dyn Profile,
) -> Result<ProfileScan, Vec<PlanError>> {
    let strat = &job.strategy;
    let rho = job.tool.nose_radius;
    let start = strat.start_radius.unwrap_or(job.surface.aperture_radius);
    let feed_speed = match strat.feed {
        Feed::PerRevolution(f) => f * strat.spindle_speed,
        Feed::PerTime(v) => v,
    };
    let scan = scan_profile(profile, start, strat.end_radius, feed_speed).map_err(|e| vec![e])?;
    let mut errors = Vec::new();
    if let Some((min_radius, at_radius)) = scan.min_concave
        && rho > min_radius
    {
        errors.push(PlanError::NoseTooLarge {
            nose_radius: rho,
            min_radius,
            at_radius,
        });
    }
    errors.extend(rate_errors(&job.machine, strat, feed_speed));
    errors.extend(search_errors(
        strat,
        rho,
        cut_range(start, strat.end_radius, rho),
        scan.sag,
    ));
    if let Some(e) = &job.tool.edge {
        errors.extend(edge_coverage(profile, &e.profile, start, strat.end_radius));
        if strat.location != ToolLocation::Exact {
            errors.push(PlanError::EdgeNotCompensated { corner_at: None });
        }
    }
    if errors.is_empty() {
        Ok(scan)
    } else {
        Err(errors)
    }
}

/// Plans the profile-turning path of `job` along `profile` (the surface's
/// section, from the JIT kernel in a build), or says every reason it cannot.
pub fn plan_profile_turning(
    job: &TurningJob,
    profile: &dyn Profile,
) -> Result<Toolpath, Vec<PlanError>> {
    let scan = check_profile_turning(job, profile)?;
    let strat = &job.strategy;
    let rho = job.tool.nose_radius;
    let start = strat.start_radius.unwrap_or(job.surface.aperture_radius);
    let end = strat.end_radius;

    let (lo, hi) = cut_range(start, end, rho);
    let pieces = envelope::split_at_corners(profile, lo, hi);
    if job.tool.edge.is_some()
        && let Some(c) = pieces.corners.first()
    {
        return Err(vec![PlanError::EdgeNotCompensated {
            corner_at: Some(c.at),
        }]);
    }
    let seams = seams(profile, &pieces, rho, start.min(end), hi);
    let section = Section {
        profile,
        pieces: &pieces,
        start,
        end,
    };
    let cut = cut_path(&section, &job.tool.nose(), strat);
    let mut passes = roughing_passes(&section, rho, strat, &cut);
    let stock = stock_outline(&section, rho, strat, &cut);
    let roughing_count = passes.len();
    passes.push(cut);
    let linked = link_passes(&passes, roughing_count, strat, &stock, job.machine.max_feed);
    let cut = passes.pop().expect("the finish pass");
    let cutting_time = linked.pass_times.iter().sum();

    if let Some(e) = travel_error(&job.machine, &linked.moves) {
        return Err(vec![e]);
    }
    Ok(Toolpath {
        cut_points: cut.len(),
        moves: linked.moves,
        cut_length: linked.cut_length,
        feed_speed: scan.feed_speed,
        cutting_time,
        pass_times: linked.pass_times,
        min_concave_radius: scan.min_concave,
        max_slope: scan.max_slope,
        seams,
        roughing_passes: roughing_count,
        pass_starts: linked.pass_starts,
    })
}

/// The contact angles of the cut from `start` to `end` (rad, atan of the
/// slope: where the surface meets the nose) that `edge` does not cover.
fn edge_coverage(
    profile: &dyn Profile,
    edge: &crate::machine::edge::EdgeProfile,
    start: f64,
    end: f64,
) -> Option<PlanError> {
    let (mut lo, mut hi) = ((f64::INFINITY, 0.0), (f64::NEG_INFINITY, 0.0));
    for i in 0..=SCAN_POINTS {
        let r = end + (start - end) * i as f64 / SCAN_POINTS as f64;
        let a = profile.point(r).dz.atan();
        if a < lo.0 {
            lo = (a, r);
        }
        if a > hi.0 {
            hi = (a, r);
        }
    }
    let (m0, m1) = edge.range();
    let outside = if lo.0 < m0 {
        Some(lo.1)
    } else if hi.0 > m1 {
        Some(hi.1)
    } else {
        None
    };
    outside.map(|at_radius| PlanError::EdgeNotCovering {
        needed: (lo.0, hi.0),
        measured: (m0, m1),
        at_radius,
    })
}

/// Scans the profile at `SCAN_POINTS` radii from `end` to `start` for its
/// curvature and slope, or says where it is undefined.
fn scan_profile(
    profile: &dyn Profile,
    start: f64,
    end: f64,
    feed_speed: f64,
) -> Result<ProfileScan, PlanError> {
    let mut min_concave: Option<(f64, f64)> = None;
    let mut max_slope = (0.0f64, 0.0f64);
    let mut sag = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..=SCAN_POINTS {
        let r = end + (start - end) * i as f64 / SCAN_POINTS as f64;
        let p = profile.point(r);
        if !(p.z.is_finite() && p.dz.is_finite() && p.d2z.is_finite()) {
            return Err(PlanError::Undefined { at_radius: r });
        }
        sag = (sag.0.min(p.z), sag.1.max(p.z));
        let slope = p.dz.atan().abs();
        if slope > max_slope.0 {
            max_slope = (slope, r);
        }
        if p.d2z > 0.0 {
            let radius = (1.0 + p.dz * p.dz).powf(1.5) / p.d2z;
            if min_concave.is_none_or(|(m, _)| radius < m) {
                min_concave = Some((radius, r));
            }
        }
    }
    Ok(ProfileScan {
        min_concave,
        max_slope,
        feed_speed,
        sag,
    })
}

/// The profile the nose can touch: the cut range from `start` to `end`
/// and, at the centre, its mirror image across the axis.
fn cut_range(start: f64, end: f64, rho: f64) -> (f64, f64) {
    let (a, b) = (start.min(end), start.max(end));
    (if a <= 0.0 { a - rho } else { a }, b)
}

/// Lei's searches counted before anything is allocated or looped over:
/// the discretised profile's points over `range` (as `cut_path` takes
/// them), and the sequential search's descent at one centre, from ρ over
/// the highest point to ρ under the lowest of `sag`.
fn search_errors(
    strat: &ProfileTurning,
    rho: f64,
    range: (f64, f64),
    sag: (f64, f64),
) -> Vec<PlanError> {
    let (spacing, descent) = match strat.location {
        ToolLocation::Exact => return Vec::new(),
        ToolLocation::Sequential { spacing, step } => (spacing, Some(step)),
        ToolLocation::Binary { spacing, .. } => (spacing, None),
    };
    let span = range.1 - range.0;
    let mut errors = Vec::new();
    if count::steps_over(span, spacing, 1, MAX_SEARCH_COUNT).is_none() {
        errors.push(PlanError::SearchTooFine {
            parameter: "search_spacing",
            span,
            step: spacing,
            count: span / spacing,
        });
    }
    if let Some(step) = descent {
        let depth = sag.1 - sag.0 + 2.0 * rho;
        if count::steps_over(depth, step, 1, MAX_SEARCH_COUNT).is_none() {
            errors.push(PlanError::SearchTooFine {
                parameter: "search_step",
                span: depth,
                step,
                count: depth / step,
            });
        }
    }
    errors
}

/// The feed and spindle speed the machine cannot give.
/// The finish's and, with roughing passes, theirs.
fn rate_errors(machine: &Lathe, strat: &ProfileTurning, feed_speed: f64) -> Vec<PlanError> {
    let mut errors = Vec::new();
    let rough = strat.roughing.map(|_| PassRates::roughing(strat));
    let rough_feed = rough.map(|r| match r.feed {
        Feed::PerRevolution(f) => f * r.spindle_speed,
        Feed::PerTime(v) => v,
    });
    let fastest = rough_feed.map_or(feed_speed, |r| r.max(feed_speed));
    if fastest > machine.max_feed {
        errors.push(PlanError::FeedTooHigh {
            feed: fastest,
            max: machine.max_feed,
        });
    }
    let spindle = rough.map_or(strat.spindle_speed, |r| {
        r.spindle_speed.max(strat.spindle_speed)
    });
    if spindle > machine.max_spindle_speed {
        errors.push(PlanError::SpindleTooFast {
            speed: spindle,
            max: machine.max_spindle_speed,
        });
    }
    errors
}

/// The passes joined into one move stream, with what it costs.
struct LinkedPasses {
    moves: Vec<Move>,
    /// Length (mm) of the feed moves, the plunges included.
    cut_length: f64,
    /// Cutting time (s) of each pass.
    pass_times: Vec<f64>,
    /// Where each pass begins in `moves`.
    pass_starts: Vec<usize>,
}

/// What lies over a pass before it cuts, as the nose centre meets it: the
/// path the pass before ran (its material is that pass's cut), the
/// stock's, or a flat face.
#[derive(Clone, Debug, PartialEq)]
enum Outline {
    /// Nose-centre points (along the path, X either way).
    Path(Vec<Vector2<f64>>),
    /// A flat face: the nose centre meets it at this height everywhere.
    Level(f64),
}

impl Outline {
    /// The nose-centre height (mm) at which the nose meets this material
    /// at X `x`, or `None` where the outline does not reach `x`. A path is
    /// interpolated between the two points about `x`: the nose centre at
    /// or above the exact offset of a surface is clear of that surface,
    /// and the chords stray from it by the chord tolerance, which the
    /// approach's clearance covers.
    fn height_at(&self, x: f64) -> Option<f64> {
        match self {
            Outline::Level(z) => Some(*z),
            Outline::Path(points) => points.windows(2).find_map(|w| {
                let (a, b) = (w[0], w[1]);
                let (lo, hi) = (a.x.min(b.x), a.x.max(b.x));
                if x < lo || x > hi {
                    return None;
                }
                if hi - lo <= 0.0 {
                    return Some(a.y.max(b.y));
                }
                let t = (x - a.x) / (b.x - a.x);
                Some(a.y + t * (b.y - a.y))
            }),
        }
    }
}

/// Each pass in turn: a rapid above its first point at the safe height
/// (the retract above the highest point of any pass), the approach down
/// to it (`plan::approach`: a rapid to a clearance over the part's top, a
/// feed through the air, the last clearance and any material at the
/// pass's feed), the pass, and a rapid back up. The first `roughing`
/// passes are timed at the roughing feed and spindle speed. `stock` is
/// what lies over the first pass; over each later pass lies the pass
/// before it.
fn link_passes(
    passes: &[Vec<Vector2<f64>>],
    roughing: usize,
    strat: &ProfileTurning,
    stock: &Outline,
    max_feed: f64,
) -> LinkedPasses {
    let cuts_top = passes
        .iter()
        .flatten()
        .map(|c| c.y)
        .fold(f64::NEG_INFINITY, f64::max);
    let safe_z = cuts_top + strat.retract;
    // Rapids stay above the stock as well as above the cuts.
    let top = match stock {
        Outline::Level(z) => cuts_top.max(*z),
        Outline::Path(_) => cuts_top,
    };
    let mut moves = Vec::with_capacity(passes.iter().map(|p| p.len() + 5).sum());
    let mut cut_length = 0.0;
    let mut pass_times = Vec::with_capacity(passes.len());
    let mut pass_starts = Vec::with_capacity(passes.len());
    for (i, cut) in passes.iter().enumerate() {
        let rates = if i < roughing {
            PassRates::roughing(strat)
        } else {
            PassRates::finish(strat)
        };
        let over = if i == 0 {
            stock.clone()
        } else {
            Outline::Path(passes[i - 1].clone())
        };
        // Where the outline does not reach the first point, nothing is
        // known of the material there: the whole approach below the
        // rapid is at the pass's feed.
        let material = over.height_at(cut[0].x).unwrap_or(f64::INFINITY);
        let approach = approach::Approach {
            x: cut[0].x,
            safe_z,
            top,
            material,
            start_z: cut[0].y,
            cutting_speed: rates.speed_at(cut[0].x),
            max_feed,
            retract: strat.retract,
        };
        pass_starts.push(moves.len());
        moves.push(Move::Rapid(Position::xz(cut[0].x, safe_z)));
        // The air feed in the pass's kind of feed: per revolution at the
        // spindle's speed over the first point (X does not change).
        let per_rev = match rates.feed {
            Feed::PerRevolution(f) => Some(f / approach.cutting_speed),
            Feed::PerTime(_) => None,
        };
        moves.extend(approach.moves(None, |v| match per_rev {
            Some(k) => crate::moves::Feed::PerRevolution(k * v),
            None => crate::moves::Feed::PerTime(v),
        }));
        let (mut time, length) = approach.feed_time_and_length();
        cut_length += length;
        for w in cut.windows(2) {
            let len = (w[1] - w[0]).norm();
            cut_length += len;
            time += len / rates.speed_at(0.5 * (w[0].x + w[1].x));
        }
        pass_times.push(time);
        moves.extend(cut.iter().skip(1).map(|c| cutting(c.x, c.y)));
        let last = cut[cut.len() - 1];
        moves.push(Move::Rapid(Position::xz(last.x, safe_z)));
    }
    LinkedPasses {
        moves,
        cut_length,
        pass_times,
        pass_starts,
    }
}

/// The feed and spindle one pass runs at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassRates {
    pub feed: Feed,
    /// Constant speed, or the cap under constant surface speed (rad/s).
    pub spindle_speed: f64,
    /// Constant surface speed (mm/s), if the pass runs at one.
    pub surface_speed: Option<f64>,
}

impl PassRates {
    /// The finish pass's: the strategy's feed and spindle.
    pub fn finish(strat: &ProfileTurning) -> PassRates {
        PassRates {
            feed: strat.feed,
            spindle_speed: strat.spindle_speed,
            surface_speed: strat.surface_speed,
        }
    }

    /// A roughing pass's: its own feed, and its own constant spindle
    /// speed if it has one, else the finish's spindle.
    pub fn roughing(strat: &ProfileTurning) -> PassRates {
        let finish = PassRates::finish(strat);
        match strat.roughing {
            Some(r) => PassRates {
                feed: r.feed,
                spindle_speed: r.spindle_speed.unwrap_or(finish.spindle_speed),
                surface_speed: if r.spindle_speed.is_some() {
                    None
                } else {
                    finish.surface_speed
                },
            },
            None => finish,
        }
    }

    /// The feed speed (mm/s) at radius r.
    pub fn speed_at(&self, r: f64) -> f64 {
        match (self.feed, self.surface_speed) {
            (Feed::PerTime(v), _) => v,
            (Feed::PerRevolution(f), None) => f * self.spindle_speed,
            (Feed::PerRevolution(f), Some(v)) => {
                f * if r.abs() * self.spindle_speed > v {
                    v / r.abs()
                } else {
                    self.spindle_speed
                }
            }
        }
    }
}

/// A cutting move of the nose centre to (x, z), at the job's feed.
fn cutting(x: f64, z: f64) -> Move {
    Move::Linear {
        to: Position::xz(x, z),
        feed: None,
    }
}

/// The first move, X before Z, that leaves the machine's travel.
fn travel_error(machine: &Lathe, moves: &[Move]) -> Option<PlanError> {
    moves.iter().find_map(|m| {
        let (Move::Rapid(to) | Move::Linear { to, .. }) = *m else {
            return None;
        };
        let (x, z) = (to.x, to.z);
        [('X', x, machine.travel_x), ('Z', z, machine.travel_z)]
            .into_iter()
            .find_map(|(axis, value, (min, max))| {
                (value < min || value > max).then_some(PlanError::OutOfTravel {
                    axis,
                    value,
                    min,
                    max,
                })
            })
    })
}

/// What lies over the first pass, as the nose centre meets it: the
/// stock's face, the stock's offset surface, or, with no stock given,
/// the design itself (a finishing job's blank is taken to be the part
/// within what the finish pass removes).
fn stock_outline(
    section: &Section,
    rho: f64,
    strat: &ProfileTurning,
    finish: &[Vector2<f64>],
) -> Outline {
    match strat.roughing.map(|r| r.stock) {
        None => Outline::Path(finish.to_vec()),
        Some(Stock::Flat { top }) => Outline::Level(top + rho),
        Some(Stock::Offset { allowance }) => {
            let exact = ProfileTurning {
                location: ToolLocation::Exact,
                chords: ChordPlacement::OnPath,
                ..strat.clone()
            };
            Outline::Path(cut_path(section, &Nose::circle(rho + allowance), &exact))
        }
    }
}

/// The roughing passes, outermost first: each the exact nose-centre path
/// for the design offset by that pass's allowance (a nose of radius
/// ρ + allowance), and with flat stock never deeper than its level below
/// the stock's top.
fn roughing_passes(
    section: &Section,
    rho: f64,
    strat: &ProfileTurning,
    finish: &[Vector2<f64>],
) -> Vec<Vec<Vector2<f64>>> {
    let Some(r) = strat.roughing else {
        return Vec::new();
    };
    let doc = r.depth_of_cut;
    let f = r.finish_allowance;
    let offset = |allowance: f64| -> Vec<Vector2<f64>> {
        if allowance == 0.0 {
            return finish.to_vec();
        }
        let exact = ProfileTurning {
            location: ToolLocation::Exact,
            chords: ChordPlacement::OnPath,
            ..strat.clone()
        };
        cut_path(section, &Nose::circle(rho + allowance), &exact)
    };
    let mut passes = Vec::new();
    match r.stock {
        Stock::Offset { allowance } => {
            let mut k = 1.0;
            while allowance - k * doc > f + 1e-12 && passes.len() < 10_000 {
                passes.push(offset(allowance - k * doc));
                k += 1.0;
            }
            if f > 0.0 && allowance > f {
                passes.push(offset(f));
            }
        }
        Stock::Flat { top } => {
            let last = offset(f);
            let lowest = last.iter().map(|c| c.y).fold(f64::INFINITY, f64::min);
            let mut k = 1.0;
            loop {
                // The nose's bottom at this level: its centre ρ above.
                let level = top - k * doc + rho;
                if level <= lowest || passes.len() >= 10_000 {
                    break;
                }
                passes.push(
                    last.iter()
                        .map(|c| Vector2::new(c.x, c.y.max(level)))
                        .collect(),
                );
                k += 1.0;
            }
            if f > 0.0 {
                passes.push(last);
            }
        }
    }
    passes
}

/// The part of the profile a cut runs over: its smooth pieces, from
/// radius `start` to `end`.
struct Section<'a> {
    profile: &'a dyn Profile,
    pieces: &'a Pieces,
    start: f64,
    end: f64,
}

/// The nose-centre points of the cut, within the chord tolerance of the
/// curve the chosen tool location gives, placed across it as the
/// strategy's `chords` says. A measured edge is compensated on the exact
/// offset (`tool_centre_by`); the planner refuses it elsewhere.
fn cut_path(section: &Section, nose: &Nose, strat: &ProfileTurning) -> Vec<Vector2<f64>> {
    let rho = nose.radius;
    let placement = strat.chords;
    let sample = |c: &dyn Fn(f64) -> Vector2<f64>, a: f64, b: f64, tol: f64| {
        if placement == ChordPlacement::OnPath {
            return sample_offset_curve(c, a, b, tol);
        }
        let (pts, params) = sample_offset_curve_at(c, a, b, tol);
        placed(placement, c, &pts, &params, tol)
    };
    let Section {
        profile,
        pieces,
        start,
        end,
    } = *section;
    let tol = strat.chord_tolerance * crate::plan::optimise::CHORD_SHARE * placement.sag_factor();
    // The ends of the cut in the tool's x: the normal offsets of its ends.
    let (x0, x1) = (
        tool_centre_by(profile, nose, start).x,
        tool_centre_by(profile, nose, end).x,
    );
    let discretised = |spacing: f64| -> Vec<(f64, f64)> {
        let (a, b) = (pieces.bounds[0], pieces.bounds[pieces.bounds.len() - 1]);
        // Counted by `check_profile_turning` (`search_errors`) over the
        // same range: a count it refused never gets here.
        let n = count::steps_over(b - a, spacing, 1, MAX_SEARCH_COUNT)
            .expect("the discretisation was counted before planning");
        (0..=n)
            .map(|i| {
                let u = a + (b - a) * i as f64 / n as f64;
                (u, profile.point(u).z)
            })
            .collect()
    };
    match strat.location {
        ToolLocation::Exact if pieces.corners.is_empty() => {
            let centre = |r: f64| tool_centre_by(profile, nose, r);
            sample(&centre, start, end, tol)
        }
        ToolLocation::Exact => {
            let centre =
                |x: f64| Vector2::new(x, envelope::centre_height(profile, pieces, rho, x).0);
            sample(&centre, x0, x1, tol)
        }
        ToolLocation::Sequential { spacing, step } => {
            let pts = discretised(spacing);
            let top = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max) + rho;
            let centre =
                |x: f64| Vector2::new(x, envelope::sequential_search(&pts, rho, x, top, step));
            sample(&centre, x0, x1, tol)
        }
        ToolLocation::Binary { spacing, tolerance } => {
            let pts = discretised(spacing);
            let centre = |x: f64| {
                let near = envelope::points_near(&pts, x, rho);
                Vector2::new(x, envelope::binary_search(near, rho, x, tolerance))
            };
            sample(&centre, x0, x1, tol)
        }
    }
}

/// The concave corners on [a, b] where the nose leaves more than 1 nm of
/// material above the design.
fn seams(profile: &dyn Profile, pieces: &Pieces, rho: f64, a: f64, b: f64) -> Vec<Seam> {
    pieces
        .corners
        .iter()
        .filter(|c| c.is_concave() && c.at >= a && c.at <= b)
        .filter_map(|c| {
            let depth = envelope::cut_height(profile, pieces, rho, c.at) - profile.point(c.at).z;
            (depth > 1e-6).then(|| Seam {
                at_radius: c.at,
                depth,
                angle: c.angle(),
            })
        })
        .collect()
}

/// The nose centre when the nose touches the profile at radius `r`: the
/// profile point moved by ρ along the unit normal that points to the tool.
pub fn tool_centre(profile: &dyn Profile, nose_radius: f64, r: f64) -> Vector2<f64> {
    tool_centre_by(profile, &Nose::circle(nose_radius), r)
}

/// The nose centre when a nose whose edge may be measured touches the
/// profile at radius `r`: the profile point moved along the normal by the
/// edge's support h(φ) at the contact angle φ = atan(dz/dr)
/// (`Nose::support`, R + δ(φ) to first order).
pub fn tool_centre_by(profile: &dyn Profile, nose: &Nose, r: f64) -> Vector2<f64> {
    let p = profile.point(r);
    let normal = Vector2::new(-p.dz, 1.0).normalize();
    let h = match nose.edge {
        None => nose.radius,
        Some(_) => nose.support(p.dz.atan()).1,
    };
    Vector2::new(r, p.z) + h * normal
}

/// Samples the curve `c(t)` for t from `a` to `b` so that no chord strays
/// more than `tol` from it: uniform seeds, then bisection wherever the
/// curve's midpoint (or quarter points) lies too far from the chord.
pub fn sample_offset_curve(
    c: &dyn Fn(f64) -> Vector2<f64>,
    a: f64,
    b: f64,
    tol: f64,
) -> Vec<Vector2<f64>> {
    sample_offset_curve_at(c, a, b, tol).0
}

/// The points (X, Z) `pts` of the curve `c`, at parameters `params`, each
/// moved along Z by `placement`'s offset for the bands of the chords it
/// joins (`plan::chords`): the curve's height above each chord measured
/// at three points between its ends. Straddling, every chord is held
/// within half the chords' share `share` (chords split where that takes
/// more points).
fn placed(
    placement: ChordPlacement,
    c: &dyn Fn(f64) -> Vector2<f64>,
    pts: &[Vector2<f64>],
    params: &[f64],
    share: f64,
) -> Vec<Vector2<f64>> {
    if placement.straddles() {
        let knots: Vec<chords::Knot> = pts
            .iter()
            .zip(params)
            .map(|(p, &s)| chords::Knot { s, u: p.x, z: p.y })
            .collect();
        let mut exact = |s: f64| {
            let q = c(s);
            (q.x, q.y)
        };
        let (knots, _) =
            chords::straddle(&knots, (None, None), 0.5 * share, &mut exact, &|_, _| true);
        return knots.iter().map(|k| Vector2::new(k.u, k.z)).collect();
    }
    let bands: Vec<Band> = (0..pts.len().saturating_sub(1))
        .map(|j| {
            let (s0, s1) = (params[j], params[j + 1]);
            let inner = [0.25, 0.5, 0.75].map(|f| {
                let q = c(s0 + f * (s1 - s0));
                (q.x, q.y)
            });
            Band::between((pts[j].x, pts[j].y), (pts[j + 1].x, pts[j + 1].y), inner)
        })
        .collect();
    let mut graph: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.y)).collect();
    chords::place_graph(placement, &mut graph, &bands);
    graph.into_iter().map(|(x, z)| Vector2::new(x, z)).collect()
}

/// `sample_offset_curve`, with the parameter of each point.
fn sample_offset_curve_at(
    c: &dyn Fn(f64) -> Vector2<f64>,
    a: f64,
    b: f64,
    tol: f64,
) -> (Vec<Vector2<f64>>, Vec<f64>) {
    const SEEDS: usize = 32;
    const MAX_DEPTH: u32 = 40;
    let mut out = vec![c(a)];
    let mut params = vec![a];
    for i in 0..SEEDS {
        let t0 = a + (b - a) * i as f64 / SEEDS as f64;
        let t1 = a + (b - a) * (i + 1) as f64 / SEEDS as f64;
        // Depth-first bisection with an explicit stack, emitting in order.
        let mut stack = vec![(t0, c(t0), t1, c(t1), 0u32)];
        while let Some((s0, p0, s1, p1, depth)) = stack.pop() {
            let too_far = [0.25, 0.5, 0.75].iter().any(|f| {
                let q = c(s0 + (s1 - s0) * f);
                distance_to_segment(q, p0, p1) > tol
            });
            if too_far && depth < MAX_DEPTH {
                let sm = 0.5 * (s0 + s1);
                let pm = c(sm);
                stack.push((sm, pm, s1, p1, depth + 1));
                stack.push((s0, p0, sm, pm, depth + 1));
            } else {
                out.push(p1);
                params.push(s1);
            }
        }
    }
    (out, params)
}

fn distance_to_segment(q: Vector2<f64>, a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    if len2 == 0.0 {
        return (q - a).norm();
    }
    let t = ((q - a).dot(&ab) / len2).clamp(0.0, 1.0);
    (q - (a + t * ab)).norm()
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod roughing_tests;

#[cfg(test)]
mod edge_tests;
