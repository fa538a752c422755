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
//! over: the simulation keeps only the servo's state.

use crate::machine::servo::SecondOrderServo;
use crate::plan::fts::SpiralPoint;
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
    /// Every sample's error gathered in bins of radius, for plots.
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
    last_error: Option<f64>,
    features: Vec<(f64, f64, f64)>,
    /// Features by cell of a uniform grid (cell size the largest
    /// diameter), for finding the lenslet under the tool.
    cell: f64,
    grid: std::collections::HashMap<(i64, i64), Vec<usize>>,
    acc: Vec<Acc>,
    max_error: f64,
    max_error_at: f64,
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
        let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
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
            by_radius,
        })
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
            let Some(q) = self.last else {
                self.state = Some(Vector2::new(p.w, 0.0));
                self.t0 = p.t;
                self.next = p.t;
                self.last = Some(p);
                continue;
            };
            let span = p.t - q.t;
            if span > 0.0 {
                // Per move, not per sample: the tool's speed over the part
                // (mm/s) and the lenslet under the move's middle.
                let (xq, yq) = (q.x * q.c.cos(), q.x * q.c.sin());
                let (xp, yp) = (p.x * p.c.cos(), p.x * p.c.sin());
                let chord = (xp - xq).hypot(yp - yq);
                let arc = 0.5 * (p.x + q.x).abs() * (p.c - q.c).abs();
                let step = chord.max(arc).max(1e-12) / span * self.dt;
                let cm = 0.5 * (p.c + q.c);
                let xm = 0.5 * (p.x + q.x);
                let lenslet = self.lenslet_at(xm * cm.cos(), xm * cm.sin());
                let mut state = self.state.expect("started");
                let (p00, p01, p10, p11) = (
                    self.phi[(0, 0)],
                    self.phi[(0, 1)],
                    self.phi[(1, 0)],
                    self.phi[(1, 1)],
                );
                let (g0, g1) = (self.gamma[0], self.gamma[1]);
                let (mut pos, mut vel) = (state.x, state.y);
                let per_second = 1.0 / span;
                let dw = p.w - q.w;
                let mut acc = lenslet.map(|i| (i, 0usize, 0.0f64, 0.0f64, 0.0f64));
                // A move whose ends lie in one bin of radius (on one side
                // of the axis, the radius runs straight between them) has
                // every sample there: its extremes are gathered here and
                // counted once.
                let bin = self.by_radius.index(q.x.abs());
                let one_bin = q.x * p.x >= 0.0 && self.by_radius.index(p.x.abs()) == bin;
                let (mut n, mut lo, mut hi) = (0u64, f64::INFINITY, f64::NEG_INFINITY);
                while self.next < p.t {
                    let f = (self.next - q.t) * per_second;
                    let command = q.w + f * dw;
                    let error = pos - command;
                    let radius = || (q.x + f * (p.x - q.x)).abs();
                    if error.abs() > self.max_error {
                        self.max_error = error.abs();
                        self.max_error_at = radius();
                    }
                    if one_bin {
                        n += 1;
                        lo = lo.min(error);
                        hi = hi.max(error);
                    } else {
                        self.by_radius.add(radius(), error);
                    }
                    if let Some((_, n, max, sum2, slope2)) = acc.as_mut() {
                        *n += 1;
                        *max = max.max(error.abs());
                        *sum2 += error * error;
                        if let Some(e0) = self.last_error {
                            let slope = (error - e0) / step;
                            *slope2 += slope * slope;
                        }
                    }
                    self.last_error = Some(error);
                    (pos, vel) = (
                        p00 * pos + p01 * vel + g0 * command,
                        p10 * pos + p11 * vel + g1 * command,
                    );
                    self.k += 1;
                    self.next = self.t0 + self.k as f64 * self.dt;
                }
                if n > 0 {
                    self.by_radius.add_many(bin, n, lo, hi);
                }
                if let Some((i, n, max, sum2, slope2)) = acc {
                    let a = &mut self.acc[i];
                    a.samples += n;
                    a.max = a.max.max(max);
                    a.sum2 += sum2;
                    a.slope2 += slope2;
                }
                state = Vector2::new(pos, vel);
                self.state = Some(state);
            }
            self.last = Some(p);
        }
    }

    /// What the servo did.
    pub fn finish(self) -> Following {
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
            by_radius: self.by_radius,
        }
    }
}

#[cfg(test)]
mod tests;
