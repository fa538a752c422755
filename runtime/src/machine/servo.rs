//! Fast-tool-servo (FTS) following dynamics: how the servo axis follows its
//! position command, modelled as the second-order transfer function
//! identified from its frequency-response plot, and the tool offset that
//! keeps the settling transient off the part.
//!
//! Source: Hashimoto & Yan (2025), FTS diamond turning of a 10 × 10 concave
//! lenslet array, eqs. 2–7. Their identified model (eq. 2) is the standard
//! second-order system with unit DC gain and no numerator zero,
//!
//! ```text
//! G(s) = ωn² / (s² + 2ζωn s + ωn²),   ωn = 2π · natural_frequency_hz,
//! ```
//!
//! and only its underdamped form (0 < ζ < 1) is modelled here: the servo of
//! the paper has a resonant peak and overshoot, and the closed forms below
//! are those of the underdamped response.
//!
//! Units: s, Hz for the frequencies named `_hz` (ωn in rad/s internally),
//! mm and mm/s for the lenslet geometry. Invalid parameters give `None`,
//! never a panic.

use std::f64::consts::PI;

use nalgebra::{Matrix2, Vector2};

/// Largest number of bisection halvings in [`SecondOrderServo::settling_time`];
/// an `f64` interval stops shrinking well before this.
const MAX_BISECTIONS: usize = 200;

/// An underdamped second-order servo, G(s) = ωn² / (s² + 2ζωn s + ωn²):
/// unit DC gain, so a held command is eventually followed exactly.
///
/// Build it with [`from_natural`](Self::from_natural) or
/// [`from_resonance`](Self::from_resonance), which check the parameters. The
/// fields are public for reading; on a hand-built model outside
/// 0 < ζ < 1 or with a non-positive frequency, the response methods return
/// NaN or `None` rather than panic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondOrderServo {
    /// Undamped natural frequency fn (Hz); ωn = 2π fn.
    pub natural_frequency_hz: f64,
    /// Damping ratio ζ, 0 < ζ < 1.
    pub damping: f64,
}

impl SecondOrderServo {
    /// The servo with natural frequency fn (Hz) and damping ratio ζ.
    /// `None` unless fn is finite and positive and 0 < ζ < 1.
    pub fn from_natural(natural_frequency_hz: f64, damping: f64) -> Option<Self> {
        let servo = Self {
            natural_frequency_hz,
            damping,
        };
        servo.is_valid().then_some(servo)
    }

    /// The servo read off a frequency-response (Bode) plot: resonance
    /// frequency fr (Hz) and resonant peak Mp in **dB** above the DC gain,
    /// as the paper reports it ("ωr = 1367 Hz, Mp = +1.0 dB").
    ///
    /// Inverts the paper's eqs. 3–4, whose Mp is the linear magnitude ratio
    /// (converted here as 10^(dB/20)):
    ///
    /// ```text
    /// Mp = 1 / (2ζ√(1 − ζ²))      (3)
    /// ωr = ωn √(1 − 2ζ²)          (4)
    /// ```
    ///
    /// Eq. 3 has two roots ζ² = (1 ∓ √(1 − 1/Mp²)) / 2. Only the smaller one
    /// (ζ < 1/√2) has a resonance at all, so it is the one taken, as the
    /// paper does (0.523 rather than 0.855). It is computed as
    /// ζ² = 1 / (2 Mp² (1 + √(1 − 1/Mp²))), free of cancellation, and then
    /// 1 − 2ζ² = √(1 − 1/Mp²), so fn = fr / (1 − 1/Mp²)^¼.
    ///
    /// `None` unless fr is finite and positive and the peak is finite and
    /// positive (a plot with no peak above 0 dB has no resonance to invert).
    pub fn from_resonance(resonance_frequency_hz: f64, resonant_peak_db: f64) -> Option<Self> {
        let valid = resonance_frequency_hz.is_finite()
            && resonance_frequency_hz > 0.0
            && resonant_peak_db.is_finite()
            && resonant_peak_db > 0.0;
        if !valid {
            return None;
        }
        let peak = 10f64.powf(resonant_peak_db / 20.0);
        // √(1 − 1/Mp²) = 1 − 2ζ² for the root with ζ < 1/√2.
        let root = (1.0 - 1.0 / (peak * peak)).sqrt();
        let damping = (1.0 / (2.0 * peak * peak * (1.0 + root))).sqrt();
        // A peak too small to tell from 1 gives root = 0, an infinite fn,
        // and `from_natural` rejects it.
        Self::from_natural(resonance_frequency_hz / root.sqrt(), damping)
    }

    /// Resonance frequency fr = fn √(1 − 2ζ²) (Hz), eq. 4; `None` when
    /// ζ ≥ 1/√2 (no resonant peak) or the model is invalid.
    pub fn resonance_frequency_hz(&self) -> Option<f64> {
        let squeeze = 1.0 - 2.0 * self.damping * self.damping;
        (self.is_valid() && squeeze > 0.0).then(|| self.natural_frequency_hz * squeeze.sqrt())
    }

    /// Resonant peak 20·log10(1 / (2ζ√(1 − ζ²))) (dB above the DC gain),
    /// eq. 3; `None` when ζ ≥ 1/√2 (no resonant peak) or the model is invalid.
    pub fn resonant_peak_db(&self) -> Option<f64> {
        let z = self.damping;
        (self.is_valid() && 2.0 * z * z < 1.0)
            .then(|| -20.0 * (2.0 * z * (1.0 - z * z).sqrt()).log10())
    }

    /// Position at time t (s) after a unit step command applied at t = 0
    /// from rest (0 for t ≤ 0):
    ///
    /// ```text
    /// y(t) = 1 − e^(−ζωn t) (cos ωd t + ζ/√(1 − ζ²) · sin ωd t),  ωd = ωn √(1 − ζ²)
    /// ```
    pub fn step_response(&self, t: f64) -> f64 {
        if !self.is_valid() {
            return f64::NAN;
        }
        if t <= 0.0 {
            return 0.0;
        }
        let z = self.damping;
        let wd = self.damped_frequency();
        let ratio = z / (1.0 - z * z).sqrt();
        1.0 - (-self.decay_rate() * t).exp() * ((wd * t).cos() + ratio * (wd * t).sin())
    }

    /// Overshoot of the step response as a fraction of the step:
    /// e^(−πζ/√(1 − ζ²)), reached at the first peak t = π/ωd.
    pub fn overshoot(&self) -> f64 {
        if !self.is_valid() {
            return f64::NAN;
        }
        (-self.log_decrement()).exp()
    }

    /// Settling time (s): the smallest time after which the unit step
    /// response stays within 1 ± `band` (`band` as a fraction, 0.002 for
    /// the paper's 0.2 %). Computed from the response itself, not from the
    /// 4/(ζωn) rule of thumb:
    ///
    /// The error is y(t) − 1 = −e^(−ζωn t)/√(1 − ζ²) · sin(ωd t + acos ζ).
    /// Its extrema sit at t_k = kπ/ωd with |error| = overshootᵏ, strictly
    /// decreasing, and between the extremum t_k and the next zero
    /// z_k = ((k + 1)π − acos ζ)/ωd its magnitude falls monotonically. So
    /// with k the last extremum outside the band (overshootᵏ > band;
    /// k = 0 is the start, error 1), the settling time is the single band
    /// crossing in [t_k, z_k], found by bisection to full `f64` precision
    /// (the returned time is the bracket end inside the band).
    ///
    /// `Some(0)` for band ≥ 1 (the response never leaves it); `None` for a
    /// band that is not finite and positive, or an invalid model.
    pub fn settling_time(&self, band: f64) -> Option<f64> {
        if !(self.is_valid() && band.is_finite() && band > 0.0) {
            return None;
        }
        if band >= 1.0 {
            return Some(0.0);
        }
        // |error(t_k)| = e^(−k·δ), δ the logarithmic decrement per half period.
        let delta = self.log_decrement();
        let peak_error = |k: f64| (-k * delta).exp();
        let mut k = ((-band.ln() / delta).ceil() - 1.0).max(0.0);
        // Guard the rounding of the logarithm: k is the last extremum outside.
        if peak_error(k + 1.0) > band {
            k += 1.0;
        }
        if k > 0.0 && peak_error(k) <= band {
            k -= 1.0;
        }

        let wd = self.damped_frequency();
        let phase = self.damping.acos();
        let scale = 1.0 / (1.0 - self.damping * self.damping).sqrt();
        let sigma = self.decay_rate();
        let error = |t: f64| scale * (-sigma * t).exp() * (wd * t + phase).sin().abs();

        let mut outside = k * PI / wd;
        let mut inside = ((k + 1.0) * PI - phase) / wd;
        for _ in 0..MAX_BISECTIONS {
            let mid = 0.5 * (outside + inside);
            if mid <= outside || mid >= inside {
                break;
            }
            if error(mid) > band {
                outside = mid;
            } else {
                inside = mid;
            }
        }
        Some(inside)
    }

    /// The servo position at each sample of a commanded position sequence
    /// sampled every `dt` (s), starting at rest at `commanded[0]`; element
    /// k is the position at time k·dt, with command k held over
    /// [k·dt, (k + 1)·dt) (zero-order hold).
    ///
    /// Uses the exact zero-order-hold discretisation of the state-space
    /// model x = (position, velocity), ẋ = A x + B u with
    /// A = [[0, 1], [−ωn², −2ζωn]], B = (0, ωn²):
    ///
    /// ```text
    /// x[k+1] = Φ x[k] + Γ u[k],   Φ = e^(A dt),   Γ = ∫₀^dt e^(Aτ) B dτ
    /// ```
    ///
    /// in closed form: Φ = e^(−ζωn dt) (cos ωd dt · I + sin ωd dt / ωd · (A + ζωn I)),
    /// and, as the DC gain is 1 (A⁻¹B = (−1, 0)), Γ = (1 − Φ₁₁, −Φ₂₁).
    /// The positions are therefore exact at the samples for a held command.
    ///
    /// `None` for a `dt` that is not finite and positive, or an invalid
    /// model; an empty command gives an empty response.
    pub fn simulate(&self, commanded: &[f64], dt: f64) -> Option<Vec<f64>> {
        if !(self.is_valid() && dt.is_finite() && dt > 0.0) {
            return None;
        }
        let (phi, gamma) = self.zero_order_hold(dt);
        let mut state = Vector2::new(commanded.first().copied().unwrap_or(0.0), 0.0);
        let mut positions = Vec::with_capacity(commanded.len());
        for &command in commanded {
            positions.push(state.x);
            state = phi * state + gamma * command;
        }
        Some(positions)
    }

    /// Φ and Γ of one step of `dt` (s) of the exact zero-order-hold
    /// discretisation (see [`simulate`](Self::simulate)), for running the
    /// servo as commands arrive; `None` for an invalid model or step.
    pub fn zero_order_hold_step(&self, dt: f64) -> Option<(Matrix2<f64>, Vector2<f64>)> {
        (self.is_valid() && dt.is_finite() && dt > 0.0).then(|| self.zero_order_hold(dt))
    }

    /// Φ = e^(A dt) and Γ of the zero-order-hold discretisation (see
    /// [`simulate`](Self::simulate)).
    fn zero_order_hold(&self, dt: f64) -> (Matrix2<f64>, Vector2<f64>) {
        let wn = self.natural_angular_frequency();
        let wd = self.damped_frequency();
        let sigma = self.decay_rate();
        let decay = (-sigma * dt).exp();
        let (sin, cos) = (wd * dt).sin_cos();
        let phi = decay
            * Matrix2::new(
                cos + sigma / wd * sin,
                sin / wd,
                -wn * wn / wd * sin,
                cos - sigma / wd * sin,
            );
        let gamma = Vector2::new(1.0 - phi[(0, 0)], -phi[(1, 0)]);
        (phi, gamma)
    }

    fn is_valid(&self) -> bool {
        self.natural_frequency_hz.is_finite()
            && self.natural_frequency_hz > 0.0
            && self.damping > 0.0
            && self.damping < 1.0
    }

    /// ωn (rad/s).
    fn natural_angular_frequency(&self) -> f64 {
        2.0 * PI * self.natural_frequency_hz
    }

    /// Damped frequency ωd = ωn √(1 − ζ²) (rad/s).
    fn damped_frequency(&self) -> f64 {
        self.natural_angular_frequency() * (1.0 - self.damping * self.damping).sqrt()
    }

    /// Envelope decay rate ζωn (1/s).
    fn decay_rate(&self) -> f64 {
        self.damping * self.natural_angular_frequency()
    }

    /// Logarithmic decrement per half period of ωd, πζ/√(1 − ζ²): the
    /// error shrinks by e^(−δ) from one extremum to the next.
    fn log_decrement(&self) -> f64 {
        PI * self.damping / (1.0 - self.damping * self.damping).sqrt()
    }
}

/// Height (mm) above the flat zone at which the tool starts and ends its
/// pass over a concave spherical lenslet, so that the servo has settled
/// before it reaches the surface (the paper's eqs. 6–7, Fig. 16):
///
/// ```text
/// h_offset = √(R² − (d/2)²) − √(R² − (d/2 + d_traj)²)     (6)
/// d_traj   = v · T_s                                       (7)
/// ```
///
/// The lenslet sphere (radius of curvature R = `lens_radius`, aperture
/// diameter d = `lens_diameter`) is continued past the aperture edge by
/// d_traj, the distance covered at surface speed v = `surface_speed` (mm/s)
/// during the settling time T_s = `settling_time` (s); h_offset is how far
/// the continued sphere rises above the edge. Evaluated as
/// d_traj (d + d_traj) / (√(R² − (d/2)²) + √(R² − (d/2 + d_traj)²)),
/// the same value without the cancellation of the difference of roots.
///
/// `None` for a non-positive R or d, a negative or non-finite speed or
/// settling time, or when d/2 + d_traj exceeds R (the continued sphere
/// would be past its equator: negative square root).
pub fn settling_offset(
    lens_radius: f64,
    lens_diameter: f64,
    surface_speed: f64,
    settling_time: f64,
) -> Option<f64> {
    let valid = lens_radius.is_finite()
        && lens_radius > 0.0
        && lens_diameter.is_finite()
        && lens_diameter > 0.0
        && surface_speed.is_finite()
        && surface_speed >= 0.0
        && settling_time.is_finite()
        && settling_time >= 0.0;
    if !valid {
        return None;
    }
    let half = lens_diameter / 2.0;
    let travel = surface_speed * settling_time;
    let reach = half + travel;
    if reach > lens_radius {
        return None;
    }
    let edge_depth = ((lens_radius - half) * (lens_radius + half)).sqrt();
    let reach_depth = ((lens_radius - reach) * (lens_radius + reach)).sqrt();
    let sum = edge_depth + reach_depth;
    if sum == 0.0 {
        // Only when d/2 = R and d_traj = 0: both roots vanish.
        return Some(0.0);
    }
    Some(travel * (lens_diameter + travel) / sum)
}

#[cfg(test)]
mod tests;
