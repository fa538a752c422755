//! Leading a fast tool servo from the program: where the controller feeds
//! nothing forward, the command written for each point is the servo's
//! inverse model applied to the path, so the servo driven by the printed
//! command follows the path itself.
//!
//! The servo is `G(s) = ωn² / (s² + 2ζωn s + ωn²)` driven by its command
//! held over each data period `dt`, the hold `(1 − e^(−s dt)) / (s dt) =
//! e^(−s dt/2) (1 − s² dt²/24 + …)`. The command written at a point is the
//! path through the inverse of both, to second order in s:
//!
//! ```text
//! u = r + (c1 + dt/2) ṙ + (c2 + c1 dt/2 + dt²/6) r̈,   c1 = 2ζ/ωn, c2 = 1/ωn²
//! ```
//!
//! (the hold's half-period delay applies to the velocity's lead as well:
//! without `c1 dt/2` the servo falls behind by that times r̈, 12 nm on a
//! 1 µm ripple at 300 Hz).
//! The path r is the program's own: linear in time between its points, so
//! its velocity steps at each point and r̈ is an impulse there. ṙ and r̈ at
//! a point are the three-point divided differences through it and its
//! neighbours, which for the impulse is its area spread as a hat over the
//! two moves beside the point (the hat the program's own linear motion
//! draws): the printed command keeps the impulse's area wherever the
//! points lie. A hat much wider than the servo's time constant would
//! smear the impulse (a lenslet's rim met from the level land, points a
//! millisecond apart, leaves hundreds of nm): where a move beside a bending
//! point is longer than two data periods, a point of the path is added on
//! it a data period from the bend, so the hat is never wider than two
//! periods. Before the first point and after the last the path holds
//! still.
//!
//! Points arrive in order, in chunks, as the planner hands them over; each
//! is led once the point after it is known ([`ProgramLead::finish`] leads
//! the last).

use crate::machine::servo::SecondOrderServo;
use crate::plan::spiral::SpiralPoint;

/// The command a servo with no feed-forward needs, written point by point.
#[derive(Clone, Debug)]
pub struct ProgramLead {
    /// The gains of ṙ (s) and r̈ (s²).
    velocity_gain: f64,
    acceleration_gain: f64,
    /// The data period (s), and the least lead (mm) of a bend worth the
    /// points added beside it (half the printed resolution).
    dt: f64,
    least: f64,
    /// The last two points received, not yet led (the later one waits
    /// for its successor).
    before: Option<SpiralPoint>,
    waiting: Option<SpiralPoint>,
}

impl ProgramLead {
    /// The lead for `servo` taking positions at `data_rate_hz`, printed
    /// to `resolution` (mm).
    pub fn new(servo: &SecondOrderServo, data_rate_hz: f64, resolution: f64) -> ProgramLead {
        let wn = 2.0 * std::f64::consts::PI * servo.natural_frequency_hz;
        let (c1, dt) = (2.0 * servo.damping / wn, 1.0 / data_rate_hz);
        ProgramLead {
            velocity_gain: c1 + 0.5 * dt,
            acceleration_gain: 1.0 / (wn * wn) + 0.5 * c1 * dt + dt * dt / 6.0,
            dt,
            least: 0.5 * resolution,
            before: None,
            waiting: None,
        }
    }

    /// Leads the next points of the path: into `commands` (cleared
    /// first) the commands, into `path` (cleared first) the path's points
    /// they lead to, one for one — the point waiting from before, then
    /// each of `points` but the last, which waits for its successor, with
    /// the points added beside bends. Each command is its path point with W
    /// the command.
    pub fn extend(
        &mut self,
        points: &[SpiralPoint],
        commands: &mut Vec<SpiralPoint>,
        path: &mut Vec<SpiralPoint>,
    ) {
        commands.clear();
        path.clear();
        for &p in points {
            if let Some(w) = self.waiting {
                self.lead(self.before.unwrap_or(w), w, Some(p), commands, path);
                self.before = Some(w);
            }
            self.waiting = Some(p);
        }
    }

    /// Leads the path's last point (after it the path holds still), as
    /// `extend` does.
    pub fn finish(&mut self, commands: &mut Vec<SpiralPoint>, path: &mut Vec<SpiralPoint>) {
        commands.clear();
        path.clear();
        if let Some(w) = self.waiting.take() {
            self.lead(self.before.unwrap_or(w), w, None, commands, path);
        }
    }

    /// Leads `p` (neighbours `a` and `b`) into `commands` and `path`, with
    /// a point of the path a data period before and after it where its
    /// moves are longer than two periods and it bends enough to lead.
    fn lead(
        &self,
        a: SpiralPoint,
        p: SpiralPoint,
        b: Option<SpiralPoint>,
        commands: &mut Vec<SpiralPoint>,
        path: &mut Vec<SpiralPoint>,
    ) {
        let on = |from: SpiralPoint, to: SpiralPoint, t: f64| {
            let f = (t - from.t) / (to.t - from.t);
            SpiralPoint {
                x: from.x + f * (to.x - from.x),
                c: from.c + f * (to.c - from.c),
                w: from.w + f * (to.w - from.w),
                t,
            }
        };
        let dt = self.dt;
        let near_a = (p.t - a.t > 2.0 * dt).then(|| on(a, p, p.t - dt));
        let near_b = b
            .filter(|b| b.t - p.t > 2.0 * dt)
            .map(|b| on(p, b, p.t + dt));
        // The bend's lead over a hat two periods wide.
        let (_, _, before, after) = self.slopes(a, p, b);
        let bends = self.acceleration_gain * (after - before).abs() / dt > self.least;
        if !(bends && (near_a.is_some() || near_b.is_some())) {
            commands.push(self.led(a, p, b));
            path.push(p);
            return;
        }
        let a_near = near_a.unwrap_or(a);
        let b_near = near_b.or(b);
        // The added points lie on straight moves: led by their velocity.
        if let Some(e) = near_a {
            commands.push(self.led(a, e, Some(p)));
            path.push(e);
        }
        commands.push(self.led(a_near, p, b_near));
        path.push(p);
        if let (Some(e), Some(b)) = (near_b, b) {
            commands.push(self.led(p, e, Some(b)));
            path.push(e);
        }
    }

    /// The moves beside `p`: their durations and slopes (a held path where
    /// there is none: the point repeated a move's time away).
    fn slopes(
        &self,
        a: SpiralPoint,
        p: SpiralPoint,
        b: Option<SpiralPoint>,
    ) -> (f64, f64, f64, f64) {
        let h2 = b.map_or(0.0, |b| b.t - p.t);
        let h1 = p.t - a.t;
        let (h1, ra) = if h1 > 0.0 { (h1, a.w) } else { (h2, p.w) };
        let (h2, rb) = match b {
            Some(b) if h2 > 0.0 => (h2, b.w),
            _ => (h1, p.w),
        };
        if !(h1 > 0.0 && h2 > 0.0) {
            return (h1, h2, 0.0, 0.0);
        }
        (h1, h2, (p.w - ra) / h1, (rb - p.w) / h2)
    }

    /// `p` led, from its neighbours `a` before and `b` after.
    fn led(&self, a: SpiralPoint, p: SpiralPoint, b: Option<SpiralPoint>) -> SpiralPoint {
        let (h1, h2, before, after) = self.slopes(a, p, b);
        if !(h1 > 0.0 && h2 > 0.0) {
            // A single point: nothing moves.
            return p;
        }
        let velocity = (h1 * after + h2 * before) / (h1 + h2);
        let acceleration = 2.0 * (after - before) / (h1 + h2);
        SpiralPoint {
            w: p.w + self.velocity_gain * velocity + self.acceleration_gain * acceleration,
            ..p
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn servo() -> SecondOrderServo {
        SecondOrderServo::from_resonance(1367.0, 1.0).expect("seed 003's servo")
    }

    fn led(points: &[SpiralPoint], chunk: usize) -> Vec<SpiralPoint> {
        let mut lead = ProgramLead::new(&servo(), 20e3, 1e-6);
        let (mut all, mut out, mut path) = (Vec::new(), Vec::new(), Vec::new());
        for c in points.chunks(chunk) {
            lead.extend(c, &mut out, &mut path);
            assert_eq!(out.len(), path.len());
            all.extend_from_slice(&out);
        }
        lead.finish(&mut out, &mut path);
        all.extend_from_slice(&out);
        all
    }

    fn point(t: f64, w: f64) -> SpiralPoint {
        SpiralPoint { x: 1.0, c: t, w, t }
    }

    #[test]
    fn a_still_path_is_written_as_it_is_and_a_ramp_led_by_its_velocity() {
        let still: Vec<_> = (0..10).map(|k| point(k as f64 * 1e-4, 0.3)).collect();
        assert_eq!(led(&still, 3), still);
        // A ramp at 2 mm/s, its inner points led by (2ζ/ωn + dt/2) · 2.
        // (Points 80 µs apart, under two periods: none added at the
        // start, where the ramp bends from rest.)
        let ramp: Vec<_> = (0..10)
            .map(|k| point(k as f64 * 8e-5, 2.0 * k as f64 * 8e-5))
            .collect();
        let out = led(&ramp, 4);
        let s = servo();
        let wn = 2.0 * std::f64::consts::PI * s.natural_frequency_hz;
        let gain = 2.0 * s.damping / wn + 0.5 / 20e3;
        for (p, q) in ramp.iter().zip(&out).skip(1).take(8) {
            assert!((q.w - p.w - 2.0 * gain).abs() < 1e-12, "{} {}", q.w, p.w);
        }
        assert_eq!(out.len(), ramp.len());
    }

    #[test]
    fn a_corner_is_written_as_a_hat_of_the_impulse_s_area() {
        // Still, then rising at 1 mm/s from t = 0.8 ms, points 80 µs apart
        // (under two data periods): the corner's impulse (1 mm/s) over the
        // hat of the two moves beside it (160 µs wide, area 80 µs ×
        // height) gives its height.
        let pts: Vec<_> = (0..16)
            .map(|k| {
                let t = k as f64 * 8e-5;
                point(t, (t - 8e-4).max(0.0))
            })
            .collect();
        let out = led(&pts, 5);
        let s = servo();
        let wn = 2.0 * std::f64::consts::PI * s.natural_frequency_hz;
        let dt = 1.0 / 20e3;
        let c1 = 2.0 * s.damping / wn + 0.5 * dt;
        let c2 = 1.0 / (wn * wn) + 0.5 * (c1 - 0.5 * dt) * dt + dt * dt / 6.0;
        assert_eq!(out.len(), pts.len());
        let corner = out[10].w - pts[10].w;
        let want = c1 * 0.5 + c2 * 1.0 / 8e-5;
        assert!((corner - want).abs() < 1e-12, "{corner} {want}");
        assert_eq!(out[2].w, pts[2].w);
        // Points 0.5 ms apart: a point of the path added a period either
        // side of the corner, the hat as narrow as before.
        let sparse: Vec<_> = (0..12)
            .map(|k| {
                let t = k as f64 * 5e-4;
                point(t, (t - 1e-3).max(0.0))
            })
            .collect();
        let out = led(&sparse, 5);
        // (and one before the end, where the path stops: held after it).
        assert_eq!(out.len(), sparse.len() + 3);
        assert!((out[2].t - (1e-3 - 5e-5)).abs() < 1e-15 && out[2].w == 0.0);
        let corner = out[3].w - sparse[2].w;
        assert!((corner - (c1 * 0.5 + c2 / 5e-5)).abs() < 1e-12, "{corner}");
    }
}
