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

use crate::fts::SpiralPoint;
use crate::servo::SecondOrderServo;
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
    /// The error every `trace_every` samples: time (s), radius (mm),
    /// commanded W (mm), error (mm), for plots.
    pub trace: Vec<[f64; 4]>,
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
    trace_every: u64,
    /// Samples until the next trace row.
    until_trace: u64,
    trace: Vec<[f64; 4]>,
}

impl FollowingSimulation {
    /// A servo sampled at `data_rate_hz` over lenslets `features` (centre
    /// x, y and radius, mm); a trace sample is kept every `trace_every`
    /// servo samples. `None` for an invalid servo or rate.
    pub fn new(
        servo: &SecondOrderServo,
        data_rate_hz: f64,
        features: &[(f64, f64, f64)],
        trace_every: u64,
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
            trace_every: trace_every.max(1),
            until_trace: 0,
            trace: Vec::new(),
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
                while self.next < p.t {
                    let f = (self.next - q.t) * per_second;
                    let command = q.w + f * dw;
                    let error = pos - command;
                    if error.abs() > self.max_error {
                        self.max_error = error.abs();
                        self.max_error_at = (q.x + f * (p.x - q.x)).abs();
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
                    if self.until_trace == 0 {
                        self.trace
                            .push([self.next, (q.x + f * (p.x - q.x)).abs(), command, error]);
                        self.until_trace = self.trace_every;
                    }
                    self.until_trace -= 1;
                    self.last_error = Some(error);
                    (pos, vel) = (
                        p00 * pos + p01 * vel + g0 * command,
                        p10 * pos + p11 * vel + g1 * command,
                    );
                    self.k += 1;
                    self.next = self.t0 + self.k as f64 * self.dt;
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
            trace: self.trace,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn servo() -> SecondOrderServo {
        SecondOrderServo::from_resonance(1367.0, 1.0).expect("seed 003's servo")
    }

    /// Points every `dt` on a circle of radius `r` at `rpm`, W given by
    /// `w(t)`.
    fn circle(r: f64, rpm: f64, dt: f64, n: usize, w: impl Fn(f64) -> f64) -> Vec<SpiralPoint> {
        let omega = rpm * 2.0 * std::f64::consts::PI / 60.0;
        (0..n)
            .map(|k| {
                let t = k as f64 * dt;
                SpiralPoint {
                    x: r,
                    c: omega * t,
                    w: w(t),
                    t,
                }
            })
            .collect()
    }

    #[test]
    fn a_held_command_is_followed_exactly() {
        let mut sim = FollowingSimulation::new(&servo(), 20e3, &[], 1).expect("valid");
        sim.extend(&circle(5.0, 100.0, 1e-3, 200, |_| 0.25));
        let f = sim.finish();
        assert!(f.samples > 3900);
        assert!(f.max_error < 1e-15, "{}", f.max_error);
    }

    #[test]
    fn streaming_matches_the_batch_servo_response() {
        // Points exactly on the servo's samples: the streamed errors are the
        // batch simulation's response minus the command, sample for sample,
        // however the points are split into chunks.
        let dt = 1.0 / 20e3;
        let w = |t: f64| 0.002 * (2.0 * std::f64::consts::PI * 300.0 * t).sin();
        let pts = circle(5.0, 100.0, dt, 2000, w);
        let mut sim = FollowingSimulation::new(&servo(), 20e3, &[], 1).expect("valid");
        for chunk in pts.chunks(37) {
            sim.extend(chunk);
        }
        let f = sim.finish();
        let commands: Vec<f64> = pts.iter().map(|p| p.w).collect();
        let batch = servo().simulate(&commands, dt).expect("valid");
        assert_eq!(f.trace.len(), pts.len() - 1);
        for (k, row) in f.trace.iter().enumerate() {
            let want = batch[k] - commands[k];
            assert!((row[3] - want).abs() < 1e-15, "{k}: {} vs {want}", row[3]);
        }
        // 300 Hz on a 1367 Hz servo: a real, visible lag.
        assert!(f.max_error > 1e-5, "{}", f.max_error);
    }

    #[test]
    fn errors_are_gathered_by_the_lenslet_under_the_tool() {
        // Two lenslets on the circle's path, at c = 0 and c = π; the
        // command wobbles fast only where the tool is over the second.
        let r = 5.0;
        let feats = [(r, 0.0, 0.5), (-r, 0.0, 0.5)];
        let omega = 100.0 * 2.0 * std::f64::consts::PI / 60.0;
        let w = |t: f64| {
            let c = (omega * t).rem_euclid(2.0 * std::f64::consts::PI);
            if (c - std::f64::consts::PI).abs() < 0.09 {
                0.001 * (2.0 * std::f64::consts::PI * 2000.0 * t).sin()
            } else {
                0.0
            }
        };
        let mut sim = FollowingSimulation::new(&servo(), 20e3, &feats, 100).expect("valid");
        sim.extend(&circle(r, 100.0, 1e-5, 60_000, w));
        let f = sim.finish();
        let (a, b) = (&f.lenslets[0], &f.lenslets[1]);
        // Each lenslet spans 2 asin(0.5/(2·5)) ≈ 0.1 rad of the turn.
        assert!(
            a.samples > 100 && b.samples > 100,
            "{} {}",
            a.samples,
            b.samples
        );
        assert!(a.max_error < 1e-12, "{}", a.max_error);
        assert!(b.max_error > 1e-5 && b.waviness > 0.0);
        assert!((b.radius - r).abs() < 1e-12);
        assert_eq!(f.trace.len(), f.samples.div_ceil(100));
    }
}
