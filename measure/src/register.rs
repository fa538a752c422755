//! Registration: the rigid placement of the measured part against the
//! design surface z = f(x, y) that best explains the measurement.
//!
//! - **A map or a profile** (heights over a grid): least squares on the
//!   heights, by Levenberg–Marquardt (Marquardt's scaling by the normal
//!   matrix's diagonal) with the surface's exact first derivatives from
//!   its kernel. The model of a measured height at (x, y) is
//!   h = f(u, v) + p + t_x·x + t_y·y, with (u, v) the point moved by the
//!   decentre (d_x, d_y) and turned by the clocking γ:
//!   u = cos γ (x − d_x) + sin γ (y − d_y), v = −sin γ (x − d_x) + cos γ (y − d_y).
//!   Tilt is the slope of the plane (rad, small angles: µrad to mrad).
//! - **A point cloud**: iterative closest point, point to plane: each
//!   point's foot on the surface by Newton (exact first and second
//!   derivatives), then the small rotation and translation that minimise
//!   the distances along the normals, until the step vanishes.
//!
//! A parameter the data cannot determine is not fitted, and the result
//! says so: clocking on a surface of revolution (its column vanishes),
//! decentre against tilt on a sphere (one is the other), y on a profile.
//!
//! `register_heights_parallel` evaluates the surface on every core, over
//! fixed chunks of the points; the normal equations are summed on one
//! thread in the points' order, so its registration is `register_heights`'s
//! bit for bit, however many threads there are.

use lensc_runtime::surface::ir::SurfaceFn;
use nalgebra::{DMatrix, DVector};

/// The parameters, in the order of the normal equations.
pub const PARAMETERS: [&str; 6] = [
    "piston",
    "tilt_x",
    "tilt_y",
    "decentre_x",
    "decentre_y",
    "clocking",
];

/// What was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Registration {
    /// mm, rad, rad, mm, mm, rad, in the order of `PARAMETERS`.
    pub values: [f64; 6],
    /// Which were fitted (the others are zero and could not be told from
    /// the data, or were not asked for).
    pub fitted: [bool; 6],
    /// Why each one not fitted was left out.
    pub left_out: Vec<(&'static str, &'static str)>,
    pub iterations: usize,
    /// The method, in words.
    pub method: &'static str,
}

impl Registration {
    pub fn piston(&self) -> f64 {
        self.values[0]
    }
    pub fn tilt(&self) -> (f64, f64) {
        (self.values[1], self.values[2])
    }
    pub fn decentre(&self) -> (f64, f64) {
        (self.values[3], self.values[4])
    }
    pub fn clocking(&self) -> Option<f64> {
        self.fitted[5].then_some(self.values[5])
    }
}

/// Why a registration failed.
#[derive(Clone, Debug, PartialEq)]
pub enum RegisterError {
    /// Fewer valid points than parameters to fit.
    TooFewPoints { points: usize },
    /// The step had not vanished after `iterations`; `rms` is the last
    /// residual (mm).
    NotConverged { iterations: usize, rms: f64 },
    /// The surface has no value at some measured points (outside its domain).
    Undefined { points: usize },
}

/// How hard to try.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    pub max_iterations: usize,
    /// Fit the y parameters (tilt, decentre) and clocking (false for a
    /// profile along x).
    pub two_d: bool,
    /// The placement to start from, in the order of `PARAMETERS` (zero
    /// unless given): a registration carried on from one found before.
    /// Its piston is moved by the mean height difference there first;
    /// a parameter that is not fitted starts (and stays) at zero.
    pub start: [f64; 6],
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_iterations: 60,
            two_d: true,
            start: [0.0; 6],
        }
    }
}

/// The heights the registered design predicts at the points, with the
/// slope of that surface in the measurement's frame: (h, ∂h/∂x, ∂h/∂y).
pub fn predict(f: &dyn SurfaceFn, pts: &[[f64; 3]], p: &[f64; 6]) -> Vec<[f64; 3]> {
    let (xs, ys) = moved(pts, p);
    let mut out = vec![0.0; 6 * pts.len()];
    f.eval_batch(&xs, &ys, &mut out);
    let (s, c) = p[5].sin_cos();
    pts.iter()
        .enumerate()
        .map(|(i, q)| {
            let (fu, fv) = (out[6 * i + 1], out[6 * i + 2]);
            [
                out[6 * i] + p[0] + p[1] * q[0] + p[2] * q[1],
                fu * c - fv * s + p[1],
                fu * s + fv * c + p[2],
            ]
        })
        .collect()
}

/// The design-frame (x, y) of each measured point under the placement
/// `p`: the point moved by the decentre, then turned by the clocking.
pub fn moved(pts: &[[f64; 3]], p: &[f64; 6]) -> (Vec<f64>, Vec<f64>) {
    let (s, c) = p[5].sin_cos();
    pts.iter()
        .map(|q| {
            let (x, y) = (q[0] - p[3], q[1] - p[4]);
            (c * x + s * y, -s * x + c * y)
        })
        .unzip()
}

/// JᵀJ, Jᵀr and Σr².
type Normal = ([[f64; 6]; 6], [f64; 6], f64);

/// Which parameters are fitted, and why the others are not.
type Freedom = ([bool; 6], Vec<(&'static str, &'static str)>);

/// The points a registration moves and evaluates together, on one
/// thread: the chunks are fixed by the points alone, never by the number
/// of threads.
pub const CHUNK: usize = 4096;

/// The surface (six outputs a point) at each point moved by `p`, into
/// `out`, with the moved (u, v): the points' fixed chunks moved and
/// evaluated in parallel. Each point's figures are its own (no sum runs
/// across points), so they are the same bits on one thread or many.
pub fn moved_and_evaluated(
    f: &(dyn SurfaceFn + Sync),
    pts: &[[f64; 3]],
    p: &[f64; 6],
    out: &mut Vec<f64>,
) -> (Vec<f64>, Vec<f64>) {
    use rayon::prelude::*;
    let (mut us, mut vs) = (vec![0.0; pts.len()], vec![0.0; pts.len()]);
    out.resize(6 * pts.len(), 0.0);
    pts.par_chunks(CHUNK)
        .zip(us.par_chunks_mut(CHUNK))
        .zip(vs.par_chunks_mut(CHUNK))
        .zip(out.par_chunks_mut(6 * CHUNK))
        .for_each(|(((q, u), v), o)| {
            // As `moved`, point by point.
            let (s, c) = p[5].sin_cos();
            for (k, q) in q.iter().enumerate() {
                let (x, y) = (q[0] - p[3], q[1] - p[4]);
                (u[k], v[k]) = (c * x + s * y, -s * x + c * y);
            }
            f.eval_batch(u, v, o);
        });
    (us, vs)
}

/// How a registration evaluates the surface at the points moved by a
/// placement: the six outputs a point into the buffer, and the moved
/// (u, v).
type Evaluation<'a> = &'a dyn Fn(&[[f64; 3]], &[f64; 6], &mut Vec<f64>) -> (Vec<f64>, Vec<f64>);

/// The surface at the points moved by `p`, on this thread: one batch.
fn evaluated(
    f: &dyn SurfaceFn,
    pts: &[[f64; 3]],
    p: &[f64; 6],
    out: &mut Vec<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let (us, vs) = moved(pts, p);
    out.resize(6 * pts.len(), 0.0);
    f.eval_batch(&us, &vs, out);
    (us, vs)
}

/// Normal equations at `p`: JᵀJ, Jᵀr and Σr², with J = ∂h/∂p. The sums
/// run over the points in their order on one thread, so the equations
/// are the same bits however the surface was evaluated (`Evaluation`).
fn normal_equations(
    eval: Evaluation,
    pts: &[[f64; 3]],
    p: &[f64; 6],
    buf: &mut Vec<f64>,
) -> Result<Normal, RegisterError> {
    let (us, vs) = eval(pts, p, buf);
    let (s, c) = p[5].sin_cos();
    let mut a = [[0.0; 6]; 6];
    let mut g = [0.0; 6];
    let mut ssr = 0.0;
    let mut undefined = 0;
    for (i, q) in pts.iter().enumerate() {
        let o = &buf[6 * i..6 * i + 3];
        if !(o[0].is_finite() && o[1].is_finite() && o[2].is_finite()) {
            undefined += 1;
            continue;
        }
        let (fu, fv) = (o[1], o[2]);
        let r = q[2] - (o[0] + p[0] + p[1] * q[0] + p[2] * q[1]);
        let j = [
            1.0,
            q[0],
            q[1],
            -fu * c + fv * s,
            -fu * s - fv * c,
            fu * vs[i] - fv * us[i],
        ];
        for m in 0..6 {
            g[m] += j[m] * r;
            for n in m..6 {
                a[m][n] += j[m] * j[n];
            }
        }
        ssr += r * r;
    }
    if undefined > 0 {
        return Err(RegisterError::Undefined { points: undefined });
    }
    let upper = a;
    for (m, row) in a.iter_mut().enumerate() {
        for (n, cell) in row.iter_mut().enumerate().take(m) {
            *cell = upper[n][m];
        }
    }
    Ok((a, g, ssr))
}

/// Which parameters the data can tell apart, from the normal matrix at
/// the start: a vanishing column (clocking on a surface of revolution),
/// then decentre against tilt (a sphere), left out with the reason.
fn determinable(a: &[[f64; 6]; 6], two_d: bool) -> Freedom {
    let mut on = [true, true, two_d, true, two_d, two_d];
    let mut why = Vec::new();
    if !two_d {
        for k in [2, 4, 5] {
            why.push((PARAMETERS[k], "a profile along x has no y"));
        }
    }
    // Clocking: its column against the tilt column's scale.
    if on[5] && a[5][5] <= 1e-20 * a[1][1].max(a[2][2]) * 1e-4 + f64::MIN_POSITIVE {
        on[5] = false;
        why.push((
            "clocking",
            "the surface is one of revolution: turning it changes nothing",
        ));
    }
    let conditioned = |on: &[bool; 6]| -> bool {
        let idx: Vec<usize> = (0..6).filter(|k| on[*k]).collect();
        let n = idx.len();
        let m = DMatrix::from_fn(n, n, |i, j| {
            a[idx[i]][idx[j]] / (a[idx[i]][idx[i]] * a[idx[j]][idx[j]]).sqrt()
        });
        let e = m.symmetric_eigen();
        e.eigenvalues.iter().cloned().fold(f64::INFINITY, f64::min) > 1e-9
    };
    if !conditioned(&on) && on[5] {
        let mut without = on;
        without[5] = false;
        if conditioned(&without) {
            on[5] = false;
            why.push((
                "clocking",
                "it cannot be told from the other parameters on this surface",
            ));
        }
    }
    if !conditioned(&on) {
        on[3] = false;
        why.push((
            "decentre_x",
            "the measured points cannot tell it from tilt (on a paraboloid, or over too small a field, a decentre is a tilt)",
        ));
        if two_d {
            on[4] = false;
            why.push(("decentre_y", "the measured points cannot tell it from tilt (on a paraboloid, or over too small a field, a decentre is a tilt)"));
        }
    }
    (on, why)
}

/// Solves (A + λ·diag A) δ = g over the active parameters.
fn damped_step(a: &[[f64; 6]; 6], g: &[f64; 6], lambda: f64, on: &[bool; 6]) -> Option<[f64; 6]> {
    let idx: Vec<usize> = (0..6).filter(|k| on[*k]).collect();
    let n = idx.len();
    let m = DMatrix::from_fn(n, n, |i, j| {
        a[idx[i]][idx[j]]
            + if i == j {
                lambda * a[idx[i]][idx[i]]
            } else {
                0.0
            }
    });
    let b = DVector::from_fn(n, |i, _| g[idx[i]]);
    let x = m.cholesky()?.solve(&b);
    let mut out = [0.0; 6];
    for (i, k) in idx.iter().enumerate() {
        out[*k] = x[i];
    }
    Some(out)
}

/// Registers heights measured at points (x, y, z, mm) to the surface by
/// Levenberg–Marquardt.
pub fn register_heights(
    f: &dyn SurfaceFn,
    pts: &[[f64; 3]],
    opts: Options,
) -> Result<Registration, RegisterError> {
    levenberg_marquardt(&|q, p, out| evaluated(f, q, p, out), pts, opts)
}

/// `register_heights` with the surface evaluated on every core, the
/// points in fixed chunks (`moved_and_evaluated`): the same registration,
/// bit for bit, however many threads there are.
pub fn register_heights_parallel(
    f: &(dyn SurfaceFn + Sync),
    pts: &[[f64; 3]],
    opts: Options,
) -> Result<Registration, RegisterError> {
    levenberg_marquardt(&|q, p, out| moved_and_evaluated(f, q, p, out), pts, opts)
}

/// `register_heights`, the surface evaluated by `eval`.
fn levenberg_marquardt(
    eval: Evaluation,
    pts: &[[f64; 3]],
    opts: Options,
) -> Result<Registration, RegisterError> {
    let requested = if opts.two_d { 6 } else { 3 };
    if pts.len() <= requested {
        return Err(RegisterError::TooFewPoints { points: pts.len() });
    }
    let mut buf = Vec::new();
    let mut p = opts.start;
    // The piston to start from: the mean height difference.
    let (a0, g0, _) = normal_equations(eval, pts, &p, &mut buf)?;
    let (on, left_out) = determinable(&a0, opts.two_d);
    p[0] += g0[0] / a0[0][0];
    for k in 1..6 {
        if !on[k] {
            p[k] = 0.0;
        }
    }
    let (mut a, mut g, mut ssr) = normal_equations(eval, pts, &p, &mut buf)?;
    // The registration at `p` after `it` iterations.
    let found = |p: [f64; 6], it: usize| Registration {
        values: p,
        fitted: on,
        left_out: left_out.clone(),
        iterations: it,
        method: "least squares on the heights (Levenberg-Marquardt, exact surface derivatives)",
    };
    let mut lambda = 1e-4;
    for it in 1..=opts.max_iterations {
        let Some(step) = damped_step(&a, &g, lambda, &on) else {
            lambda *= 10.0;
            continue;
        };
        let mut trial = p;
        for k in 0..6 {
            trial[k] += step[k];
        }
        let (ta, tg, tssr) = normal_equations(eval, pts, &trial, &mut buf)?;
        if tssr <= ssr {
            let small = step_vanished(&step, &p, pts);
            p = trial;
            (a, g) = (ta, tg);
            let gain = ssr - tssr;
            ssr = tssr;
            lambda = (lambda / 10.0).max(1e-12);
            if small || gain <= 1e-15 * ssr + f64::MIN_POSITIVE {
                return Ok(found(p, it));
            }
        } else {
            // A step that moves nothing that matters, or leaves the sum
            // within rounding of the best, and still does not lower it:
            // the best is the minimum as far as the sums can tell (more
            // damping would only try smaller steps of the same).
            if step_vanished(&step, &p, pts) || tssr - ssr <= 1e-15 * ssr + f64::MIN_POSITIVE {
                return Ok(found(p, it));
            }
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    Err(RegisterError::NotConverged {
        iterations: opts.max_iterations,
        rms: (ssr / pts.len() as f64).sqrt(),
    })
}

/// Whether a step moved nothing that matters: 1e-7 nm of piston or
/// decentre, 1e-7 nm over the measured extent of tilt or clocking.
fn step_vanished(step: &[f64; 6], _p: &[f64; 6], pts: &[[f64; 3]]) -> bool {
    let extent = pts
        .iter()
        .map(|q| q[0].abs().max(q[1].abs()))
        .fold(1e-3, f64::max);
    let tol = 1e-13; // mm
    step[0].abs() < tol
        && step[1].abs() * extent < tol
        && step[2].abs() * extent < tol
        && step[3].abs() < tol
        && step[4].abs() < tol
        && step[5].abs() * extent < tol
}

/// The foot of the normal from `q` onto z = f(x, y), by Newton on the
/// squared distance (exact first and second derivatives); `None` when
/// Newton does not settle.
pub fn foot(f: &dyn SurfaceFn, q: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
    let (mut u, mut v) = (q[0], q[1]);
    for _ in 0..30 {
        let o = f.eval(u, v);
        let (z, fu, fv, fuu, fuv, fvv) = (o[0], o[1], o[2], o[3], o[4], o[5]);
        let dz = z - q[2];
        // gradient and Hessian of ½|(u,v,f) − q|²
        let gu = (u - q[0]) + dz * fu;
        let gv = (v - q[1]) + dz * fv;
        let huu = 1.0 + fu * fu + dz * fuu;
        let hvv = 1.0 + fv * fv + dz * fvv;
        let huv = fu * fv + dz * fuv;
        let det = huu * hvv - huv * huv;
        if !(det.is_finite() && det > 0.0) {
            return None;
        }
        let du = (hvv * gu - huv * gv) / det;
        let dv = (huu * gv - huv * gu) / det;
        u -= du;
        v -= dv;
        if du.abs() < 1e-14 && dv.abs() < 1e-14 {
            let o = f.eval(u, v);
            let norm = (1.0 + o[1] * o[1] + o[2] * o[2]).sqrt();
            return Some(([u, v, o[0]], [-o[1] / norm, -o[2] / norm, 1.0 / norm]));
        }
    }
    None
}

/// Registers a point cloud (x, y, z, mm) by iterative closest point, point
/// to plane. The result is stated as the map's parameters: the
/// translation's z is the piston, x and y the decentre, the rotations
/// about x and y the tilt (slopes, for small angles), about z the
/// clocking.
pub fn register_cloud(
    f: &dyn SurfaceFn,
    pts: &[[f64; 3]],
    opts: Options,
) -> Result<Registration, RegisterError> {
    // The transform applied to the points: rotation R (3×3) and translation t.
    let mut r = nalgebra::Matrix3::<f64>::identity();
    let mut t = nalgebra::Vector3::<f64>::zeros();
    let mut on: Option<Freedom> = None;
    if pts.len() <= if opts.two_d { 6 } else { 3 } {
        return Err(RegisterError::TooFewPoints { points: pts.len() });
    }
    for it in 1..=opts.max_iterations {
        let mut a = [[0.0; 6]; 6];
        let mut g = [0.0; 6];
        let mut missed = 0;
        for q in pts {
            let p = r * nalgebra::Vector3::new(q[0], q[1], q[2]) + t;
            let Some((s, n)) = foot(f, [p.x, p.y, p.z]) else {
                missed += 1;
                continue;
            };
            let n = nalgebra::Vector3::new(n[0], n[1], n[2]);
            let d = (p - nalgebra::Vector3::new(s[0], s[1], s[2])).dot(&n);
            let pxn = p.cross(&n);
            // unknowns in the order of PARAMETERS: t_z, ω_y, ω_x, t_x, t_y, ω_z
            let j = [n.z, -pxn.y, -pxn.x, n.x, n.y, pxn.z];
            for m in 0..6 {
                g[m] -= j[m] * d;
                for k in 0..6 {
                    a[m][k] += j[m] * j[k];
                }
            }
        }
        if missed > 0 {
            return Err(RegisterError::Undefined { points: missed });
        }
        let (active, _) = on.get_or_insert_with(|| determinable(&a, opts.two_d));
        let Some(step) = damped_step(&a, &g, 1e-12, active) else {
            break;
        };
        // ω = (−step[2], −step[1], step[5]) so that the signs match the
        // map's tilts (a tilt t_x raises +x: rotation about −y).
        let w = nalgebra::Vector3::new(-step[2], -step[1], step[5]);
        let dr = nalgebra::Rotation3::new(w).into_inner();
        r = dr * r;
        t = dr * t + nalgebra::Vector3::new(step[3], step[4], step[0]);
        if step_vanished(&step, &[0.0; 6], pts) {
            // The measured part = the inverse of what was applied.
            let ri = r.transpose();
            let ti = -(ri * t);
            let (active, left_out) = on.expect("set on the first pass");
            let values = [
                ti.z,
                ri[(2, 0)] / ri[(2, 2)],
                ri[(2, 1)] / ri[(2, 2)],
                ti.x,
                ti.y,
                ri[(1, 0)].atan2(ri[(0, 0)]),
            ];
            let mut v = values;
            for k in 0..6 {
                if !active[k] {
                    v[k] = 0.0;
                }
            }
            return Ok(Registration {
                values: v,
                fitted: active,
                left_out,
                iterations: it,
                method: "iterative closest point, point to plane (exact surface derivatives)",
            });
        }
    }
    Err(RegisterError::NotConverged {
        iterations: opts.max_iterations,
        rms: f64::NAN,
    })
}

#[cfg(test)]
pub(crate) mod tests;
