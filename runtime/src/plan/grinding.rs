//! Profile grinding of an aspheric lens on a two-axis (x, z) grinder with a
//! spherical wheel: one job — turn a profile and the grinding parameters
//! into the wheel-centre points and the commanded z-axis velocity and
//! acceleration of every interval, after Kim, Yang & Kim 2008 (seed 001,
//! "Sub-micron control algorithm for grinding and polishing aspherical
//! surface"), eqs 5–7 and 17–19.
//!
//! # Wheel centre (paper eqs 5–6)
//!
//! The paper writes x_t = x + (D_t/2) sin θ, z_t = z − (D_t/2) cos θ with
//! tan θ = f'(x). Its +z points *into* the material: with R > 0 its convex
//! lens has z rising with x, and the wheel centre sits at −z from the
//! contact. Our +z points out of the material (z_ours = −z_paper), so
//! tan θ = −z' and the same offset reads
//! centre = (x, z) + (D_t/2)·n, n = (−z', 1)/√(1+z'²) — the exact normal
//! offset towards the wheel. The paper's R > 0 is our `Sense::Convex`,
//! R < 0 our `Sense::Concave` with `radius = |R|`; κ carries over
//! unchanged, and the paper's A_j carry over for a convex lens and change
//! sign for a concave one.
//!
//! # Intervals and the position function q (paper §3.2, eqs 7, 10, 17)
//!
//! The paper partitions the path "by an interval on x domain" — the
//! contact-point x, not the wheel-centre x_t (partitioning on x_t "requires
//! numerical root finding" and is deferred to a later paper) and not arc
//! length. So here the contact stations are x_i = start + i·δ (the last
//! interval may be shorter to land exactly on `end`), each interval takes
//! t_s = δ/v_f (eq 17), and q(x) = z_t is the wheel-centre height as a
//! function of the *contact* x (eq 7). The x axis of the machine carries the
//! wheel centre, which moves p(x_{i+1}) − p(x_i) ≠ δ in t_s: its speed is
//! v_f only where the slope does not change.
//!
//! # Velocity and acceleration (eqs 18–19)
//!
//! v_i is the signed z-axis speed (mm/s, + towards the wheel, i.e. out of
//! the material) commanded over interval i, and a_i the acceleration that
//! ramps from v_{i−1} to v_i during the first γ·t_s of it:
//!
//!   v_i = [2 v_f/δ (q(x_{i+1}) − q(x_i)) + γ v_{i−1}] / (2 − γ)   (18)
//!   a_i = v_f/(γ δ) (v_i − v_{i−1})                                 (19)
//!
//! with v_{−1} = 0: the z axis starts at rest. These are the paper's
//! equations as published. They come from its eq 9,
//! d_i = ½ a_i t_a² + v_i (t_s − t_a), which leaves out the v_{i−1}·t_a the
//! axis travels while it accelerates. Two consequences, both kept visible
//! rather than silently "fixed": on a constant slope m the recursion
//! settles at m·v_f/(1 − γ), not m·v_f (twice it at γ = 0.5), and an axis
//! executing the commands open loop drifts from q by Σ γ t_s v_{i−1}
//! ([`GrindingPath::open_loop_drift`]). The paper closes the loop with eq 20,
//! v_c = a_i γ δ/v_f + v_{i−1} + K_p E_i + K_v (E_i − E_{i−1})/h,
//! E_i = q(x_i) − z_measured, which corrects the drift on the machine; that
//! belongs to the servo, not to this plan. (With v_{i−1}·t_a included, eq 18
//! would read [2 v_f/δ Δq − γ v_{i−1}]/(2 − γ) and settle at m·v_f.)
//!
//! The recursion is stable only for γ < 1 (its gain is γ/(2 − γ)), and γ is
//! by definition t_a/t_s, a fraction of the interval; eq 19 divides by γ.
//! So smoothness must lie in (0, 1) — the paper tried 0.1 to 0.9.

use nalgebra::Vector2;

use crate::surface::{Profile, ProfilePoint};

/// One grinding pass along a lens profile (paper §4.2: from the centre,
/// `start = 0`, to the right edge, `end` = the lens radius; any other
/// finite range, e.g. −edge..edge or edge to centre, works the same way).
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileGrinding {
    /// D_t: diameter (mm) of the spherical wheel.
    pub wheel_diameter: f64,
    /// δ: distance (mm) between contact points, measured along contact x.
    pub interval: f64,
    /// v_f: feed (mm/s) of the contact point along x.
    pub feed: f64,
    /// γ: share of each interval spent accelerating, in (0, 1).
    pub smoothness: f64,
    /// Contact x (mm) where the pass starts.
    pub start: f64,
    /// Contact x (mm) where the pass ends.
    pub end: f64,
}

/// A wheel-centre point and the command of the interval that reaches it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrindingPoint {
    /// Wheel-centre x (mm): the machine's x axis.
    pub x: f64,
    /// Wheel-centre z (mm): the machine's z axis, q(contact_x).
    pub z: f64,
    /// x (mm) of the point where the wheel touches the surface.
    pub contact_x: f64,
    /// Commanded z-axis velocity (mm/s) of the interval ending here
    /// (v_{k−1} at point k; 0 at the start point: the axis starts at rest).
    pub velocity: f64,
    /// Commanded z-axis acceleration (mm/s²) of the interval ending here
    /// (a_{k−1} at point k; 0 at the start point).
    pub acceleration: f64,
}

/// A planned grinding pass and its figures.
#[derive(Clone, Debug, PartialEq)]
pub struct GrindingPath {
    /// Wheel-centre points in grinding order, `segments + 1` of them.
    pub points: Vec<GrindingPoint>,
    /// Number of intervals.
    pub segments: usize,
    /// t_s = δ/v_f (s) of a full interval (eq 17).
    pub interval_time: f64,
    /// Grinding time of the pass (s): |end − start| / v_f.
    pub total_time: f64,
    /// Largest |v_i| (mm/s).
    pub max_speed: f64,
    /// Largest |a_i| (mm/s²).
    pub max_acceleration: f64,
    /// Largest |z − q| (mm) an axis executing the commands open loop (ramp
    /// for γ·t_s, then hold) would reach: Σ γ t_s v_{i−1}. See the module
    /// comment: eq 20's position feedback is what removes it on the machine.
    pub open_loop_drift: f64,
    /// Smallest concave radius of curvature (mm) on the range and its x,
    /// if any part of the range is concave.
    pub min_concave_radius: Option<(f64, f64)>,
}

/// Why a pass cannot be planned, with the figures a diagnostic needs.
#[derive(Clone, Debug, PartialEq)]
pub enum GrindingError {
    /// A parameter is out of range (`allowed` says the range).
    InvalidParameter {
        name: &'static str,
        value: f64,
        allowed: &'static str,
    },
    /// `start` equals `end`: nothing to grind.
    EmptyRange { start: f64, end: f64 },
    /// δ is so small that the pass would need more than `limit` intervals.
    TooManySegments { segments: f64, limit: usize },
    /// The surface (or its slope or curvature) is not finite at contact x.
    NonFiniteSurface { x: f64 },
    /// The wheel radius exceeds the smallest concave radius of curvature:
    /// the wheel cannot reach the bottom of the bowl without grinding its
    /// sides.
    WheelTooLarge {
        x: f64,
        wheel_radius: f64,
        curvature_radius: f64,
    },
}

impl std::fmt::Display for GrindingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GrindingError::InvalidParameter {
                name,
                value,
                allowed,
            } => write!(f, "grinding {name} = {value} is out of range ({allowed})"),
            GrindingError::EmptyRange { start, end } => {
                write!(f, "grinding range {start}..{end} mm is empty")
            }
            GrindingError::TooManySegments { segments, limit } => write!(
                f,
                "grinding pass needs {segments} intervals, more than {limit}"
            ),
            GrindingError::NonFiniteSurface { x } => {
                write!(f, "surface is undefined at x = {x} mm")
            }
            GrindingError::WheelTooLarge {
                x,
                wheel_radius,
                curvature_radius,
            } => write!(
                f,
                "wheel radius {wheel_radius} mm exceeds the concave radius of \
                 curvature {curvature_radius} mm at x = {x} mm"
            ),
        }
    }
}

impl std::error::Error for GrindingError {}

/// Most intervals one pass may have (keeps memory bounded on a tiny δ).
pub const MAX_SEGMENTS: usize = 2_000_000;

/// Even stations, besides the contact points and interval midpoints, at
/// which the curvature is checked.
const SCAN_POINTS: usize = 4096;

/// What a pass's profile shows before any wheel centre is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrindingScan {
    /// Number of intervals.
    pub segments: usize,
    /// Smallest concave radius of curvature (mm) on the range and its x,
    /// if any part of the range is concave.
    pub min_concave: Option<(f64, f64)>,
}

/// Checks a pass against its profile before planning: its parameters are
/// in range, the profile is defined at every contact station, interval
/// midpoint and scan point, and the wheel fits its smallest concave radius
/// of curvature there. The compiler's lowering runs it so `lensc check`
/// reports these; the planner runs it as its first step, on the same
/// points, so the figures agree.
pub fn check_profile_grinding(
    p: &ProfileGrinding,
    profile: &dyn Profile,
) -> Result<GrindingScan, GrindingError> {
    scan_profile(p, profile, |_| {})
}

/// Plans one grinding pass of `p` along `profile`: wheel-centre points at
/// contact-x interval δ with each interval's commanded z velocity and
/// acceleration (paper eqs 17–19).
pub fn plan_profile_grinding(
    p: &ProfileGrinding,
    profile: &dyn Profile,
) -> Result<GrindingPath, GrindingError> {
    let mut contacts = Vec::new();
    let scan = scan_profile(p, profile, |c| contacts.push(c))?;
    let (segments, min_concave) = (scan.segments, scan.min_concave);
    let wheel_radius = 0.5 * p.wheel_diameter;
    let length = (p.end - p.start).abs();

    // Wheel centres (eqs 5–6 in our frame) and the commands (eqs 17–19).
    let centres: Vec<Vector2<f64>> = contacts
        .iter()
        .map(|&(x, pt)| wheel_centre(x, pt, wheel_radius))
        .collect();
    if let Some(i) = centres
        .iter()
        .position(|c| !(c.x.is_finite() && c.y.is_finite()))
    {
        return Err(GrindingError::NonFiniteSurface { x: contacts[i].0 });
    }
    let interval_time = p.interval / p.feed;
    let commands = commands(p, &contacts, &centres, interval_time);
    if !(commands.max_speed.is_finite() && commands.max_acceleration.is_finite()) {
        return Err(GrindingError::NonFiniteSurface { x: p.start });
    }

    Ok(GrindingPath {
        points: commands.points,
        segments,
        interval_time,
        total_time: length / p.feed,
        max_speed: commands.max_speed,
        max_acceleration: commands.max_acceleration,
        open_loop_drift: commands.open_loop_drift,
        min_concave_radius: min_concave,
    })
}

/// Number of intervals: length/δ, rounded when it is an integer up to
/// rounding (1.6 mm / 1 µm), else one more, shorter, last interval.
fn segment_count(length: f64, interval: f64) -> Result<usize, GrindingError> {
    let ratio = length / interval;
    let nearest = ratio.round();
    let count = if (ratio - nearest).abs() <= 1e-9 * nearest.max(1.0) {
        nearest.max(1.0)
    } else {
        ratio.ceil()
    };
    // (length and δ are finite and δ > 0, so count is never NaN.)
    if count > MAX_SEGMENTS as f64 {
        return Err(GrindingError::TooManySegments {
            segments: count,
            limit: MAX_SEGMENTS,
        });
    }
    Ok(count as usize)
}

/// A contact x and the profile there.
type Contact = (f64, ProfilePoint);

/// The smallest concave radius of curvature (mm) and its x, if any.
type MinConcave = Option<(f64, f64)>;

/// The check of `check_profile_grinding`, handing each contact station
/// (in order, `segments + 1` of them) to `station` as it is evaluated:
/// the smallest concave radius of curvature (and its x) over the contact
/// points, interval midpoints and an even scan, or the first x where the
/// profile is undefined, or the wheel that does not fit.
fn scan_profile(
    p: &ProfileGrinding,
    profile: &dyn Profile,
    mut station: impl FnMut(Contact),
) -> Result<GrindingScan, GrindingError> {
    check_parameters(p)?;
    let segments = segment_count((p.end - p.start).abs(), p.interval)?;
    let dir = (p.end - p.start).signum();
    let at = |i: usize| {
        if i >= segments {
            p.end
        } else {
            p.start + dir * i as f64 * p.interval
        }
    };
    let mut min_concave: MinConcave = None;
    let mut check = |x: f64| -> Result<ProfilePoint, GrindingError> {
        let pt = profile.point(x);
        if !(pt.z.is_finite() && pt.dz.is_finite() && pt.d2z.is_finite()) {
            return Err(GrindingError::NonFiniteSurface { x });
        }
        if pt.d2z > 0.0 {
            let radius = (1.0 + pt.dz * pt.dz).powf(1.5) / pt.d2z;
            if min_concave.is_none_or(|(m, _)| radius < m) {
                min_concave = Some((radius, x));
            }
        }
        Ok(pt)
    };
    for i in 0..=segments {
        let x = at(i);
        station((x, check(x)?));
        if i > 0 {
            check(0.5 * (at(i - 1) + x))?;
        }
    }
    for i in 0..=SCAN_POINTS {
        check(p.start + (p.end - p.start) * i as f64 / SCAN_POINTS as f64)?;
    }
    let wheel_radius = 0.5 * p.wheel_diameter;
    if let Some((curvature_radius, x)) = min_concave
        && wheel_radius > curvature_radius
    {
        return Err(GrindingError::WheelTooLarge {
            x,
            wheel_radius,
            curvature_radius,
        });
    }
    Ok(GrindingScan {
        segments,
        min_concave,
    })
}

/// The pass's points with each interval's commands, and their extremes.
struct Commands {
    points: Vec<GrindingPoint>,
    max_speed: f64,
    max_acceleration: f64,
    open_loop_drift: f64,
}

/// Each interval's commanded z velocity (eq 18) and acceleration (eq 19),
/// the axis starting at rest.
fn commands(
    p: &ProfileGrinding,
    contacts: &[Contact],
    centres: &[Vector2<f64>],
    interval_time: f64,
) -> Commands {
    let segments = contacts.len() - 1;
    let gamma = p.smoothness;
    let mut points = Vec::with_capacity(segments + 1);
    points.push(GrindingPoint {
        x: centres[0].x,
        z: centres[0].y,
        contact_x: contacts[0].0,
        velocity: 0.0,
        acceleration: 0.0,
    });
    let (mut v_prev, mut max_speed, mut max_acceleration) = (0.0f64, 0.0f64, 0.0f64);
    let (mut drift, mut open_loop_drift) = (0.0f64, 0.0f64);
    for i in 0..segments {
        // t_s of this interval: δ/v_f, or the short last one's length/v_f.
        let t_s = if i + 1 == segments {
            (contacts[i + 1].0 - contacts[i].0).abs() / p.feed
        } else {
            interval_time
        };
        let dq = centres[i + 1].y - centres[i].y;
        let v = (2.0 * dq / t_s + gamma * v_prev) / (2.0 - gamma); // eq 18
        let a = (v - v_prev) / (gamma * t_s); // eq 19
        drift += gamma * t_s * v_prev;
        open_loop_drift = open_loop_drift.max(drift.abs());
        max_speed = max_speed.max(v.abs());
        max_acceleration = max_acceleration.max(a.abs());
        points.push(GrindingPoint {
            x: centres[i + 1].x,
            z: centres[i + 1].y,
            contact_x: contacts[i + 1].0,
            velocity: v,
            acceleration: a,
        });
        v_prev = v;
    }
    Commands {
        points,
        max_speed,
        max_acceleration,
        open_loop_drift,
    }
}

/// The wheel centre when the wheel of radius `wheel_radius` touches the
/// profile at contact x: the point moved along the unit normal towards the
/// wheel (paper eqs 5–6 with our +z).
pub fn wheel_centre(x: f64, pt: ProfilePoint, wheel_radius: f64) -> Vector2<f64> {
    let normal = Vector2::new(-pt.dz, 1.0) / (1.0 + pt.dz * pt.dz).sqrt();
    Vector2::new(x, pt.z) + wheel_radius * normal
}

fn check_parameters(p: &ProfileGrinding) -> Result<(), GrindingError> {
    let invalid = |name, value, allowed| {
        Err(GrindingError::InvalidParameter {
            name,
            value,
            allowed,
        })
    };
    if !(p.wheel_diameter.is_finite() && p.wheel_diameter > 0.0) {
        return invalid("wheel diameter", p.wheel_diameter, "finite, > 0 mm");
    }
    if !(p.interval.is_finite() && p.interval > 0.0) {
        return invalid("interval", p.interval, "finite, > 0 mm");
    }
    if !(p.feed.is_finite() && p.feed > 0.0) {
        return invalid("feed", p.feed, "finite, > 0 mm/s");
    }
    if !(p.smoothness > 0.0 && p.smoothness < 1.0) {
        return invalid("smoothness", p.smoothness, "0 < γ < 1");
    }
    if !p.start.is_finite() {
        return invalid("start", p.start, "finite");
    }
    if !p.end.is_finite() {
        return invalid("end", p.end, "finite");
    }
    if p.start == p.end {
        return Err(GrindingError::EmptyRange {
            start: p.start,
            end: p.end,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests;
