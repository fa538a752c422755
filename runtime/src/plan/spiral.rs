//! Spiral turning with a fast tool servo (Hashimoto & Yan 2025, seed 003):
//! an Archimedean spiral in X (radius) and C (spindle angle) with the fast
//! axis W carrying the height of the tool-nose centre, revolution by
//! revolution, lazily and in parallel, identical for any thread count.
//!
//! Geometry. At spindle angle θ the nose sits over the part's ray at polar
//! angle θ, its centre at radius x(θ) = r₀ − f θ / 2π. The nose's cutting
//! edge is a circle of radius ρ in the plane of that ray and the spindle
//! axis, so the centre height is the envelope of the section along the ray:
//!   w = max over u of  z(u) + sqrt(ρ² − (u − x)²),
//! found by Newton's method on the exact derivatives (`envelope::piece_max`),
//! within the reach ρ·sin(steepest slope) of x. The surface the planner
//! follows is the tool trajectory: for lens arrays, each lenslet continued
//! past its rim up to the settling offset h above the land (eqs 6–7), the
//! land itself at h, so the servo has settled before the cut begins.
//!
//! A measured edge (`machine::edge`). The tool's edge lies in its XZ
//! plane, which at spindle angle θ is the plane of the ray and the
//! spindle axis, +X along the ray outwards; so the ray's section meets the
//! edge, and the centre height is the same envelope with the edge's depth
//! L(d) below its centre (`Nose::lift`) for the circle's sqrt(ρ² − d²):
//!   w = max over u of  z(u) + L(u − x).
//! On a smooth section the edge touches where the slope along the ray,
//! ∂z/∂u, is the edge's own: at the angle θ = atan(∂z/∂u) from the
//! tool's axis (positive towards +X, to within tan(θ − φ) = ρ′/ρ), so
//! the edge angle is set by the radial slope alone. A slope across the
//! ray (the surface rising in the cutting direction: a tilted or off-axis
//! surface, a lenslet off the axis) does not move that point: the edge is
//! a curve in the ray's plane and is swept through that plane, so the
//! section it leaves there is the edge itself, wherever the surface goes
//! next (its rake and clearance faces are the tool's `clearance`
//! check's). `Planner::edged` starts from the circle's contact.
//!
//! Sampling. X and C move together linearly in the program, which is the
//! Archimedean spiral itself, so only W needs sampling: from seeds a fixed
//! arc apart, each interval is halved until the W midpoint lies within the
//! chord tolerance of the chord in (C, W).
//!
//! Speed. Constant spindle speed, or constant surface speed with a cap.
//! Each point's time follows from the speed at its radius; the fast axis's
//! acceleration is the second divided difference of W in time, checked
//! against the machine's limit.

use std::ops::ControlFlow;

use crate::machine::edge::{EdgeProfile, Nose};
use crate::plan::chords::{self, Band, ChordPlacement};
use crate::plan::envelope;
use crate::surface::ir::SurfaceFn;
use crate::surface::{Profile, ProfilePoint};

/// How fast the spindle turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpindleSpeed {
    /// Constant (rad/s).
    Constant(f64),
    /// Constant surface speed (mm/s) at the tool, capped (rad/s).
    SurfaceSpeed { speed: f64, max: f64 },
}

impl SpindleSpeed {
    /// The speed as the job states it: the spindle speed (rad/s) of a
    /// constant speed, the surface speed (mm/s) of a constant surface
    /// speed.
    pub fn stated(self) -> f64 {
        match self {
            SpindleSpeed::Constant(w) => w,
            SpindleSpeed::SurfaceSpeed { speed, .. } => speed,
        }
    }

    /// Spindle speed (rad/s) with the tool at radius `r` (mm).
    pub fn at(self, r: f64) -> f64 {
        match self {
            SpindleSpeed::Constant(w) => w,
            SpindleSpeed::SurfaceSpeed { speed, max } => {
                if r * max <= speed {
                    max
                } else {
                    speed / r
                }
            }
        }
    }
}

/// A fast-tool-servo spiral, from `start_radius` in to `end_radius` (at
/// or past the axis: 0 or negative, the nose centre beyond it).
#[derive(Clone, Debug, PartialEq)]
pub struct FtsSpiral {
    /// Radial feed per revolution (mm).
    pub feed_per_rev: f64,
    pub speed: SpindleSpeed,
    /// The path's tolerance T (mm); W's chords in (C, W) take
    /// `optimise::UNOPTIMISED_CHORD_SHARE` of it, blending the rest.
    pub chord_tolerance: f64,
    /// Largest arc (mm) between seeds; features shorter than this along
    /// the spiral may be missed by the sampling.
    pub seed_arc: f64,
    /// The servo's data period (s): no two points closer in time. Where
    /// the trajectory has a corner (in the air, at the settling plateau)
    /// the chord tolerance gives way to it.
    pub min_interval: f64,
    pub start_radius: f64,
    pub end_radius: f64,
    /// Where the points sit across the curve of W (`plan::chords`): each
    /// point's W moved by the sags of the chords it joins, measured at the
    /// chords' midpoints as the sampler splits them.
    pub chords: ChordPlacement,
}

impl FtsSpiral {
    /// The cutting time (s) of the whole spiral, in closed form: the angle
    /// turned is 2π/feed per mm of radius, at the speed `speed.at(r)`, so
    /// t = (2π / feed) ∫ dr / ω(r) from `end_radius` to `start_radius`
    /// (r / v above the radius where the cap takes over, 1 / ω_max below
    /// it). What the header states before the points are planned; the
    /// points' own times add up to it.
    pub fn cutting_time(&self) -> f64 {
        let (a, b) = (self.end_radius.max(0.0), self.start_radius);
        if self.feed_per_rev <= 0.0 || b <= a {
            return 0.0;
        }
        // Past the axis (a negative end radius) the spindle turns as at
        // the axis: at its speed, or at the cap.
        let past_axis = (-self.end_radius).max(0.0)
            / match self.speed {
                SpindleSpeed::Constant(w) => w,
                SpindleSpeed::SurfaceSpeed { max, .. } => max,
            };
        let integral = match self.speed {
            SpindleSpeed::Constant(w) => (b - a) / w,
            SpindleSpeed::SurfaceSpeed { speed, max } => {
                let capped_below = (speed / max).clamp(a, b);
                (b * b - capped_below * capped_below) / (2.0 * speed) + (capped_below - a) / max
            }
        };
        std::f64::consts::TAU / self.feed_per_rev * (integral + past_axis)
    }
}

/// The fast axis's limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FastAxis {
    /// Travel (mm).
    pub stroke: f64,
    /// Largest acceleration (mm/s²).
    pub max_acceleration: f64,
}

/// What the planner knows of the trajectory surface beforehand.
#[derive(Clone, Debug, PartialEq)]
pub struct TrajectoryBounds {
    /// The highest the surface rises (mm): where it is this high, the nose
    /// rests there and no neighbour can lift it.
    pub z_max: f64,
    /// Its steepest slope (rad): the contact is within ρ·sin of this.
    pub max_slope: f64,
    /// Discs (centre x, y and radius, mm) outside which the surface is
    /// level at `z_max`, if known (the lenslets of an array): the spiral is
    /// sampled only where it crosses them.
    pub features: Option<Vec<(f64, f64, f64)>>,
    /// The highest level (mm) of the part itself: where the trajectory is
    /// above it (a settling plateau, a lenslet's continuation over the
    /// land) the nose cuts air. Equal to `z_max` without settling.
    pub part_top: f64,
}

/// One programmed point: tool-nose centre at radius `x` (mm), spindle angle
/// `c` (rad, counted from the start), fast-axis height `w` (mm), and the
/// time (s) since the start of the spiral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpiralPoint {
    pub x: f64,
    pub c: f64,
    pub w: f64,
    pub t: f64,
}

/// What a search over the real check found for a spiral refused for its
/// fast axis's acceleration; speeds in the job's own kind (spindle speed,
/// rad/s, or surface speed, mm/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpeedAdvice {
    /// `passes` was planned and keeps within the axis's limits; `fails`,
    /// the lowest speed tried above it, does not. `lag`: at `passes` the
    /// servo (where it has a model and is gated) lags beyond the job's
    /// following-error limit.
    Found {
        passes: f64,
        fails: f64,
        lag: Option<LagMissed>,
    },
    /// No speed tried passes; `lowest_tried` was the slowest. `budget`:
    /// the search stopped because a slower trial would have simulated the
    /// servo over more samples than it had left (rather than because the
    /// excess stopped falling with the speed).
    NotFound { lowest_tried: f64, budget: bool },
}

/// The servo's lag at the advised speed, beyond what the job accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagMissed {
    /// The largest following error there (mm) and the limit (mm).
    pub lag: f64,
    pub limit: f64,
}

/// Why a spiral cannot be planned.
#[derive(Clone, Debug, PartialEq)]
pub enum FtsError {
    /// The surface is undefined where the nose must go.
    Undefined { x: f64, c: f64 },
    /// The fast axis would travel further than its stroke.
    StrokeExceeded { range: f64, stroke: f64 },
    /// The fast axis would accelerate beyond its limit (mm/s²), the
    /// worst at `at_radius` (mm). With a check (`Planner::check`) the
    /// acceleration is the largest met before the planner stopped.
    AccelerationExceeded {
        acceleration: f64,
        max: f64,
        at_radius: f64,
    },
    /// Parameters that cannot make a spiral.
    Invalid(&'static str),
}

/// The figures of a planned spiral.
#[derive(Clone, Debug, PartialEq)]
pub struct FtsSummary {
    pub revolutions: usize,
    pub points: usize,
    /// Cutting time (s).
    pub time: f64,
    /// W range (mm): lowest and highest.
    pub w_min: f64,
    pub w_max: f64,
    /// Largest |acceleration| of W (mm/s²) and the radius where it occurs.
    pub max_acceleration: f64,
    pub max_acceleration_at: f64,
    /// The highest spindle speed (constant speed, rad/s) or surface speed
    /// (constant surface speed, mm/s) at which every point's acceleration
    /// would stay within the limit were it to scale with the square of the
    /// speed: an estimate, exact only where neither the sampling (split
    /// down to the data period at corners, where acceleration scales with
    /// the speed itself) nor the trajectory (the settling offset) changes
    /// with speed. A refusal's advice is searched instead (`SpeedAdvice`).
    pub highest_allowed_speed: f64,
    /// Highest spindle speed used (rad/s) and the surface speed (mm/s) at
    /// the outermost point.
    pub max_spindle_speed: f64,
    /// FNV-1a 64 over the bits of every point, in order: equal for any
    /// thread count.
    pub fingerprint: u64,
    /// Chords left further from the exact path than their share of the
    /// tolerance because the servo's data period stopped their splitting.
    pub chords_over_tolerance: Option<ChordShortfall>,
}

/// One revolution's points (spindle angle, nose-centre height on the
/// exact path, and the band of the chord from it to the next point: how
/// far the path lies above it, `plan::chords`) and the chords among them
/// that could not meet the chord tolerance.
pub type Revolution = (Vec<(f64, f64, Band)>, Option<ChordShortfall>);

/// Chords the sampler could not split down to the chord tolerance: two
/// points may not be closer in time than the servo's data period, and
/// between those the exact path strays further than the chords' share.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChordShortfall {
    /// How many chords.
    pub count: usize,
    /// The largest deviation (mm) of a chord's midpoint from the exact
    /// path, and the radius (mm) where it is.
    pub deviation: f64,
    pub at_radius: f64,
}

impl ChordShortfall {
    fn merge(into: &mut Option<ChordShortfall>, other: Option<ChordShortfall>) {
        match (into.as_mut(), other) {
            (_, None) => {}
            (None, Some(o)) => *into = Some(o),
            (Some(a), Some(o)) => {
                a.count += o.count;
                if o.deviation > a.deviation {
                    a.deviation = o.deviation;
                    a.at_radius = o.at_radius;
                }
            }
        }
    }
}

/// A polynomial in the radius u along one ray from the spindle axis,
/// Σ_k a_k u^k (at most `RAY_TERMS` terms): a correction's section there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaySection {
    pub a: [f64; RAY_TERMS],
    pub terms: usize,
}

/// The most terms a `RaySection` has (a radial correction of order 12 is
/// of degree 24 in the radius).
pub const RAY_TERMS: usize = 25;

impl RaySection {
    /// Its value, first and second derivatives at u (Horner's rule).
    pub fn at(&self, u: f64) -> (f64, f64, f64) {
        let (mut v, mut d, mut dd) = (0.0, 0.0, 0.0);
        for &a in self.a[..self.terms].iter().rev() {
            dd = dd * u + 2.0 * d;
            d = d * u + v;
            v = v * u + a;
        }
        (v, d, dd)
    }
}

/// What a compensated trajectory is less of, by its sections along the
/// spindle's rays: the planner asks the surface several times along each
/// ray it plans a point on, and a correction's section there is a
/// polynomial of a few terms, where the corrected surface's kernel
/// evaluates every term of the correction and its derivatives at each
/// point (a compensated spiral's planning took 40 % longer).
pub trait RayCorrection: Sync {
    /// The section along the ray (cos θ, sin θ).
    fn section(&self, cos: f64, sin: f64) -> RaySection;
}

/// The nose-centre height with the centre at radius `x` over `ray`, and
/// the contact's offset along the ray from x; `hint`, a neighbouring
/// point's offset, starts Newton's method nearer the contact. NaN height
/// (offset 0) where the trajectory is undefined near x.
fn nose_on_ray(
    ray: &Ray,
    bounds: &TrajectoryBounds,
    rho: f64,
    x: f64,
    hint: Option<f64>,
) -> (f64, f64) {
    let reach = rho * bounds.max_slope.sin() * 1.05 + 1e-9;
    let start = match hint {
        Some(h) if h != 0.0 && h.abs() < reach => x + h,
        _ => x,
    };
    let here = ray.point(start);
    if start == x && here.z >= bounds.z_max && here.dz == 0.0 {
        // Nothing within reach can rise above the highest level.
        return (here.z + rho, 0.0);
    }
    // Newton on φ′ from u = start, where the surface is already
    // evaluated; should a step leave the reach or φ not be concave
    // there (a corner of the trajectory), the bracketed search takes
    // over.
    let (mut u, mut p) = (start, here);
    for _ in 0..8 {
        let d = u - x;
        let root = (rho * rho - d * d).sqrt();
        let dphi = p.dz - d / root;
        let ddphi = p.d2z - rho * rho / (root * root * root);
        let step = -dphi / ddphi;
        let next = u + step;
        if !(ddphi < 0.0 && (next - x).abs() < reach) {
            break;
        }
        if step.abs() <= 1e-9 {
            // Converged: φ at u is exact to ~φ″·step², far below a pm.
            return (p.z + root, u - x);
        }
        u = next;
        p = ray.point(u);
    }
    let (w, at) = envelope::piece_max(ray, rho, x, x - reach, x + reach);
    if at.is_nan() {
        // A slope that is not a number (the trajectory undefined near
        // x) leaves no contact: the height is unknown here, not the
        // last guess's (which lost the nose radius).
        return (f64::NAN, 0.0);
    }
    (w, at - x)
}

/// The most halvings of [`rim_centre`]'s bracket: 2.2 ρ to a nanometre
/// takes 21 for a 0.5 mm nose, 40 for a 500 m one.
const RIM_BISECTIONS: usize = 64;

/// How many spindle angles around [`rim_start`] solves at.
const RIM_ANGLES: usize = 720;

/// The radius (mm) a spiral starts at for its rim to be cut: at every
/// spindle angle θ of the first revolution, whose nose centre lies at
/// x(θ) = r₀ − fθ/2π, the contact lies at least a feed f beyond `edge(θ)`,
/// the aperture's farthest point along the ray at θ (`None`: the ray
/// misses the aperture). Where the surface falls away outward the
/// contact lies ρ·sin(atan g) inside the nose centre, and a spiral started
/// with its centre on the edge leaves the rim beyond its contact to the
/// nose's flank (issue #29: a dome of R 10 mm under a 0.5 mm nose stood
/// 47 µm proud at its rim). A point of the rim then lies between the
/// contacts of two revolutions and is left no higher than a scallop.
/// Where the trajectory has no continuation that far (its contact is
/// undefined), that angle's contact is put on the edge instead. `None`
/// if no start puts every contact of the first revolution on a defined
/// trajectory. `feed` is per revolution (mm).
pub fn rim_start(
    surface: &dyn SurfaceFn,
    bounds: &TrajectoryBounds,
    rho: f64,
    feed: f64,
    edge: &dyn Fn(f64) -> Option<f64>,
) -> Option<f64> {
    let contact = |x: f64, c: f64| {
        let ray = Ray {
            surface,
            cos: c.cos(),
            sin: c.sin(),
            less: None,
        };
        let (w, d) = nose_on_ray(&ray, bounds, rho, x, None);
        w.is_finite().then_some(x + d)
    };
    let turn = std::f64::consts::TAU;
    let mut start = f64::NEG_INFINITY;
    for k in 0..RIM_ANGLES {
        let c = turn * k as f64 / RIM_ANGLES as f64;
        let Some(r) = edge(c) else { continue };
        let x = rim_centre(&|x| contact(x, c), r + feed, rho)
            .or_else(|| rim_centre(&|x| contact(x, c), r, rho))?;
        // The first revolution reaches angle c a fraction of a feed in.
        start = start.max(x + feed * c / turn);
    }
    // Every contact of the first revolution on the trajectory.
    let defined = (0..RIM_ANGLES).all(|k| {
        let c = turn * k as f64 / RIM_ANGLES as f64;
        contact(start - feed * c / turn, c).is_some()
    });
    (start.is_finite() && defined).then_some(start)
}

/// The least nose-centre radius (mm, to a nanometre) whose contact along
/// the ray lies at `target` or beyond, `contact(x)` being the contact's
/// radius with the centre at x (`None` where undefined, taken as beyond:
/// the answer must then be checked); searched within 1.1 ρ of the target,
/// never inside the axis.
fn rim_centre(contact: &dyn Fn(f64) -> Option<f64>, target: f64, rho: f64) -> Option<f64> {
    let (mut lo, mut hi) = ((target - 1.1 * rho).max(0.0), target + 1.1 * rho);
    let reaches = |x: f64| contact(x).is_none_or(|u| u >= target);
    if reaches(lo) {
        return None;
    }
    // Bounded: far from the axis (2^34 mm) neighbouring floats lie
    // further apart than the nanometre, and the midpoint of two of them
    // is one of them (issue #33: a part 4,300 km across looped for ever).
    for _ in 0..RIM_BISECTIONS {
        let m = 0.5 * (lo + hi);
        if hi - lo <= 1e-6 || m <= lo || m >= hi {
            break;
        }
        if reaches(m) {
            hi = m;
        } else {
            lo = m;
        }
    }
    contact(hi)
        .is_some_and(|u| u >= target - 1e-6)
        .then_some(hi)
}

/// The section of a surface along the ray at angle θ: z, dz/du, d²z/du²,
/// less a correction's section there, if any.
struct Ray<'a> {
    surface: &'a dyn SurfaceFn,
    cos: f64,
    sin: f64,
    less: Option<RaySection>,
}

impl Profile for Ray<'_> {
    fn point(&self, u: f64) -> ProfilePoint {
        let o = self.surface.eval(u * self.cos, u * self.sin);
        let (c, s) = (self.cos, self.sin);
        let p = ProfilePoint {
            z: o[0],
            dz: o[1] * c + o[2] * s,
            d2z: o[3] * c * c + 2.0 * o[4] * c * s + o[5] * s * s,
        };
        match &self.less {
            None => p,
            Some(section) => {
                let (v, d, dd) = section.at(u);
                ProfilePoint {
                    z: p.z - v,
                    dz: p.dz - d,
                    d2z: p.d2z - dd,
                }
            }
        }
    }
}

/// The planner: the spiral's geometry and how to find each point.
pub struct Planner<'a> {
    pub spiral: &'a FtsSpiral,
    pub surface: &'a (dyn SurfaceFn + Sync),
    /// A correction the trajectory is less of, taken out along each ray
    /// (`RayCorrection`); none where `surface` is the trajectory itself.
    pub less: Option<&'a dyn RayCorrection>,
    pub nose_radius: f64,
    /// The nose's measured edge, if the tool names one: each centre is
    /// then the lowest that clears the section with that edge (module
    /// doc, "A measured edge").
    pub edge: Option<&'a EdgeProfile>,
    pub bounds: TrajectoryBounds,
}

impl Planner<'_> {
    /// Number of revolutions from the start radius in to the end radius.
    pub fn revolutions(&self) -> usize {
        let s = self.spiral;
        ((s.start_radius - s.end_radius) / s.feed_per_rev)
            .ceil()
            .max(0.0) as usize
    }

    /// Total spindle angle (rad) of the spiral.
    fn total_angle(&self) -> f64 {
        let s = self.spiral;
        2.0 * std::f64::consts::PI * (s.start_radius - s.end_radius) / s.feed_per_rev
    }

    /// Tool radius at spindle angle c.
    fn radius(&self, c: f64) -> f64 {
        self.spiral.start_radius - self.spiral.feed_per_rev * c / (2.0 * std::f64::consts::PI)
    }

    /// The least radius (mm) of the first revolution's contacts, over
    /// [`RIM_ANGLES`] spindle angles: where a spiral started inside the
    /// aperture (a partial cut) stops cutting to the design, the band
    /// beyond it left to its nose's flank. The start radius where no
    /// contact is defined.
    pub fn first_contacts_least(&self) -> f64 {
        let turn = std::f64::consts::TAU;
        (0..RIM_ANGLES)
            .map(|k| {
                let c = turn * k as f64 / RIM_ANGLES as f64;
                let (w, d) = self.centre_near(c, None);
                if w.is_finite() {
                    self.radius(c) + d
                } else {
                    self.spiral.start_radius
                }
            })
            .fold(self.spiral.start_radius, f64::min)
    }

    /// The nose-centre height at spindle angle c (exact, see module doc).
    pub fn centre(&self, c: f64) -> f64 {
        self.centre_near(c, None).0
    }

    /// The nose-centre height at spindle angle c and the contact's offset
    /// along the ray from the nose's radius; `hint`, a neighbouring point's
    /// offset, starts Newton's method nearer the contact than the nose's
    /// own radius does. The height is the same to far below a picometre
    /// from any start (seed 003's programs came out byte for byte the same).
    fn centre_near(&self, c: f64, hint: Option<f64>) -> (f64, f64) {
        let (w, d) = self.circle_near(c, hint);
        match self.edge {
            Some(edge) if w.is_finite() => self.edged(c, edge, w, d),
            _ => (w, d),
        }
    }

    /// The nose-centre height at spindle angle c were the nose a circle
    /// of radius ρ, and the contact's offset along the ray (`centre_near`).
    fn circle_near(&self, c: f64, hint: Option<f64>) -> (f64, f64) {
        let x = self.radius(c);
        let (cos, sin) = (c.cos(), c.sin());
        let ray = Ray {
            surface: self.surface,
            cos,
            sin,
            less: self.less.map(|l| l.section(cos, sin)),
        };
        nose_on_ray(&ray, &self.bounds, self.nose_radius, x, hint)
    }

    /// The nose-centre height at spindle angle c with the measured
    /// `edge`, from the circle's height `w_circle` and contact offset `d`
    /// (`envelope::edged_max` along the ray). The contact's offset is
    /// returned as the circle's is.
    fn edged(&self, c: f64, edge: &EdgeProfile, w_circle: f64, d: f64) -> (f64, f64) {
        let x = self.radius(c);
        let nose = Nose {
            radius: self.nose_radius,
            edge: Some(edge),
        };
        let (cos, sin) = (c.cos(), c.sin());
        let ray = Ray {
            surface: self.surface,
            cos,
            sin,
            less: self.less.map(|l| l.section(cos, sin)),
        };
        match envelope::edged_max(&ray, &nose, x, x + d) {
            Some((w, u)) => (w, u - x),
            // The edge does not reach the circle's contact (it reaches
            // past R·sin of the steepest slope everywhere, so never): no
            // height rather than the circle's.
            None => {
                let _ = w_circle;
                (f64::NAN, d)
            }
        }
    }

    /// Points of revolution `k` (its first point, not its last: the next
    /// revolution starts there), sampled to the chord tolerance, and the
    /// chords that could not meet it.
    pub fn revolution(&self, k: usize) -> Revolution {
        let two_pi = 2.0 * std::f64::consts::PI;
        let (c0, c1) = (
            two_pi * k as f64,
            (two_pi * (k + 1) as f64).min(self.total_angle()),
        );
        if c1 <= c0 {
            return (Vec::new(), None);
        }
        let mut out = Vec::new();
        let mut over = None;
        match self.feature_spans(c0, c1) {
            None => self.sample(c0, c1, &mut out, &mut over),
            Some(spans) => {
                // Level between the spans: their ends are enough.
                let level = self.bounds.z_max + self.nose_radius;
                let mut at = c0;
                for (a, b) in spans {
                    if a > at {
                        out.push((at, level, Band::default()));
                    }
                    self.sample(a.max(at), b, &mut out, &mut over);
                    at = b;
                }
                if at < c1 {
                    out.push((at, level, Band::default()));
                }
            }
        }
        // A point repeated: the chord from it is the later one's.
        out.dedup_by(|b, a| {
            let same = b.0 == a.0;
            if same {
                a.2 = a.2.union(b.2);
            }
            same
        });
        // Where W stays level (the land, or the settling plateau), the
        // spiral between the ends of the level stretch is one move, its
        // band the union of the chords it replaces.
        let mut kept: Vec<(f64, f64, Band)> = Vec::with_capacity(out.len() / 4 + 2);
        for (i, p) in out.iter().enumerate() {
            let level_before = kept.last().is_some_and(|q| q.1 == p.1);
            let level_after = out.get(i + 1).is_some_and(|q| q.1 == p.1);
            if !(level_before && level_after) {
                kept.push(*p);
            } else if let Some(q) = kept.last_mut() {
                q.2 = q.2.union(p.2);
            }
        }
        if self.spiral.chords.straddles() {
            kept = self.straddled(&kept, c1);
        }
        (kept, over)
    }

    /// The revolution's points `pts`, up to the next revolution's first at
    /// `c1`, moved in W to straddle the exact path (`plan::chords`): each
    /// chord within half the chords' share either way, chords split where
    /// their neighbours bend the other way (down to the servo's data
    /// period). Its first point, which the revolution before shares, and
    /// the next revolution's first stay on the path, so every revolution
    /// is placed on its own, in parallel.
    fn straddled(&self, pts: &[(f64, f64, Band)], c1: f64) -> Vec<(f64, f64, Band)> {
        let share = self.spiral.chord_tolerance
            * crate::plan::optimise::UNOPTIMISED_CHORD_SHARE
            * self.spiral.chords.sag_factor();
        let knot = |c: f64, w: f64| chords::Knot { s: c, u: c, z: w };
        let mut knots: Vec<chords::Knot> = pts.iter().map(|p| knot(p.0, p.1)).collect();
        let mut hint = None;
        let mut exact = |c: f64| {
            let (w, h) = self.centre_near(c, hint);
            hint = Some(h);
            (c, w)
        };
        let last = knots.last().map(|k| k.s);
        if last.is_some_and(|l| c1 > l) {
            knots.push(knot(c1, exact(c1).1));
        }
        let min_interval = self.spiral.min_interval;
        let speed = self.spiral.speed;
        // Not below the servo's data period, nor where the nose cuts air
        // (both ends above the part's top: a settling plateau's corners).
        let air = self.bounds.part_top + self.nose_radius - 1e-9;
        let can_split = |a: &chords::Knot, b: &chords::Knot| {
            b.s - a.s > 2.0 * speed.at(self.radius(b.s)) * min_interval && a.z.min(b.z) < air
        };
        let (mut placed, _) = chords::straddle(
            &knots,
            (Some(0.0), Some(0.0)),
            0.5 * share,
            &mut exact,
            &can_split,
        );
        if last.is_some_and(|l| c1 > l) {
            placed.pop();
        }
        placed
            .into_iter()
            .map(|k| (k.s, k.z, Band::default()))
            .collect()
    }

    /// Samples [c0, c1) into `out`: seeds a seed arc apart, each interval
    /// halved until its W midpoint is on the chord (or down to the servo's
    /// data period).
    fn sample(
        &self,
        c0: f64,
        c1: f64,
        out: &mut Vec<(f64, f64, Band)>,
        over: &mut Option<ChordShortfall>,
    ) {
        let tol = self.spiral.chord_tolerance
            * crate::plan::optimise::UNOPTIMISED_CHORD_SHARE
            * self.spiral.chords.sag_factor();
        let r = self.radius(c0).max(self.spiral.seed_arc);
        let seeds = (((c1 - c0) * r / self.spiral.seed_arc).ceil() as usize).max(2);
        // The contact's offset along the ray at the last point computed:
        // each solve starts from its neighbour's.
        let (w0, mut hint) = self.centre_near(c0, None);
        let mut prev = (c0, w0);
        for i in 1..=seeds {
            let c = c0 + (c1 - c0) * i as f64 / seeds as f64;
            let (w, h) = self.centre_near(c, Some(hint));
            hint = h;
            let next = (c, w);
            // Halve (prev, next) until every midpoint is on its chord, or
            // the interval is down to the servo's data period.
            let shortest = self.spiral.speed.at(self.radius(c)) * self.spiral.min_interval;
            let mut stack = vec![(next, 0u32)];
            let mut left = prev;
            while let Some((right, depth)) = stack.pop() {
                let m = 0.5 * (left.0 + right.0);
                let (wm, h) = self.centre_near(m, Some(hint));
                hint = h;
                let splittable = depth < 40 && right.0 - left.0 > 2.0 * shortest;
                let deviation = (wm - 0.5 * (left.1 + right.1)).abs();
                if splittable && deviation > tol {
                    stack.push((right, depth + 1));
                    stack.push(((m, wm), depth + 1));
                } else {
                    // Only where the nose reaches the part: a chord wholly
                    // above its top (a settling plateau, a lenslet's
                    // continuation over the land) cuts air.
                    let low = left.1.min(right.1).min(wm);
                    if deviation > tol && low < self.bounds.part_top + self.nose_radius - 1e-9 {
                        ChordShortfall::merge(
                            over,
                            Some(ChordShortfall {
                                count: 1,
                                deviation,
                                at_radius: self.radius(m),
                            }),
                        );
                    }
                    let band = self.chord_band(left, (m, wm), right, &mut hint);
                    out.push((left.0, left.1, band));
                    left = right;
                }
            }
            prev = next;
        }
    }

    /// The band of the chord from `left` to `right` (`plan::chords`), its
    /// middle `mid` on the exact path: from the path's height above the
    /// chord there and at its quarters (not measured, and not needed, with
    /// the points on the path).
    fn chord_band(
        &self,
        left: (f64, f64),
        mid: (f64, f64),
        right: (f64, f64),
        hint: &mut f64,
    ) -> Band {
        // Straddling measures its chords itself, once the revolution is
        // sampled (`straddled`).
        if matches!(
            self.spiral.chords,
            ChordPlacement::OnPath | ChordPlacement::Straddle | ChordPlacement::StraddleLong
        ) {
            return Band::default();
        }
        let mut above = |t: f64| {
            let (w, h) = self.centre_near(left.0 + t * (right.0 - left.0), Some(*hint));
            *hint = h;
            w - (left.1 + t * (right.1 - left.1))
        };
        let (quarter, three) = (above(0.25), above(0.75));
        Band::from_quarters([quarter, mid.1 - 0.5 * (left.1 + right.1), three])
    }

    /// The spans of spindle angle in [c0, c1) where the spiral passes over
    /// a feature disc (grown by the nose's reach and a seed arc), merged and
    /// in order; `None` when the features are not known.
    fn feature_spans(&self, c0: f64, c1: f64) -> Option<Vec<(f64, f64)>> {
        let features = self.bounds.features.as_ref()?;
        let two_pi = 2.0 * std::f64::consts::PI;
        let (r_out, r_in) = (self.radius(c0), self.radius(c1));
        let grow = self.nose_radius * self.bounds.max_slope.sin() + self.spiral.seed_arc;
        let mut spans: Vec<(f64, f64)> = Vec::new();
        for &(fx, fy, fr) in features {
            let d = fx.hypot(fy);
            let rr = fr + grow;
            if d - rr > r_out || d + rr < r_in {
                continue;
            }
            // Half-width in angle at the radius nearest the disc centre.
            let r = d.clamp(r_in, r_out);
            if d <= rr || r <= rr {
                // The disc is all round the axis at these radii: the whole
                // revolution is over it. (As centre ± π its two pieces in
                // [c0, c1) need not meet to the bit, and a level point
                // between them was a step in W.)
                spans.push((c0, c1));
                continue;
            }
            let half = {
                let cos = ((r * r + d * d - rr * rr) / (2.0 * r * d)).clamp(-1.0, 1.0);
                cos.acos()
            };
            let centre = fy.atan2(fx);
            // Every copy of [centre − half, centre + half] (mod 2π) in range.
            let base = ((c0 - centre - half) / two_pi).floor();
            let mut n = base;
            loop {
                let (a, b) = (centre - half + n * two_pi, centre + half + n * two_pi);
                if a >= c1 {
                    break;
                }
                if b > c0 {
                    spans.push((a.max(c0), b.min(c1)));
                }
                n += 1.0;
            }
        }
        spans.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut merged: Vec<(f64, f64)> = Vec::with_capacity(spans.len());
        for (a, b) in spans {
            match merged.last_mut() {
                Some(last) if a <= last.1 => last.1 = last.1.max(b),
                _ => merged.push((a, b)),
            }
        }
        Some(merged)
    }

    /// Plans the spiral, handing each revolution's points in order to
    /// `sink`; revolutions are computed `batch` at a time in parallel.
    pub fn plan(
        &self,
        fast_axis: &FastAxis,
        sink: impl FnMut(&[SpiralPoint]) + Send,
    ) -> Result<FtsSummary, FtsError> {
        self.run(fast_axis, false, sink)
    }

    /// Plans the spiral as `plan` does, keeping no point, to see whether
    /// it passes the fast axis's limits: the same pass or fail as `plan`, but
    /// stopped at the first batch of revolutions that accelerates beyond
    /// the limit (a refusal costs only the revolutions up to it).
    pub fn check(&self, fast_axis: &FastAxis) -> Result<FtsSummary, FtsError> {
        self.run(fast_axis, true, |_| {})
    }

    /// `check`, handing each revolution's points in order to `sink` as
    /// `plan` does (up to the batch where a refusal stops it).
    pub fn check_with(
        &self,
        fast_axis: &FastAxis,
        sink: impl FnMut(&[SpiralPoint]) + Send,
    ) -> Result<FtsSummary, FtsError> {
        self.run(fast_axis, true, sink)
    }

    fn run(
        &self,
        fast_axis: &FastAxis,
        stop_over_limit: bool,
        mut sink: impl FnMut(&[SpiralPoint]) + Send,
    ) -> Result<FtsSummary, FtsError> {
        let s = self.spiral;
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(s.feed_per_rev) && ok(s.chord_tolerance) && ok(s.seed_arc) && ok(self.nose_radius))
        {
            return Err(FtsError::Invalid(
                "feed, tolerance, seed arc and nose radius must be positive",
            ));
        }
        // The spiral may end past the axis (a negative radius: the nose
        // centre beyond it, where the surface slopes at the axis).
        if !(s.start_radius.is_finite()
            && s.end_radius > -s.start_radius
            && s.start_radius > s.end_radius)
        {
            return Err(FtsError::Invalid(
                "the spiral must run inwards from its start radius",
            ));
        }
        let revs = self.revolutions();
        let mut summary = FtsSummary {
            revolutions: revs,
            points: 0,
            time: 0.0,
            w_min: f64::INFINITY,
            w_max: f64::NEG_INFINITY,
            max_acceleration: 0.0,
            max_acceleration_at: s.start_radius,
            highest_allowed_speed: f64::INFINITY,
            max_spindle_speed: 0.0,
            fingerprint: 0xcbf2_9ce4_8422_2325,
            chords_over_tolerance: None,
        };
        let batch = 64;
        // The last two points, for the acceleration across revolutions.
        let mut last: Vec<SpiralPoint> = Vec::with_capacity(2);
        let mut buffer: Vec<SpiralPoint> = Vec::new();
        let mut undefined = None;
        let total = self.total_angle();
        let make = |j: usize| {
            if j == revs {
                // The end point of the spiral.
                (vec![(total, self.centre(total), Band::default())], None)
            } else {
                self.revolution(j)
            }
        };
        let mut j = 0;
        // The band of the chord into the next point, from the revolution
        // before (`plan::chords`).
        let mut band_before = None;
        // The least and greatest nonzero |acceleration| (`account`).
        let mut nonzero = (f64::INFINITY, 0.0);
        let take = |(pts, over): Revolution| {
            ChordShortfall::merge(&mut summary.chords_over_tolerance, over);
            buffer.clear();
            for (c, w, band) in pts {
                // The spiral's end point starts no chord.
                let after = (j < revs).then_some(band);
                let w = w + s.chords.offset(band_before, after);
                band_before = after;
                let x = self.radius(c);
                if !(w.is_finite() && x.is_finite()) {
                    undefined = Some(FtsError::Undefined { x, c });
                    return ControlFlow::Break(());
                }
                let t = match last.last() {
                    None => 0.0,
                    Some(p) => {
                        let spin = s.speed.at(0.5 * (p.x + x));
                        p.t + (c - p.c) / spin
                    }
                };
                let point = SpiralPoint { x, c, w, t };
                let spin = s.speed.at(point.x);
                Self::account(&mut summary, &mut nonzero, &last, point, spin);
                if last.len() == 2 {
                    last.remove(0);
                }
                last.push(point);
                buffer.push(point);
            }
            sink(&buffer);
            j += 1;
            // A check stops after the batch of revolutions that went over.
            let batch_done = j % batch == 0 || j > revs;
            if stop_over_limit
                && batch_done
                && summary.max_acceleration > fast_axis.max_acceleration
            {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        };
        crate::plan::stream::in_order(revs + 1, batch, make, take);
        if let Some(e) = undefined {
            return Err(e);
        }
        summary.time = last.last().map_or(0.0, |p| p.t);
        summary.highest_allowed_speed =
            highest_allowed_speed(s.speed.stated(), fast_axis.max_acceleration, nonzero);
        let range = summary.w_max - summary.w_min;
        if range > fast_axis.stroke {
            return Err(FtsError::StrokeExceeded {
                range,
                stroke: fast_axis.stroke,
            });
        }
        if summary.max_acceleration > fast_axis.max_acceleration {
            return Err(FtsError::AccelerationExceeded {
                acceleration: summary.max_acceleration,
                max: fast_axis.max_acceleration,
                at_radius: summary.max_acceleration_at,
            });
        }
        Ok(summary)
    }

    /// Folds one point into the summary: counts, W range, spindle speed,
    /// acceleration (second divided difference with the two before it) and
    /// the least and greatest nonzero |acceleration| (`nonzero`), from which
    /// `highest_allowed_speed` follows.
    fn account(
        sum: &mut FtsSummary,
        nonzero: &mut (f64, f64),
        last: &[SpiralPoint],
        p: SpiralPoint,
        spin: f64,
    ) {
        sum.points += 1;
        sum.w_min = sum.w_min.min(p.w);
        sum.w_max = sum.w_max.max(p.w);
        sum.max_spindle_speed = sum.max_spindle_speed.max(spin);
        for v in [p.x, p.c, p.w] {
            for b in v.to_bits().to_le_bytes() {
                sum.fingerprint ^= u64::from(b);
                sum.fingerprint = sum.fingerprint.wrapping_mul(0x0100_0000_01b3);
            }
        }
        if let [a, b] = last {
            let (d1, d2) = (b.t - a.t, p.t - b.t);
            if d1 > 0.0 && d2 > 0.0 {
                let acc = 2.0 * ((p.w - b.w) / d2 - (b.w - a.w) / d1) / (d1 + d2);
                if acc.abs() > sum.max_acceleration {
                    sum.max_acceleration = acc.abs();
                    sum.max_acceleration_at = b.x;
                }
                if acc != 0.0 && !acc.is_nan() {
                    let (low, high) = nonzero;
                    *low = low.min(acc.abs());
                    *high = high.max(acc.abs());
                }
            }
        }
    }
}

/// The highest spindle speed (or surface speed) at which every point's
/// acceleration stays within `limit`: acceleration scales with the square
/// of the speed, so `now` times sqrt(limit / |acc|), least over the points
/// (a NaN passed over). Each step (a division, a square root and a product,
/// each rounded once) is monotone in |acc|, so that least value is the one
/// at the least or the greatest nonzero |acc| (`nonzero`), bit for bit: two
/// evaluations, not one a point.
fn highest_allowed_speed(now: f64, limit: f64, nonzero: (f64, f64)) -> f64 {
    let (low, high) = nonzero;
    if low > high {
        return f64::INFINITY;
    }
    let at = |acc: f64| now * (limit / acc).sqrt();
    f64::INFINITY.min(at(low)).min(at(high))
}

/// The settling offset h (mm) for a lenslet whose height along its radius
/// is `lenslet(u)` (rim at `rim_radius`): how far the lenslet's own surface,
/// continued past its rim, rises above the rim while the tool covers
/// d_traj = v·T_s (eqs 6–7 for a sphere; any lenslet here).
pub fn settling_offset(
    lenslet: impl Fn(f64) -> f64,
    rim_radius: f64,
    surface_speed: f64,
    settling_time: f64,
) -> f64 {
    let d_traj = surface_speed * settling_time;
    lenslet(rim_radius + d_traj) - lenslet(rim_radius)
}

#[cfg(test)]
mod tests;
