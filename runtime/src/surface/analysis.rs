//! Surface analysis over a domain: sag range, steepest slopes overall and
//! along x and y, and the smallest radii of curvature of the concave and
//! convex regions along x and y, each with where it occurs.
//!
//! Method: the surface is evaluated (value and exact derivatives) on a
//! grid over the domain, and every extremum found on the grid is refined
//! by repeatedly re-gridding a shrinking window around it, so the figures
//! are accurate well beyond the grid spacing.

use crate::surface::ir::SurfaceFn;

/// Where a surface is defined and machined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// A disc about the origin.
    Circle { radius: f64 },
    /// A ring about the origin: inner ≤ r ≤ outer.
    Annulus { inner: f64, outer: f64 },
    /// x0 ≤ x ≤ x1, y0 ≤ y ≤ y1.
    Rect { x: (f64, f64), y: (f64, f64) },
}

impl Domain {
    pub fn contains(&self, x: f64, y: f64) -> bool {
        match *self {
            Domain::Circle { radius } => x * x + y * y <= radius * radius * (1.0 + 1e-12),
            Domain::Annulus { inner, outer } => {
                let r2 = x * x + y * y;
                r2 >= inner * inner * (1.0 - 1e-12) && r2 <= outer * outer * (1.0 + 1e-12)
            }
            Domain::Rect {
                x: (x0, x1),
                y: (y0, y1),
            } => x >= x0 && x <= x1 && y >= y0 && y <= y1,
        }
    }
    /// The domain grown by `margin` (mm) all round: a disc or ring's outer
    /// radius larger (and a ring's hole smaller), a rectangle wider.
    pub fn grown(&self, margin: f64) -> Domain {
        match *self {
            Domain::Circle { radius } => Domain::Circle {
                radius: radius + margin,
            },
            Domain::Annulus { inner, outer } => Domain::Annulus {
                inner: (inner - margin).max(0.0),
                outer: outer + margin,
            },
            Domain::Rect { x, y } => Domain::Rect {
                x: (x.0 - margin, x.1 + margin),
                y: (y.0 - margin, y.1 + margin),
            },
        }
    }
    /// The bounding box ((x0, x1), (y0, y1)).
    pub fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        match *self {
            Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => {
                ((-radius, radius), (-radius, radius))
            }
            Domain::Rect { x, y } => (x, y),
        }
    }
}

/// A figure and the point where it occurs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extremum {
    pub value: f64,
    pub x: f64,
    pub y: f64,
}

/// The analysis of one surface over its domain. Slopes are angles (rad),
/// radii in mm; a radius is `None` where the surface has no region of that
/// kind (a convex dome has no concave radius).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceAnalysis {
    pub sag_min: Extremum,
    pub sag_max: Extremum,
    /// Steepest slope in any direction: atan |∇z|.
    pub max_slope: Extremum,
    /// Steepest slope along x (atan |∂z/∂x|) and along y.
    pub max_slope_x: Extremum,
    pub max_slope_y: Extremum,
    /// Smallest radius of curvature of the x–z section where it is concave
    /// (curving towards +z, the tool side), and where it is convex.
    pub min_radius_concave_x: Option<Extremum>,
    pub min_radius_convex_x: Option<Extremum>,
    pub min_radius_concave_y: Option<Extremum>,
    pub min_radius_convex_y: Option<Extremum>,
}

impl SurfaceAnalysis {
    /// Peak-to-valley sag (mm).
    pub fn pv(&self) -> f64 {
        self.sag_max.value - self.sag_min.value
    }
}

/// Curvature of the section along x (1/mm): z_xx / (1 + z_x²)^(3/2).
pub fn curvature_x(o: &[f64]) -> f64 {
    o[3] / (1.0 + o[1] * o[1]).powf(1.5)
}

/// Curvature of the section along y (1/mm).
pub fn curvature_y(o: &[f64]) -> f64 {
    o[5] / (1.0 + o[2] * o[2]).powf(1.5)
}

/// What is maximised to find each figure.
#[derive(Clone, Copy)]
enum Metric {
    SagMax,
    SagMin,
    Slope,
    SlopeX,
    SlopeY,
    ConcaveX,
    ConvexX,
    ConcaveY,
    ConvexY,
}

const METRICS: [Metric; 9] = [
    Metric::SagMax,
    Metric::SagMin,
    Metric::Slope,
    Metric::SlopeX,
    Metric::SlopeY,
    Metric::ConcaveX,
    Metric::ConvexX,
    Metric::ConcaveY,
    Metric::ConvexY,
];

impl Metric {
    fn score(self, o: &[f64]) -> f64 {
        match self {
            Metric::SagMax => o[0],
            Metric::SagMin => -o[0],
            Metric::Slope => o[1].hypot(o[2]),
            Metric::SlopeX => o[1].abs(),
            Metric::SlopeY => o[2].abs(),
            Metric::ConcaveX => curvature_x(o),
            Metric::ConvexX => -curvature_x(o),
            Metric::ConcaveY => curvature_y(o),
            Metric::ConvexY => -curvature_y(o),
        }
    }
}

/// Evaluates `f` on an n × n grid over the domain's bounding box, keeping
/// the points inside the domain: (xs, ys, six outputs per point).
pub fn grid(f: &dyn SurfaceFn, domain: &Domain, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let ((x0, x1), (y0, y1)) = domain.bounds();
    grid_in(f, domain, (x0, x1), (y0, y1), n)
}

fn grid_in(
    f: &dyn SurfaceFn,
    domain: &Domain,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    n: usize,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = n.max(2);
    let mut xs = Vec::with_capacity(n * n);
    let mut ys = Vec::with_capacity(n * n);
    for j in 0..n {
        let y = y0 + (y1 - y0) * j as f64 / (n - 1) as f64;
        for i in 0..n {
            let x = x0 + (x1 - x0) * i as f64 / (n - 1) as f64;
            if domain.contains(x, y) {
                xs.push(x);
                ys.push(y);
            }
        }
    }
    let mut out = vec![0.0; 6 * xs.len()];
    f.eval_batch(&xs, &ys, &mut out);
    (xs, ys, out)
}

/// Analyses `f` over `domain` from an n × n grid (n ≥ 2), refining each
/// extremum. Points where the surface is not finite are skipped.
pub fn analyse(f: &dyn SurfaceFn, domain: &Domain, n: usize) -> SurfaceAnalysis {
    let (xs, ys, out) = grid(f, domain, n);
    let ((x0, x1), (y0, y1)) = domain.bounds();
    let cell = (
        (x1 - x0) / (n.max(2) - 1) as f64,
        (y1 - y0) / (n.max(2) - 1) as f64,
    );
    let found = METRICS.map(|m| {
        let mut best: Option<(f64, usize)> = None;
        for i in 0..xs.len() {
            let o = &out[6 * i..6 * i + 6];
            if o.iter().any(|v| !v.is_finite()) {
                continue;
            }
            let s = m.score(o);
            if best.is_none_or(|(b, _)| s > b) {
                best = Some((s, i));
            }
        }
        best.map(|(s, i)| refine(f, domain, m, (s, xs[i], ys[i]), cell))
    });
    let ext = |k: usize, value: fn(f64) -> f64| {
        found[k].map(|(s, x, y)| Extremum {
            value: value(s),
            x,
            y,
        })
    };
    let none = Extremum {
        value: f64::NAN,
        x: f64::NAN,
        y: f64::NAN,
    };
    // A radius exists only where the curvature of that sign is non-zero.
    let radius = |k: usize| {
        found[k]
            .filter(|(s, _, _)| *s > 1e-12)
            .map(|(s, x, y)| Extremum {
                value: 1.0 / s,
                x,
                y,
            })
    };
    SurfaceAnalysis {
        sag_max: ext(0, |s| s).unwrap_or(none),
        sag_min: ext(1, |s| -s).unwrap_or(none),
        max_slope: ext(2, f64::atan).unwrap_or(none),
        max_slope_x: ext(3, f64::atan).unwrap_or(none),
        max_slope_y: ext(4, f64::atan).unwrap_or(none),
        min_radius_concave_x: radius(5),
        min_radius_convex_x: radius(6),
        min_radius_concave_y: radius(7),
        min_radius_convex_y: radius(8),
    }
}

/// Zooms in on an extremum: re-grids a window of ±1 cell around the best
/// point, 9 × 9, shrinking the window fourfold each round.
fn refine(
    f: &dyn SurfaceFn,
    domain: &Domain,
    m: Metric,
    start: (f64, f64, f64),
    cell: (f64, f64),
) -> (f64, f64, f64) {
    let (mut best, mut bx, mut by) = start;
    let (mut hx, mut hy) = cell;
    for _ in 0..12 {
        let (xs, ys, out) = grid_in(f, domain, (bx - hx, bx + hx), (by - hy, by + hy), 9);
        for i in 0..xs.len() {
            let o = &out[6 * i..6 * i + 6];
            if o.iter().all(|v| v.is_finite()) {
                let s = m.score(o);
                if s > best {
                    (best, bx, by) = (s, xs[i], ys[i]);
                }
            }
        }
        hx /= 4.0;
        hy /= 4.0;
    }
    (best, bx, by)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::ir::{Graph, Interpreter, SurfaceTape, Unary};

    /// Seed 002 job 1: z = 0.02 (sin 5x + cos(10y/3)) − 0.04 over
    /// x ∈ [0, 2π], y ∈ [0, 6π]. The paper's figures: minimum radius of
    /// curvature 2 mm, maximum slope 3.81° along y (circumferential, the
    /// cutting direction) and 5.71° along x (axial).
    #[test]
    fn seed_002_pattern_figures() {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let five = g.constant_node(5.0);
        let k = g.constant_node(10.0 / 3.0);
        let a = g.mul(five, x);
        let b = g.mul(k, y);
        let s = g.unary(Unary::Sin, a);
        let c = g.unary(Unary::Cos, b);
        let sum = g.add(s, c);
        let amp = g.constant_node(0.02);
        let wave = g.mul(amp, sum);
        let off = g.constant_node(0.04);
        let z = g.sub(wave, off);
        let f = Interpreter::new(&SurfaceTape::new(g, z));
        let domain = Domain::Rect {
            x: (0.0, 2.0 * std::f64::consts::PI),
            y: (0.0, 6.0 * std::f64::consts::PI),
        };
        let a = analyse(&f, &domain, 201);
        let deg = |r: f64| r.to_degrees();
        assert!(
            (deg(a.max_slope_x.value) - 5.7106).abs() < 1e-3,
            "{}",
            deg(a.max_slope_x.value)
        );
        assert!(
            (deg(a.max_slope_y.value) - 3.8141).abs() < 1e-3,
            "{}",
            deg(a.max_slope_y.value)
        );
        let r_min = [a.min_radius_concave_x, a.min_radius_convex_x]
            .iter()
            .flatten()
            .map(|e| e.value)
            .fold(f64::INFINITY, f64::min);
        assert!((r_min - 2.0).abs() < 1e-6, "{r_min}");
        assert!((a.pv() - 0.08).abs() < 1e-9, "{}", a.pv());
    }
}
