//! Fast-tool-servo following: the fast axis simulated as the machine's
//! second-order servo (`servo.rs`), driven at its data rate by the
//! commanded positions (each program move linear in time between its
//! points, as inverse-time feed runs it; the command held over each data
//! period), and its following error — actual minus commanded — measured
//! along the spiral. Errors are gathered per lenslet (the discs the
//! planner knows as features): the largest, the RMS, and the waviness,
//! the RMS slope of the error along the cut (the error's share of the
//! surface's Sdq, seed 003).
//!
//! Points arrive in spiral order, in chunks, as the planner hands them
//! over: the simulation keeps only the servo's state (and, led, the few
//! points of the next data period).
//!
//! Led by the program ([`FollowingSimulation::extend_toward`]): the
//! commands are the pre-compensated ones a program writes for a servo with
//! no feed-forward (`machine::lead`), each with the point of the path it
//! is meant to put the servo at; the servo runs on the commands unled and
//! its error is measured from the path. The servo's acceleration, the
//! change of its velocity over each data period, is measured too: the
//! lead must not drive it beyond its limit.
//!
//! Led ([`FollowingSimulation::led`]): the servo is driven not by the
//! commanded position r(t) itself but by its inverse model applied to it,
//! u = r + (2ζ/ωn) ṙ + r̈/ωn² (velocity and acceleration feed-forward), so
//! that G(s) u = r. The command held over each data period is u weighted
//! by the triangle of two periods' width centred half a period ahead (the
//! half-period lead that undoes the hold's delay): the held commands then
//! keep u's area and its first moment wherever r bends (r is linear in
//! time between points, so its velocity steps at them and r̈ is impulses
//! there), and the servo's response to them differs from r only to second
//! order in the period. Worked out exactly on the commanded path: the
//! triangle's mean of r piece by piece, of ṙ and r̈ by parts (the
//! triangle's slopes and corners on r). The error is still the servo's
//! position minus r(t).

use crate::machine::servo::SecondOrderServo;
use crate::plan::spiral::SpiralPoint;
use nalgebra::{Matrix2, Vector2};

/// What the servo does over one lenslet.
#[derive(Clone, Debug, PartialEq)]
pub struct LensletFollowing {
    /// The lenslet's centre (mm, part coordinates) and its distance from
    /// the spindle axis.
    pub centre: (f64, f64),
    pub radius: f64,
    /// Servo samples over the lenslet.
    pub samples: usize,
    /// Largest |following error| and its RMS (mm).
    pub max_error: f64,
    pub rms_error: f64,
    /// RMS slope of the following error along the cut (rad).
    pub waviness: f64,
}

/// What the servo does over the whole spiral.
#[derive(Clone, Debug, PartialEq)]
pub struct Following {
    pub samples: usize,
    /// Largest |following error| (mm) and the radius (mm) where it is.
    pub max_error: f64,
    pub max_error_at: f64,
    pub lenslets: Vec<LensletFollowing>,
    /// The servo's largest acceleration (mm/s²; its velocity's change
    /// over a data period) and the radius (mm) where it is.
    pub max_acceleration: f64,
    pub max_acceleration_at: f64,
    /// Every sample's error where the nose cuts (`cutting_below`)
    /// gathered in bins of radius, for plots.
    pub by_radius: RadialBins,
}

/// The following error of every sample gathered in a fixed number of
/// bins of radius: per bin, the count and the least and largest error, so
/// a plot of them keeps every peak however many samples fall in a bin,
/// and memory stays fixed however long the spiral.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialBins {
    /// The radii (mm) the bins cover, `from < to`, in equal widths.
    pub from: f64,
    pub to: f64,
    pub bins: Vec<ErrorBin>,
}

/// One bin of [`RadialBins`]: samples, least and largest error (mm); the
/// extremes are ±infinity while it is empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorBin {
    pub samples: u64,
    pub min: f64,
    pub max: f64,
}

impl RadialBins {
    /// `count` (at least 1) empty bins over the radii `from..to` (mm);
    /// an empty or reversed range is taken as one 1 µm wide.
    pub fn new(from: f64, to: f64, count: usize) -> RadialBins {
        let (from, to) = if to > from && (to - from).is_finite() {
            (from, to)
        } else {
            (from, from + 1e-3)
        };
        RadialBins {
            from,
            to,
            bins: vec![
                ErrorBin {
                    samples: 0,
                    min: f64::INFINITY,
                    max: f64::NEG_INFINITY,
                };
                count.max(1)
            ],
        }
    }

    /// The bin of radius `r` (mm); radii beyond the range fall in the end
    /// bins.
    pub fn index(&self, r: f64) -> usize {
        let n = self.bins.len();
        let t = (r - self.from) / (self.to - self.from) * n as f64;
        if t.is_nan() {
            return 0;
        }
        (t.floor().max(0.0) as usize).min(n - 1)
    }

    /// The radii (mm) bin `i` covers.
    pub fn span(&self, i: usize) -> (f64, f64) {
        let w = (self.to - self.from) / self.bins.len() as f64;
        (self.from + i as f64 * w, self.from + (i + 1) as f64 * w)
    }

    /// Counts an error `e` (mm) at radius `r` (mm).
    pub fn add(&mut self, r: f64, e: f64) {
        self.add_many(self.index(r), 1, e, e);
    }

    /// Counts `n` errors from `min` to `max` (mm) in bin `i`.
    pub fn add_many(&mut self, i: usize, n: u64, min: f64, max: f64) {
        let b = &mut self.bins[i];
        b.samples += n;
        b.min = b.min.min(min);
        b.max = b.max.max(max);
    }
}

/// The lenslets by cell of the grid that finds the one under the tool: a
/// hash map keyed by the cell's indices, hashed by a multiply and a
/// rotate (a few dozen cells; looked up once per move).
type CellMap =
    std::collections::HashMap<(i64, i64), Vec<usize>, std::hash::BuildHasherDefault<CellHash>>;

/// [`CellMap`]'s hash: each word mixed in by a multiply and a rotate.
#[derive(Default)]
struct CellHash(u64);

impl std::hash::Hasher for CellHash {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, word: u64) {
        self.0 = (self.0 ^ word)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(29);
    }
    fn write_i64(&mut self, word: i64) {
        self.write_u64(word as u64);
    }
}

/// A new largest following error `error` (mm), at `radius` (mm).
#[cold]
#[inline(never)]
fn new_peak(error: f64, radius: f64) -> (f64, f64) {
    (error.abs(), radius)
}

/// One move's ends and rates.
struct Move<'a> {
    q: SpiralPoint,
    p: SpiralPoint,
    /// The path's W (mm) at `q` and `p`: the commands' own, or where the
    /// program's lead means them to put the servo.
    aims: (f64, f64),
    /// `p` and the points after it known so far (led: up to a data period
    /// past `p`, or the end of the spiral).
    from_p: &'a [SpiralPoint],
    /// 1 / the move's duration (1/s).
    per_second: f64,
    /// The tool's travel over the part in one sample (mm).
    step: f64,
}

/// What one move's samples add: to its lenslet, and to its one bin of
/// radius (count, least and largest error).
struct MoveAcc {
    samples: usize,
    max: f64,
    sum2: f64,
    slope2: f64,
    bin: (u64, f64, f64),
}

struct Acc {
    samples: usize,
    max: f64,
    sum2: f64,
    slope2: f64,
}

/// The servo, run as points arrive.
pub struct FollowingSimulation {
    phi: Matrix2<f64>,
    gamma: Vector2<f64>,
    dt: f64,
    state: Option<Vector2<f64>>,
    /// The time (s) of the first sample, the next sample's and its index.
    t0: f64,
    next: f64,
    k: u64,
    last: Option<SpiralPoint>,
    /// The path's W at `last` (its own W unless led by the program).
    last_aim: f64,
    /// Led: the feed-forward gains (2ζ/ωn in s, 1/ωn² in s²), and the
    /// points received whose moves wait for the path a data period on.
    lead: Option<(f64, f64)>,
    ahead: Vec<SpiralPoint>,
    /// The point before the last one run (led: the path a period back).
    prior: Option<SpiralPoint>,
    /// The command (mm) at and above which the nose cuts air
    /// (`cutting_below`; infinite: it cuts everywhere).
    air: f64,
    /// The last point in part coordinates (x cos c, x sin c; mm), worked
    /// out once per point.
    last_xy: (f64, f64),
    last_error: Option<f64>,
    features: Vec<(f64, f64, f64)>,
    /// Features by cell of a uniform grid (cell size the largest
    /// diameter), for finding the lenslet under the tool.
    cell: f64,
    grid: CellMap,
    acc: Vec<Acc>,
    max_error: f64,
    max_error_at: f64,
    max_acceleration: f64,
    max_acceleration_at: f64,
    by_radius: RadialBins,
}

impl FollowingSimulation {
    /// A servo sampled at `data_rate_hz` over lenslets `features` (centre
    /// x, y and radius, mm); every sample's error is also gathered in
    /// `by_radius`. `None` for an invalid servo or rate.
    pub fn new(
        servo: &SecondOrderServo,
        data_rate_hz: f64,
        features: &[(f64, f64, f64)],
        by_radius: RadialBins,
    ) -> Option<FollowingSimulation> {
        let dt = 1.0 / data_rate_hz;
        let (phi, gamma) = servo.zero_order_hold_step(dt)?;
        let cell = features
            .iter()
            .map(|f| 2.0 * f.2)
            .fold(0.0, f64::max)
            .max(1e-3);
        let mut grid = CellMap::default();
        for (i, f) in features.iter().enumerate() {
            let lo = (
                ((f.0 - f.2) / cell).floor() as i64,
                ((f.1 - f.2) / cell).floor() as i64,
            );
            let hi = (
                ((f.0 + f.2) / cell).floor() as i64,
                ((f.1 + f.2) / cell).floor() as i64,
            );
            for gx in lo.0..=hi.0 {
                for gy in lo.1..=hi.1 {
                    grid.entry((gx, gy)).or_default().push(i);
                }
            }
        }
        Some(FollowingSimulation {
            phi,
            gamma,
            dt,
            state: None,
            t0: 0.0,
            next: 0.0,
            k: 0,
            last: None,
            last_aim: 0.0,
            lead: None,
            ahead: Vec::new(),
            prior: None,
            air: f64::INFINITY,
            last_xy: (0.0, 0.0),
            last_error: None,
            features: features.to_vec(),
            cell,
            grid,
            acc: features
                .iter()
                .map(|_| Acc {
                    samples: 0,
                    max: 0.0,
                    sum2: 0.0,
                    slope2: 0.0,
                })
                .collect(),
            max_error: 0.0,
            max_error_at: f64::NAN,
            max_acceleration: 0.0,
            max_acceleration_at: f64::NAN,
            by_radius,
        })
    }

    /// The same simulation with the servo led by its inverse model (see
    /// the module's doc): feed-forward of the commanded velocity and
    /// acceleration, so its output tracks the commanded path.
    pub fn led(mut self, servo: &SecondOrderServo) -> FollowingSimulation {
        let wn = 2.0 * std::f64::consts::PI * servo.natural_frequency_hz;
        self.lead = Some((2.0 * servo.damping / wn, 1.0 / (wn * wn)));
        self
    }

    /// The same simulation with the error gathered only where the nose
    /// cuts: a move whose ends both command `level` (mm) or higher (a
    /// settling plateau, a lenslet's continuation over the land: the
    /// trajectory above the part's top) cuts air, and the servo's error
    /// there leaves no mark. The servo still runs through it.
    pub fn cutting_below(mut self, level: f64) -> FollowingSimulation {
        self.air = level;
        self
    }

    fn lenslet_at(&self, x: f64, y: f64) -> Option<usize> {
        let key = (
            (x / self.cell).floor() as i64,
            (y / self.cell).floor() as i64,
        );
        self.grid.get(&key)?.iter().copied().find(|&i| {
            let f = self.features[i];
            (x - f.0).powi(2) + (y - f.1).powi(2) <= f.2 * f.2
        })
    }

    /// Runs the servo over the next points of the spiral.
    pub fn extend(&mut self, points: &[SpiralPoint]) {
        for &p in points {
            if self.lead.is_none() {
                self.run_to(p, p.w, &[p]);
                continue;
            }
            self.ahead.push(p);
            self.run_known(false);
        }
    }

    /// Runs the servo, unled, over the next `commands` as a program that
    /// leads it itself prints them (`machine::lead`), `aims[i]` the W of
    /// the path `commands[i]` is meant to put it at: the error is the
    /// servo's position minus the path. (A simulation led by its
    /// controller, [`led`](Self::led), takes the commands as the path.)
    pub fn extend_toward(&mut self, commands: &[SpiralPoint], aims: &[f64]) {
        if self.lead.is_some() {
            return self.extend(commands);
        }
        for (&p, &aim) in commands.iter().zip(aims) {
            self.run_to(p, aim, &[p]);
        }
    }

    /// Led: runs the moves into the points waiting whose data periods'
    /// path is known (a point two data periods past them, or, `end`, the
    /// end of the spiral, past which the path holds still).
    fn run_known(&mut self, end: bool) {
        let ahead = std::mem::take(&mut self.ahead);
        let horizon = ahead.last().map_or(f64::NEG_INFINITY, |p| p.t);
        let mut used = 0;
        while used < ahead.len() && (end || horizon >= ahead[used].t + 2.0 * self.dt) {
            self.run_to(ahead[used], ahead[used].w, &ahead[used..]);
            used += 1;
        }
        self.ahead = ahead;
        self.ahead.drain(..used);
    }

    /// Runs the servo from the last point to `p`, the first of `from_p`
    /// (the points known from `p` on).
    fn run_to(&mut self, p: SpiralPoint, aim: f64, from_p: &[SpiralPoint]) {
        let xy = (p.x * p.c.cos(), p.x * p.c.sin());
        let Some(q) = self.last else {
            // At rest where the path starts.
            self.state = Some(Vector2::new(aim, 0.0));
            self.t0 = p.t;
            self.next = p.t;
            self.last = Some(p);
            self.last_aim = aim;
            self.last_xy = xy;
            return;
        };
        if p.t - q.t > 0.0 {
            self.run_move(q, self.last_xy, p, xy, (self.last_aim, aim), from_p);
        }
        self.prior = self.last;
        self.last = Some(p);
        self.last_aim = aim;
        self.last_xy = xy;
    }

    /// The servo's samples over one move from `q` to `p` (later than `q`),
    /// at `(xq, yq)` and `(xp, yp)` on the part (mm).
    fn run_move(
        &mut self,
        q: SpiralPoint,
        (xq, yq): (f64, f64),
        p: SpiralPoint,
        (xp, yp): (f64, f64),
        aims: (f64, f64),
        from_p: &[SpiralPoint],
    ) {
        let span = p.t - q.t;
        // Per move, not per sample: the tool's speed over the part
        // (mm/s) and the lenslet under the move's middle.
        let chord = (xp - xq).hypot(yp - yq);
        let arc = 0.5 * (p.x + q.x).abs() * (p.c - q.c).abs();
        let step = chord.max(arc).max(1e-12) / span * self.dt;
        let cm = 0.5 * (p.c + q.c);
        let xm = 0.5 * (p.x + q.x);
        let lenslet = self.lenslet_at(xm * cm.cos(), xm * cm.sin());
        // A move whose ends lie in one bin of radius (on one side of the
        // axis, the radius runs straight between them) has every sample
        // there: its extremes are gathered here and counted once.
        let bin = self.by_radius.index(q.x.abs());
        let one_bin = q.x * p.x >= 0.0 && self.by_radius.index(p.x.abs()) == bin;
        let mv = Move {
            q,
            p,
            aims,
            from_p,
            per_second: 1.0 / span,
            step,
        };
        // The four kinds of move get a loop each, so the per-sample work
        // carries no test that cannot change within the move.
        // A move wholly in the air (`cutting_below`) cuts nothing: the
        // servo runs, its error is not gathered.
        let in_air = aims.0.min(aims.1) >= self.air;
        let acc = match (one_bin, lenslet.is_some()) {
            _ if in_air => self.samples::<true, false, false>(&mv),
            (true, true) => self.samples::<true, true, true>(&mv),
            (true, false) => self.samples::<true, false, true>(&mv),
            (false, true) => self.samples::<false, true, true>(&mv),
            (false, false) => self.samples::<false, false, true>(&mv),
        };
        if in_air {
            self.last_error = None;
            return;
        }
        if acc.bin.0 > 0 {
            self.by_radius
                .add_many(bin, acc.bin.0, acc.bin.1, acc.bin.2);
        }
        if let Some(i) = lenslet {
            let a = &mut self.acc[i];
            a.samples += acc.samples;
            a.max = a.max.max(acc.max);
            a.sum2 += acc.sum2;
            a.slope2 += acc.slope2;
        }
    }

    /// Steps the servo over the samples of one move, gathering the errors
    /// in the move's one bin of radius (`ONE_BIN`, else each in its own)
    /// and, `IN_LENSLET`, for the lenslet under it; none unless `CUTTING`.
    #[inline(always)]
    fn samples<const ONE_BIN: bool, const IN_LENSLET: bool, const CUTTING: bool>(
        &mut self,
        mv: &Move,
    ) -> MoveAcc {
        let Move {
            q,
            p,
            aims: (aim_q, aim_p),
            from_p,
            per_second,
            step,
        } = *mv;
        let aim_dw = aim_p - aim_q;
        let (p00, p01, p10, p11) = (
            self.phi[(0, 0)],
            self.phi[(0, 1)],
            self.phi[(1, 0)],
            self.phi[(1, 1)],
        );
        let (g0, g1) = (self.gamma[0], self.gamma[1]);
        let state = self.state.expect("started");
        let (mut pos, mut vel) = (state.x, state.y);
        let dw = p.w - q.w;
        let (t0, dt) = (self.t0, self.dt);
        let lead = self.lead;
        let path = Path {
            prior: self.prior.unwrap_or(q),
            q,
            from_p,
        };
        // Led, where the triangle lies within the move: its mean of r is r
        // half a period on, ṙ is the move's own and r̈ nothing.
        let (half, velocity) = (0.5 * dt * per_second * dw, dw * per_second);
        let (mut k, mut next) = (self.k, self.next);
        let (mut max_error, mut max_error_at) = (self.max_error, self.max_error_at);
        let (mut max_acceleration, mut max_acceleration_at) =
            (self.max_acceleration, self.max_acceleration_at);
        let mut last_error = self.last_error;
        let mut acc = MoveAcc {
            samples: 0,
            max: 0.0,
            sum2: 0.0,
            slope2: 0.0,
            bin: (0, f64::INFINITY, f64::NEG_INFINITY),
        };
        while next < p.t {
            let f = (next - q.t) * per_second;
            let command = q.w + f * dw;
            let error = pos - (aim_q + f * aim_dw);
            let radius = || (q.x + f * (p.x - q.x)).abs();
            if CUTTING && error.abs() > max_error {
                // Rare once the spiral is under way: a branch, not a
                // select the peak's radius would be computed for.
                (max_error, max_error_at) = new_peak(error, radius());
            }
            if !CUTTING {
            } else if ONE_BIN {
                acc.bin.0 += 1;
                acc.bin.1 = acc.bin.1.min(error);
                acc.bin.2 = acc.bin.2.max(error);
            } else {
                self.by_radius.add(radius(), error);
            }
            if IN_LENSLET {
                acc.samples += 1;
                acc.max = acc.max.max(error.abs());
                acc.sum2 += error * error;
                if let Some(e0) = last_error {
                    let slope = (error - e0) / step;
                    acc.slope2 += slope * slope;
                }
            }
            last_error = Some(error);
            let drive = match lead {
                None => command,
                Some((c1, _)) if next - 0.5 * dt >= q.t && next + 1.5 * dt <= p.t => {
                    command + half + c1 * velocity
                }
                Some((c1, c2)) => path.held_command(next + 0.5 * dt, dt, c1, c2),
            };
            let v0 = vel;
            (pos, vel) = (
                p00 * pos + p01 * vel + g0 * drive,
                p10 * pos + p11 * vel + g1 * drive,
            );
            let acceleration = (vel - v0).abs() / dt;
            if acceleration > max_acceleration {
                (max_acceleration, max_acceleration_at) = new_peak(acceleration, radius());
            }
            k += 1;
            next = t0 + k as f64 * dt;
        }
        self.state = Some(Vector2::new(pos, vel));
        (self.k, self.next) = (k, next);
        (self.max_error, self.max_error_at) = (max_error, max_error_at);
        (self.max_acceleration, self.max_acceleration_at) = (max_acceleration, max_acceleration_at);
        self.last_error = last_error;
        acc
    }

    /// What the servo did.
    pub fn finish(mut self) -> Following {
        self.run_known(true);
        let lenslets = self
            .features
            .iter()
            .zip(&self.acc)
            .map(|(f, a)| {
                let n = a.samples.max(1) as f64;
                LensletFollowing {
                    centre: (f.0, f.1),
                    radius: f.0.hypot(f.1),
                    samples: a.samples,
                    max_error: a.max,
                    rms_error: (a.sum2 / n).sqrt(),
                    waviness: (a.slope2 / n).sqrt(),
                }
            })
            .collect();
        Following {
            samples: self.k as usize,
            max_error: self.max_error,
            max_error_at: self.max_error_at,
            lenslets,
            max_acceleration: self.max_acceleration,
            max_acceleration_at: self.max_acceleration_at,
            by_radius: self.by_radius,
        }
    }
}

/// The commanded path about one sample, for the led servo: linear in
/// time through `prior`, `q` and the points `from_p` after it, held before
/// the first and after the last.
struct Path<'a> {
    prior: SpiralPoint,
    q: SpiralPoint,
    from_p: &'a [SpiralPoint],
}

impl Path<'_> {
    fn len(&self) -> usize {
        self.from_p.len() + 2
    }

    fn point(&self, i: usize) -> SpiralPoint {
        match i {
            0 => self.prior,
            1 => self.q,
            _ => self.from_p[i - 2],
        }
    }

    /// r(t) (mm).
    fn at(&self, t: f64) -> f64 {
        let first = self.point(0);
        if t <= first.t {
            return first.w;
        }
        for i in 1..self.len() {
            let b = self.point(i);
            if t < b.t {
                let a = self.point(i - 1);
                return a.w + (t - a.t) * (b.w - a.w) / (b.t - a.t);
            }
        }
        self.point(self.len() - 1).w
    }

    /// ∫ weight(t) r(t) dt over [a, b], `weight` linear there: by
    /// Simpson's rule on each piece between points, exact (the integrand
    /// is quadratic on each).
    fn integral(&self, a: f64, b: f64, weight: &impl Fn(f64) -> f64) -> f64 {
        let piece = |from: f64, to: f64| {
            let m = 0.5 * (from + to);
            (to - from) / 6.0
                * (weight(from) * self.at(from)
                    + 4.0 * weight(m) * self.at(m)
                    + weight(to) * self.at(to))
        };
        let (mut sum, mut from) = (0.0, a);
        for i in 0..self.len() {
            let t = self.point(i).t;
            if t > from && t < b {
                sum += piece(from, t);
                from = t;
            }
        }
        sum + piece(from, b)
    }

    /// The led servo's held command for the data period whose triangle is
    /// centred at `c` (s; half a period after the period starts): u = r +
    /// c1 ṙ + c2 r̈ weighted by the triangle τ(t) = (1 − |t − c|/dt)/dt
    /// over [c − dt, c + dt]. By parts, ∫τṙ = (∫ r over [c, c + dt] −
    /// ∫ r over [c − dt, c]) / dt² and ∫τr̈ = (r(c − dt) − 2r(c) +
    /// r(c + dt)) / dt².
    fn held_command(&self, c: f64, dt: f64, c1: f64, c2: f64) -> f64 {
        let triangle = |t: f64| (1.0 - (t - c).abs() / dt) / dt;
        let one = |_: f64| 1.0;
        let mean = self.integral(c - dt, c, &triangle) + self.integral(c, c + dt, &triangle);
        let slope = (self.integral(c, c + dt, &one) - self.integral(c - dt, c, &one)) / (dt * dt);
        let bend = (self.at(c - dt) - 2.0 * self.at(c) + self.at(c + dt)) / (dt * dt);
        mean + c1 * slope + c2 * bend
    }
}

#[cfg(test)]
mod tests;
