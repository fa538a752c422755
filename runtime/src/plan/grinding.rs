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

/// Plans one grinding pass of `p` along `profile`: wheel-centre points at
/// contact-x interval δ with each interval's commanded z velocity and
/// acceleration (paper eqs 17–19).
pub fn plan_profile_grinding(
    p: &ProfileGrinding,
    profile: &dyn Profile,
) -> Result<GrindingPath, GrindingError> {
    check_parameters(p)?;
    let wheel_radius = 0.5 * p.wheel_diameter;
    let length = (p.end - p.start).abs();
    let dir = (p.end - p.start).signum();

    // Number of intervals: length/δ, rounded when it is an integer up to
    // rounding (1.6 mm / 1 µm), else one more, shorter, last interval.
    let ratio = length / p.interval;
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
    let segments = count as usize;
    let station = |i: usize| {
        if i >= segments {
            p.end
        } else {
            p.start + dir * i as f64 * p.interval
        }
    };

    // Curvature: contact points, interval midpoints and an even scan.
    let mut min_concave: Option<(f64, f64)> = None;
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
    let mut contacts = Vec::with_capacity(segments + 1);
    for i in 0..=segments {
        let x = station(i);
        contacts.push((x, check(x)?));
        if i > 0 {
            check(0.5 * (station(i - 1) + x))?;
        }
    }
    for i in 0..=SCAN_POINTS {
        check(p.start + (p.end - p.start) * i as f64 / SCAN_POINTS as f64)?;
    }
    if let Some((curvature_radius, x)) = min_concave
        && wheel_radius > curvature_radius
    {
        return Err(GrindingError::WheelTooLarge {
            x,
            wheel_radius,
            curvature_radius,
        });
    }

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
    let gamma = p.smoothness;
    let interval_time = p.interval / p.feed;
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
    if !(max_speed.is_finite() && max_acceleration.is_finite()) {
        return Err(GrindingError::NonFiniteSurface { x: p.start });
    }

    Ok(GrindingPath {
        points,
        segments,
        interval_time,
        total_time: length / p.feed,
        max_speed,
        max_acceleration,
        open_loop_drift,
        min_concave_radius: min_concave,
    })
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
mod tests {
    use super::*;
    use crate::surface::{RotationalSurface, Sense};

    /// Paper Table 2, convex column: R = 22.405, κ = 43.098, lens radius
    /// 1.6 mm. The paper's A_j are not published, so the lens is the conic
    /// alone (its sag at the edge is 60.8 µm, not the table's 279.19 µm: the
    /// unknown A_j carry the difference).
    fn table2_convex() -> RotationalSurface {
        RotationalSurface {
            radius: 22.405,
            conic: 43.098,
            sense: Sense::Convex,
            terms: vec![],
            aperture_radius: 1.6,
        }
    }

    /// Paper Table 2, concave column: R = −4.254 (paper sign: concave; ours
    /// is `Sense::Concave` with |R|), κ = −3.359, lens radius 1.5 mm. Conic
    /// only, as above (sag 247.5 µm against the table's 84.05 µm).
    fn table2_concave() -> RotationalSurface {
        RotationalSurface {
            radius: 4.254,
            conic: -3.359,
            sense: Sense::Concave,
            terms: vec![],
            aperture_radius: 1.5,
        }
    }

    /// Table 2: D_t = 4.0 mm, γ = 0.5; δ and v_f per lens; §4.2: from the
    /// centre to the right edge.
    fn table2_pass(interval: f64, feed: f64, edge: f64) -> ProfileGrinding {
        ProfileGrinding {
            wheel_diameter: 4.0,
            interval,
            feed,
            smoothness: 0.5,
            start: 0.0,
            end: edge,
        }
    }

    /// A straight section z = m·x + c: its wheel-centre path is the same
    /// line moved along the normal.
    struct Line {
        slope: f64,
        height: f64,
    }

    impl Profile for Line {
        fn point(&self, r: f64) -> ProfilePoint {
            ProfilePoint {
                z: self.slope * r + self.height,
                dz: self.slope,
                d2z: 0.0,
            }
        }
    }

    fn sphere(sense: Sense) -> RotationalSurface {
        // Fixture: any sphere; R = 10 mm, aperture 3 mm chosen here.
        RotationalSurface {
            radius: 10.0,
            conic: 0.0,
            sense,
            terms: vec![],
            aperture_radius: 3.0,
        }
    }

    #[test]
    fn wheel_centre_on_a_sphere_lies_on_the_concentric_sphere() {
        // Geometry: the normal of a sphere passes through its centre, so the
        // wheel centre is at R + D_t/2 from it over a dome (centre (0, −R))
        // and R − D_t/2 in a bowl (centre (0, R)). D_t = 4 mm from Table 2.
        let p = ProfileGrinding {
            wheel_diameter: 4.0,
            interval: 0.01,
            feed: 0.02,
            smoothness: 0.5,
            start: -3.0,
            end: 3.0,
        };
        for (sense, centre, radius) in [
            (Sense::Convex, Vector2::new(0.0, -10.0), 12.0),
            (Sense::Concave, Vector2::new(0.0, 10.0), 8.0),
        ] {
            let path = plan_profile_grinding(&p, &sphere(sense)).unwrap();
            assert_eq!(path.segments, 600);
            for g in &path.points {
                let d = (Vector2::new(g.x, g.z) - centre).norm();
                assert!((d - radius).abs() < 1e-12, "{sense:?} x={}: {d}", g.x);
            }
        }
    }

    #[test]
    fn wheel_centres_do_not_gouge_table2_lenses() {
        // Every wheel centre is at least D_t/2 from every surface point
        // sampled every 0.15 µm across the whole lens (−edge..edge), for the
        // two Table 2 lenses with the table's D_t, δ and v_f.
        for (surf, interval, feed) in [
            (table2_convex(), 0.001, 0.020),
            (table2_concave(), 0.002, 0.010),
        ] {
            let edge = surf.aperture_radius;
            let p = table2_pass(interval, feed, edge);
            let path = plan_profile_grinding(&p, &surf).unwrap();
            let samples = 20_000;
            let surface: Vec<Vector2<f64>> = (0..=samples)
                .map(|k| {
                    let x = -edge + 2.0 * edge * k as f64 / samples as f64;
                    Vector2::new(x, surf.eval(x).z)
                })
                .collect();
            for g in path.points.iter().step_by(10) {
                let c = Vector2::new(g.x, g.z);
                let nearest = surface
                    .iter()
                    .map(|s| (s - c).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest >= 2.0 - 1e-12, "x={}: {nearest}", g.contact_x);
                // ... and the sampling is dense enough to find the contact.
                assert!(nearest < 2.0 + 1e-6, "x={}: {nearest}", g.contact_x);
            }
        }
    }

    #[test]
    fn a_plane_needs_no_z_motion() {
        // Fixture: the flat z = 0.1 with Table 2's convex δ, v_f, γ.
        let flat = Line {
            slope: 0.0,
            height: 0.1,
        };
        let path = plan_profile_grinding(&table2_pass(0.001, 0.02, 1.6), &flat).unwrap();
        assert_eq!(path.segments, 1600);
        assert!(path.points.iter().all(|g| g.velocity == 0.0));
        assert!(path.points.iter().all(|g| (g.z - 2.1).abs() < 1e-15));
        assert_eq!(path.max_acceleration, 0.0);
    }

    #[test]
    fn eq18_settles_on_a_constant_slope_and_eq19_matches_its_steps() {
        // Fixture: the line z = −0.2·x (a 0.2 slope, like a dome's side)
        // with Table 2's convex δ = 1 µm, v_f = 20 µm/s, γ = 0.5.
        // The z axis has to move at m·v_f = −4 µm/s. Eq 18's fixed point is
        // v* = m v_f/(1 − γ) = −8 µm/s (eq 9 leaves out v_{i−1}·t_a), reached
        // geometrically with ratio γ/(2 − γ) = 1/3 from rest.
        let (m, feed, interval, gamma) = (-0.2, 0.02, 0.001, 0.5);
        let line = Line {
            slope: m,
            height: 0.0,
        };
        let p = table2_pass(interval, feed, 0.1);
        let path = plan_profile_grinding(&p, &line).unwrap();
        assert_eq!(path.segments, 100);
        let settled = m * feed / (1.0 - gamma);
        let last = path.points.last().unwrap();
        assert!((last.velocity - settled).abs() < 1e-15, "{}", last.velocity);
        assert!((last.velocity / (m * feed) - 2.0).abs() < 1e-12);
        // From rest: v_0 = 2 Δq/(t_s (2 − γ)) = (4/3) m v_f.
        let v0 = path.points[1].velocity;
        assert!((v0 - 4.0 / 3.0 * m * feed).abs() < 1e-15, "{v0}");

        // Eq 19 against the velocity steps, and eq 9 (the paper's interval
        // model) against the centre-height steps q(x_{i+1}) − q(x_i) (eq 10).
        let t_s = interval / feed;
        for w in path.points.windows(2) {
            let (prev, here) = (w[0], w[1]);
            let a = feed / (gamma * interval) * (here.velocity - prev.velocity);
            assert!((here.acceleration - a).abs() <= 1e-9 * a.abs().max(1e-9));
            let t_a = gamma * t_s;
            let d = 0.5 * here.acceleration * t_a * t_a + here.velocity * (t_s - t_a);
            assert!((d - (here.z - prev.z)).abs() < 1e-15);
        }
        // Open loop, the axis gains γ t_s v_{i−1} per interval: over 100
        // intervals close to 99 γ t_s v* = 99·0.025·(−8 µm/s) ≈ −19.8 µm.
        assert!(path.open_loop_drift > 0.0195 && path.open_loop_drift < 0.0199);
    }

    /// dq/dx: slope of the wheel-centre height over contact x, from the
    /// exact derivatives: q = z + r/√(1+z'²), q' = z' − r z' z''/(1+z'²)^{3/2}.
    fn centre_slope(surf: &RotationalSurface, wheel_radius: f64, x: f64) -> f64 {
        let p = surf.eval(x);
        p.dz - wheel_radius * p.dz * p.d2z / (1.0 + p.dz * p.dz).powf(1.5)
    }

    /// Largest |q''| over the pass, by second differences of the centre
    /// heights on the uniform contact grid.
    fn max_centre_curvature(path: &GrindingPath, interval: f64) -> f64 {
        path.points
            .windows(3)
            .map(|w| ((w[2].z - 2.0 * w[1].z + w[0].z) / (interval * interval)).abs())
            .fold(0.0, f64::max)
    }

    /// Figures both Table 2 lenses must show, derived from eqs 17–19:
    /// - intervals = lens radius / δ, time = lens radius / v_f;
    /// - v settles at q'·v_f/(1 − γ), so max |v| is that at the edge, where
    ///   the centre path is steepest (lag ≪ 1 %);
    /// - a_i = Δv/(γ t_s) with Δv ≈ q'' δ v_f/(1 − γ), so
    ///   max |a| ≈ max |q''| · v_f²/(γ (1 − γ)).
    fn check_table2(surf: &RotationalSurface, p: &ProfileGrinding, path: &GrindingPath) {
        let edge = surf.aperture_radius;
        let gamma = p.smoothness;
        assert_eq!(path.segments, (edge / p.interval).round() as usize);
        assert_eq!(path.points.len(), path.segments + 1);
        assert!((path.total_time - edge / p.feed).abs() < 1e-9);
        assert!((path.interval_time - p.interval / p.feed).abs() < 1e-15);
        let v_edge = centre_slope(surf, 0.5 * p.wheel_diameter, edge) * p.feed / (1.0 - gamma);
        assert!(
            (path.max_speed - v_edge.abs()).abs() < 0.01 * v_edge.abs(),
            "{} vs {v_edge}",
            path.max_speed
        );
        assert!((path.points.last().unwrap().velocity - v_edge).abs() < 0.01 * v_edge.abs());
        let a_bound =
            max_centre_curvature(path, p.interval) * p.feed * p.feed / (gamma * (1.0 - gamma));
        assert!(
            (path.max_acceleration - a_bound).abs() < 0.02 * a_bound,
            "{} vs {a_bound}",
            path.max_acceleration
        );
        // The centre starts D_t/2 above the vertex.
        assert!((path.points[0].z - 0.5 * p.wheel_diameter).abs() < 1e-15);
        assert_eq!(path.points[0].x, 0.0);
    }

    #[test]
    fn table2_convex_lens() {
        // Table 2 convex: D_t 4 mm, δ 1 µm, v_f 20 µm/s, γ 0.5, lens radius
        // 1.6 mm, from the centre to the edge (§4.2). Conic only.
        let surf = table2_convex();
        let p = table2_pass(0.001, 0.02, 1.6);
        let path = plan_profile_grinding(&p, &surf).unwrap();
        print_figures("convex", &path);
        check_table2(&surf, &p, &path);
        assert_eq!(path.segments, 1600);
        assert!((path.total_time - 80.0).abs() < 1e-12);
        assert!(path.min_concave_radius.is_none());
        // Conic sag at the edge 60.76 µm, slope −0.0811 (computed from
        // R, κ). The dome falls away from the centre, so the wheel descends:
        // every v < 0 (in the paper's +z, into the material, they are > 0).
        let edge = surf.eval(1.6);
        assert!((edge.z + 0.060_763_66).abs() < 1e-8 && (edge.dz + 0.081_113_5).abs() < 1e-7);
        assert!(path.points[1..].iter().all(|g| g.velocity < 0.0));
        // The normal tilts outwards: the last centre is beyond the edge.
        assert!(path.points.last().unwrap().x > 1.6);
    }

    #[test]
    fn table2_concave_lens() {
        // Table 2 concave: D_t 4 mm, δ 2 µm, v_f 10 µm/s, γ 0.5, lens radius
        // 1.5 mm, from the centre to the edge. Conic only.
        let surf = table2_concave();
        let p = table2_pass(0.002, 0.01, 1.5);
        let path = plan_profile_grinding(&p, &surf).unwrap();
        print_figures("concave", &path);
        check_table2(&surf, &p, &path);
        assert_eq!(path.segments, 750);
        assert!((path.total_time - 150.0).abs() < 1e-12);
        // Conic sag at the edge 247.48 µm, slope 0.3101. The bowl rises
        // from the centre: every v > 0.
        let edge = surf.eval(1.5);
        assert!((edge.z - 0.247_475_87).abs() < 1e-8 && (edge.dz - 0.310_058_6).abs() < 1e-7);
        assert!(path.points[1..].iter().all(|g| g.velocity > 0.0));
        // Its smallest radius of curvature is the vertex radius 4.254 mm (a
        // hyperboloid flattens outwards), larger than the 2 mm wheel radius.
        let (rho, at) = path.min_concave_radius.unwrap();
        assert!((rho - 4.254).abs() < 1e-12 && at == 0.0, "{rho} at {at}");
        // The normal tilts inwards: the last centre is inside the edge.
        let last = path.points.last().unwrap();
        assert!(last.x < 1.5 && last.contact_x == 1.5);
    }

    fn print_figures(name: &str, path: &GrindingPath) {
        println!(
            "{name}: {} segments, {} s, max |v| {:.6e} mm/s, max |a| {:.6e} mm/s², \
             open-loop drift {:.6e} mm, last centre ({:.6}, {:.6})",
            path.segments,
            path.total_time,
            path.max_speed,
            path.max_acceleration,
            path.open_loop_drift,
            path.points.last().unwrap().x,
            path.points.last().unwrap().z,
        );
    }

    #[test]
    fn too_large_wheel_in_a_bowl_is_refused_where_the_bowl_is_tightest() {
        // Table 2 concave lens ground edge to edge with a 9 mm wheel (radius
        // 4.5 > the vertex radius 4.254): the tightest point is the vertex,
        // in the middle of the range.
        let mut p = table2_pass(0.002, 0.01, 1.5);
        p.start = -1.5;
        p.wheel_diameter = 9.0;
        match plan_profile_grinding(&p, &table2_concave()) {
            Err(GrindingError::WheelTooLarge {
                x,
                wheel_radius,
                curvature_radius,
            }) => {
                assert!(x.abs() < 1e-12, "{x}");
                assert_eq!(wheel_radius, 4.5);
                assert!((curvature_radius - 4.254).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        }
        // A prolate ellipse (κ = 0.5) tightens outwards: the error is at the
        // end of the range. Fixture chosen here: R = 4 mm, radius of
        // curvature (R² − κ r²)^{3/2}/R² = 3.7071... at r = 1.5.
        let ellipse = RotationalSurface {
            radius: 4.0,
            conic: 0.5,
            sense: Sense::Concave,
            terms: vec![],
            aperture_radius: 1.5,
        };
        p.start = 0.0;
        p.wheel_diameter = 7.8;
        match plan_profile_grinding(&p, &ellipse) {
            Err(GrindingError::WheelTooLarge {
                x,
                curvature_radius,
                ..
            }) => {
                assert_eq!(x, 1.5);
                let want = (16.0f64 - 0.5 * 2.25).powf(1.5) / 16.0;
                assert!((curvature_radius - want).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_parameters_and_surfaces_are_errors() {
        let surf = table2_convex();
        let good = table2_pass(0.001, 0.02, 1.6);
        let cases = [
            (
                ProfileGrinding {
                    interval: 0.0,
                    ..good.clone()
                },
                "interval",
            ),
            (
                ProfileGrinding {
                    feed: -1.0,
                    ..good.clone()
                },
                "feed",
            ),
            (
                ProfileGrinding {
                    smoothness: 1.0,
                    ..good.clone()
                },
                "smoothness",
            ),
            (
                ProfileGrinding {
                    smoothness: f64::NAN,
                    ..good.clone()
                },
                "smoothness",
            ),
            (
                ProfileGrinding {
                    wheel_diameter: f64::INFINITY,
                    ..good.clone()
                },
                "wheel diameter",
            ),
        ];
        for (p, which) in cases {
            match plan_profile_grinding(&p, &surf) {
                Err(GrindingError::InvalidParameter { name, .. }) => assert_eq!(name, which),
                other => panic!("{which}: {other:?}"),
            }
        }
        let empty = ProfileGrinding {
            end: 0.0,
            ..good.clone()
        };
        assert!(matches!(
            plan_profile_grinding(&empty, &surf),
            Err(GrindingError::EmptyRange { .. })
        ));
        let tiny = ProfileGrinding {
            interval: 1e-12,
            ..good.clone()
        };
        assert!(matches!(
            plan_profile_grinding(&tiny, &surf),
            Err(GrindingError::TooManySegments { .. })
        ));
        // The Table 2 convex conic ends at R/√(1+κ) = 3.374 mm.
        let beyond = ProfileGrinding { end: 3.5, ..good };
        match plan_profile_grinding(&beyond, &surf) {
            Err(GrindingError::NonFiniteSurface { x }) => assert!(x > 3.37 && x <= 3.5),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_short_last_interval_lands_on_the_end() {
        // 0.0105 mm at δ = 2 µm: five full intervals and one of 0.5 µm,
        // which takes 0.5 µm / v_f; total time is still length / v_f.
        let mut p = table2_pass(0.002, 0.01, 0.0105);
        p.start = 0.0;
        let path = plan_profile_grinding(&p, &table2_concave()).unwrap();
        assert_eq!(path.segments, 6);
        assert_eq!(path.points.last().unwrap().contact_x, 0.0105);
        assert!((path.total_time - 1.05).abs() < 1e-12);
        // Reversed direction: edge to centre.
        p.start = 0.0105;
        p.end = 0.0;
        let back = plan_profile_grinding(&p, &table2_concave()).unwrap();
        assert_eq!(back.segments, 6);
        assert_eq!(back.points.last().unwrap().contact_x, 0.0);
        assert!(back.points[1..].iter().all(|g| g.velocity < 0.0));
    }
}
