//! A round nose's measured edge: its radius ρ(θ) = R + δ(θ) at each angle
//! θ of the nose, the deviation δ interpolated between measured samples,
//! and what the planner and the simulation ask of such an edge (the point
//! that touches a surface of given normal, the lowest point at an
//! abscissa).
//!
//! Angles: θ is measured at the nose centre from the tool's axis (−Z, the
//! nose's lowest point), positive towards +X. A surface of slope dz/dr
//! touches the nose at θ = atan(dz/dr). δ > 0 where the edge stands proud
//! of the circle of radius R (it cuts deeper there).
//!
//! Interpolation: a natural cubic spline through the samples, so δ and
//! δ′ are continuous; beyond the samples' angles δ holds its end value
//! (the edge taken as a circle through the last sample's radius).
//!
//! The text format read (`parse`): one sample a line, angle in degrees
//! then deviation in micrometres, separated by white space, a comma or a
//! semicolon; `#` starts a comment; a first line of words (a column
//! header) is skipped.

/// A measured edge profile: strictly increasing angles (rad) and the
/// deviation at each (mm), with the spline's second derivatives.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeProfile {
    angles: Vec<f64>,
    deviations: Vec<f64>,
    /// δ″ at each sample (natural spline: zero at both ends).
    second: Vec<f64>,
}

/// Why samples do not make an edge profile.
#[derive(Clone, Debug, PartialEq)]
pub enum EdgeError {
    /// A line that is not two numbers: its number (from 1), the byte where
    /// it starts, and what is wrong.
    Malformed {
        line: usize,
        at: usize,
        what: String,
    },
    /// Fewer than `MIN_SAMPLES` samples.
    TooFew { samples: usize },
    /// An angle (deg) not greater than the one before it, on line `line`
    /// (0 when the samples came from no file).
    NotIncreasing {
        line: usize,
        at: usize,
        angle: f64,
        previous: f64,
    },
}

impl std::fmt::Display for EdgeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EdgeError::Malformed { line, what, .. } => write!(f, "line {line}: {what}"),
            EdgeError::TooFew { samples } => write!(
                f,
                "{samples} samples: an edge profile needs at least {MIN_SAMPLES}"
            ),
            EdgeError::NotIncreasing {
                line,
                angle,
                previous,
                ..
            } => write!(
                f,
                "line {line}: the angle {angle}° does not follow {previous}°: angles must increase down the file"
            ),
        }
    }
}

/// The fewest samples an edge profile is made of.
pub const MIN_SAMPLES: usize = 3;

/// One parsed sample: angle (deg), deviation (µm), its line and byte.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub angle_deg: f64,
    pub deviation_um: f64,
    pub line: usize,
    pub at: usize,
}

/// Reads the text format (module doc) into samples, in file order;
/// checks only that each line is two finite numbers.
pub fn parse(text: &str) -> Result<Vec<Sample>, EdgeError> {
    let mut out = Vec::new();
    let mut at = 0;
    let mut seen_data = false;
    for (i, raw) in text.split_inclusive('\n').enumerate() {
        let start = at;
        at += raw.len();
        let body = raw.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let words: Vec<&str> = body
            .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
            .filter(|w| !w.is_empty())
            .collect();
        let numbers: Vec<Option<f64>> = words.iter().map(|w| w.parse::<f64>().ok()).collect();
        let malformed = |what: String| EdgeError::Malformed {
            line: i + 1,
            at: start,
            what,
        };
        if !seen_data && numbers.iter().all(Option::is_none) {
            // A column header.
            seen_data = true;
            continue;
        }
        seen_data = true;
        match numbers.as_slice() {
            [Some(a), Some(d)] if a.is_finite() && d.is_finite() => out.push(Sample {
                angle_deg: *a,
                deviation_um: *d,
                line: i + 1,
                at: start,
            }),
            [Some(_), Some(_)] => return Err(malformed("a number that is not finite".into())),
            _ => {
                return Err(malformed(format!(
                    "`{body}` is not an angle (deg) and a deviation (um)"
                )));
            }
        }
    }
    Ok(out)
}

impl EdgeProfile {
    /// The profile through `samples` (angle in degrees, deviation in µm),
    /// or why they make none: fewer than `MIN_SAMPLES`, or angles that do
    /// not increase.
    pub fn from_samples(samples: &[Sample]) -> Result<EdgeProfile, EdgeError> {
        if samples.len() < MIN_SAMPLES {
            return Err(EdgeError::TooFew {
                samples: samples.len(),
            });
        }
        for w in samples.windows(2) {
            if w[1].angle_deg <= w[0].angle_deg {
                return Err(EdgeError::NotIncreasing {
                    line: w[1].line,
                    at: w[1].at,
                    angle: w[1].angle_deg,
                    previous: w[0].angle_deg,
                });
            }
        }
        let angles: Vec<f64> = samples.iter().map(|s| s.angle_deg.to_radians()).collect();
        let deviations: Vec<f64> = samples.iter().map(|s| s.deviation_um * 1e-3).collect();
        let second = natural_spline(&angles, &deviations);
        Ok(EdgeProfile {
            angles,
            deviations,
            second,
        })
    }

    /// The angles (rad) the samples cover: first and last.
    pub fn range(&self) -> (f64, f64) {
        (self.angles[0], self.angles[self.angles.len() - 1])
    }

    /// The largest |δ| among the samples (mm), and the angle (rad).
    pub fn largest(&self) -> (f64, f64) {
        self.angles
            .iter()
            .zip(&self.deviations)
            .map(|(&a, &d)| (d.abs(), a))
            .fold((0.0, 0.0), |m, x| if x.0 > m.0 { x } else { m })
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.angles.len()
    }

    /// Never: a profile has at least `MIN_SAMPLES` samples.
    pub fn is_empty(&self) -> bool {
        self.angles.is_empty()
    }

    /// δ(θ) (mm) and δ′(θ) (mm/rad): the spline, or the end value held
    /// (slope 0) beyond the samples.
    pub fn deviation(&self, theta: f64) -> (f64, f64) {
        let n = self.angles.len();
        let (lo, hi) = self.range();
        if theta <= lo {
            return (self.deviations[0], 0.0);
        }
        if theta >= hi {
            return (self.deviations[n - 1], 0.0);
        }
        // The interval [θ_j, θ_j+1] holding θ.
        let j = self.angles.partition_point(|&a| a <= theta).clamp(1, n - 1) - 1;
        let (x0, x1) = (self.angles[j], self.angles[j + 1]);
        let (y0, y1) = (self.deviations[j], self.deviations[j + 1]);
        let (m0, m1) = (self.second[j], self.second[j + 1]);
        let h = x1 - x0;
        let a = (x1 - theta) / h;
        let b = (theta - x0) / h;
        let value = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let slope = (y1 - y0) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        (value, slope)
    }
}

/// The second derivatives of the natural cubic spline through (x, y):
/// the tridiagonal system solved by the Thomas algorithm.
fn natural_spline(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    // Rows 1..n-1: h_{i-1} m_{i-1} + 2(h_{i-1}+h_i) m_i + h_i m_{i+1} = r_i.
    let mut diag = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    for i in 1..n - 1 {
        let (h0, h1) = (x[i] - x[i - 1], x[i + 1] - x[i]);
        diag[i] = 2.0 * (h0 + h1);
        rhs[i] = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
    }
    // Forward sweep (the sub-diagonal of row i is h_{i-1}, the
    // super-diagonal h_i).
    for i in 2..n - 1 {
        let h_prev = x[i] - x[i - 1];
        let w = h_prev / diag[i - 1];
        diag[i] -= w * h_prev;
        rhs[i] -= w * rhs[i - 1];
    }
    for i in (1..n - 1).rev() {
        let h = x[i + 1] - x[i];
        m[i] = (rhs[i] - h * m[i + 1]) / diag[i];
    }
    m
}

/// A round nose as the planner and the simulation see it: radius R and,
/// when measured, its edge's deviation from the circle.
#[derive(Clone, Copy, Debug)]
pub struct Nose<'a> {
    pub radius: f64,
    pub edge: Option<&'a EdgeProfile>,
}

impl<'a> Nose<'a> {
    /// A perfect circle of radius `radius`.
    pub fn circle(radius: f64) -> Nose<'static> {
        Nose { radius, edge: None }
    }

    /// ρ(θ) and ρ′(θ): the edge's distance from the nose centre at θ.
    pub fn rho(&self, theta: f64) -> (f64, f64) {
        match self.edge {
            None => (self.radius, 0.0),
            Some(e) => {
                let (d, s) = e.deviation(theta);
                (self.radius + d, s)
            }
        }
    }

    /// The angle θ* of the edge point that touches a line whose normal,
    /// from the nose centre towards the line, points at angle `phi` (from
    /// −Z towards +X), and how far the line is from the centre there: the
    /// support function h(φ) = max over θ of ρ(θ) cos(θ − φ), whose
    /// maximum satisfies tan(θ − φ) = ρ′/ρ. h = R + δ(φ) + δ′²/(2R) to
    /// second order.
    pub fn support(&self, phi: f64) -> (f64, f64) {
        let Some(_) = self.edge else {
            return (phi, self.radius);
        };
        let mut theta = phi;
        for _ in 0..4 {
            let (r, dr) = self.rho(theta);
            theta = phi + (dr / r).atan();
        }
        let (r, _) = self.rho(theta);
        (theta, r * (theta - phi).cos())
    }

    /// The edge point (relative to the nose centre) that touches a line
    /// whose normal from the centre points along the unit vector `d`
    /// (x, z).
    pub fn support_point(&self, d: (f64, f64)) -> (f64, f64) {
        if self.edge.is_none() {
            return (self.radius * d.0, self.radius * d.1);
        }
        let phi = d.0.atan2(-d.1);
        let (theta, _) = self.support(phi);
        let (r, _) = self.rho(theta);
        (r * theta.sin(), -r * theta.cos())
    }

    /// The farthest reach of the edge from its centre (mm).
    pub fn reach(&self) -> f64 {
        self.radius + self.edge.map_or(0.0, |e| e.largest().0)
    }

    /// The lowest point's height of the nose centred at `c` at abscissa
    /// `x`, if the nose reaches `x`: the θ in (−90°, 90°) where
    /// c.x + ρ(θ) sin θ = x, by Newton from the circle's.
    pub fn bottom(&self, c: (f64, f64), x: f64) -> Option<f64> {
        self.lift(x - c.0).map(|(l, _)| c.1 - l)
    }

    /// How far below its centre the nose's edge lies at the horizontal
    /// offset `d` from it (mm), and how that depth changes with `d`: L(d)
    /// = ρ(θ) cos θ and dL/dd, θ in (−90°, 90°) the edge's angle where
    /// ρ(θ) sin θ = d (Newton from the circle's asin(d/R)); `None` beyond
    /// the nose's reach. A circle's: sqrt(R² − d²) and −d/sqrt(R² − d²).
    pub fn lift(&self, d: f64) -> Option<(f64, f64)> {
        let Some(_) = self.edge else {
            let rho = self.radius;
            if d.abs() > rho {
                return None;
            }
            let root = (rho * rho - d * d).sqrt();
            return Some((root, -d / root));
        };
        let theta = self.angle_at(d)?;
        let (r, dr) = self.rho(theta);
        let (sin, cos) = theta.sin_cos();
        Some((r * cos, (dr * cos - r * sin) / (dr * sin + r * cos)))
    }

    /// The edge's angle θ in (−90°, 90°) whose point lies `d` (mm) from
    /// the nose centre across it: ρ(θ) sin θ = d, by Newton from the
    /// circle's; `None` beyond the reach or where Newton does not land.
    pub fn angle_at(&self, d: f64) -> Option<f64> {
        if d.abs() > self.reach() {
            return None;
        }
        let mut theta = (d / self.radius).clamp(-1.0, 1.0).asin();
        if self.edge.is_none() {
            return Some(theta);
        }
        for _ in 0..20 {
            let (r, dr) = self.rho(theta);
            let f = r * theta.sin() - d;
            let slope = dr * theta.sin() + r * theta.cos();
            if slope <= 0.0 || !slope.is_finite() {
                break;
            }
            let step = f / slope;
            theta = (theta - step).clamp(-0.5 * std::f64::consts::PI, 0.5 * std::f64::consts::PI);
            if step.abs() < 1e-15 {
                break;
            }
        }
        let (r, _) = self.rho(theta);
        ((r * theta.sin() - d).abs() <= 1e-9).then_some(theta)
    }
}

#[cfg(test)]
mod tests;
