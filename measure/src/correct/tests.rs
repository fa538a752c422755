use super::*;
use lensc_runtime::surface::ir::{Interpreter, SurfaceFn, SurfaceTape};

/// A radial error made of known terms is fitted back to them, its piston
/// left out of the correction.
#[test]
fn a_radial_error_is_fitted_to_its_terms() {
    let basis = Basis::radial(2.0, 0.5); // order 8
    assert_eq!(basis.order(), 8);
    let truth = |x: f64, y: f64| {
        let t = 2.0 * (x * x + y * y) / 4.0 - 1.0;
        let p = legendre(t, 8);
        4e-6 + 3e-5 * p[2] - 1e-5 * p[5] + 2e-6 * p[8]
    };
    let mut xy = Vec::new();
    let mut e = Vec::new();
    for j in 0..101 {
        for i in 0..101 {
            let (x, y) = (-2.0 + 0.04 * i as f64, -2.0 + 0.04 * j as f64);
            if x * x + y * y <= 4.0 {
                xy.push((x, y));
                e.push(truth(x, y));
            }
        }
    }
    let cells = bin(&basis, &xy, &e, 0.002);
    let c = fit(basis, &cells).expect("fits");
    let want = [0.0, 0.0, 3e-5, 0.0, 0.0, -1e-5, 0.0, 0.0, 2e-6];
    // Within 2e-9 mm (0.002 nm): a ring's mean error is not the error at
    // its mean radius, to second order in the ring's 2 µm width.
    for (k, (got, want)) in c.coefficients.iter().zip(want).enumerate() {
        assert!((got - want).abs() < 2e-9, "term {k}: {got} vs {want}");
    }
    assert!(c.fit_residual_rms < 1e-9, "{}", c.fit_residual_rms);
    // The correction is the error less its piston, everywhere.
    assert!((c.at(0.7, -1.1) - (truth(0.7, -1.1) - 4e-6)).abs() < 1e-8);
}

/// A map's error is fitted with its piston and tilts left out; ripple
/// shorter than the smoothing length is not followed.
#[test]
fn a_map_error_is_fitted_without_placement_and_without_short_ripple() {
    let basis = Basis::map((-1.0, 1.0), (-1.0, 1.0), 0.5); // order 4
    assert_eq!(basis.order(), 4);
    let form = |x: f64, y: f64| 2e-5 * (x * x - y * y) + 1e-5 * x * y * y;
    let ripple = |x: f64, _y: f64| 1e-6 * (2.0 * std::f64::consts::PI * x / 0.05).sin();
    let mut xy = Vec::new();
    let mut e = Vec::new();
    for j in 0..201 {
        for i in 0..201 {
            let (x, y) = (-1.0 + 0.01 * i as f64, -1.0 + 0.01 * j as f64);
            xy.push((x, y));
            e.push(3e-6 + 1e-5 * x - 2e-5 * y + form(x, y) + ripple(x, y));
        }
    }
    let cells = bin(&basis, &xy, &e, 0.01);
    let c = fit(basis, &cells).expect("fits");
    for (x, y) in [(0.3, -0.4), (-0.9, 0.8), (0.0, 0.0)] {
        // x·y² = x·(2 P2(y) + 1)/3 holds a tilt x/3, left out with the
        // others; differences from the centre leave out the piston.
        let kept = |x: f64, y: f64| form(x, y) - 1e-5 / 3.0 * x;
        let want = kept(x, y) - kept(0.0, 0.0);
        let got = c.at(x, y) - c.at(0.0, 0.0);
        assert!((got - want).abs() < 3e-8, "({x}, {y}): {got} vs {want}");
    }
    // The ripple (50 µm period, a tenth of the smoothing length) is left.
    assert!(
        (c.fit_residual_rms - 1e-6 / 2f64.sqrt()).abs() < 5e-8,
        "{}",
        c.fit_residual_rms
    );
}

/// Too few cells for the terms: no fit rather than a made-up one.
#[test]
fn too_few_cells_is_no_fit() {
    let basis = Basis::radial(1.0, 0.1); // order 20: 21 terms
    let cells: Vec<_> = (0..10).map(|k| (0.1 * k as f64, 0.0, 0.0, 1.0)).collect();
    assert!(fit(basis, &cells).is_none());
}

fn tapes(c: &Correction) -> SurfaceTape {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = c.node(&mut g, x, y, 0.7);
    SurfaceTape::new(g, z)
}

fn sample_correction(basis: Basis) -> Correction {
    let n = basis.terms().len();
    let coefficients = (0..n)
        .map(|k| {
            if basis.is_placement(basis.terms()[k]) {
                0.0
            } else {
                1e-5 / (1.0 + k as f64)
            }
        })
        .collect();
    Correction {
        basis,
        coefficients,
        fit_residual_rms: 0.0,
        cells: 0,
    }
}

/// The IR of a correction computes what `at` computes, and its
/// derivatives agree with finite differences of it.
#[test]
fn the_ir_is_the_polynomial_with_its_derivatives() {
    for basis in [
        Basis::radial(1.5, 0.1),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
    ] {
        let c = sample_correction(basis);
        let f = Interpreter::new(&tapes(&c));
        for (x, y) in [(0.3, -0.2), (-0.9, 0.4), (1.1, 0.9), (0.0, 0.0)] {
            let o = f.eval(x, y);
            let want = 0.7 * c.at(x, y);
            assert!(
                (o[0] - want).abs() <= 1e-13 * want.abs().max(1e-6),
                "{basis:?} z at ({x}, {y}): {} vs {want}",
                o[0]
            );
            let h = 1e-5;
            let at = |x: f64, y: f64| 0.7 * c.at(x, y);
            let fd = [
                (at(x + h, y) - at(x - h, y)) / (2.0 * h),
                (at(x, y + h) - at(x, y - h)) / (2.0 * h),
                (at(x + h, y) - 2.0 * at(x, y) + at(x - h, y)) / (h * h),
                (at(x + h, y + h) - at(x + h, y - h) - at(x - h, y + h) + at(x - h, y - h))
                    / (4.0 * h * h),
                (at(x, y + h) - 2.0 * at(x, y) + at(x, y - h)) / (h * h),
            ];
            for k in 0..5 {
                let tol = if k < 2 { 1e-9 } else { 1e-4 };
                assert!(
                    (o[k + 1] - fd[k]).abs() <= tol * (1.0 + fd[k].abs()),
                    "{basis:?} output {} at ({x}, {y}): {} vs {}",
                    k + 1,
                    o[k + 1],
                    fd[k]
                );
            }
        }
    }
}

/// The JIT and the interpreter agree on a correction's tape (the
/// conformance rule every surface is held to: 1e-13 relative).
#[test]
fn jit_and_interpreter_agree() {
    use lensc_runtime::surface::jit::JitSurface;
    for basis in [
        Basis::radial(1.5, 0.08),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
    ] {
        let c = sample_correction(basis);
        let tape = tapes(&c);
        let i = Interpreter::new(&tape);
        let j = JitSurface::compile(&tape).expect("compiles");
        let xs: Vec<f64> = (0..97).map(|k| -1.0 + 0.021 * k as f64).collect();
        let ys: Vec<f64> = (0..97).map(|k| 1.4 - 0.019 * k as f64).collect();
        let (mut a, mut b) = (vec![0.0; 6 * 97], vec![0.0; 6 * 97]);
        i.eval_batch(&xs, &ys, &mut a);
        j.eval_batch(&xs, &ys, &mut b);
        for (k, (a, b)) in a.iter().zip(&b).enumerate() {
            let scale = a.abs().max(b.abs()).max(1e-300);
            assert!(
                (a - b).abs() <= 1e-13 * scale.max(1e-6),
                "{basis:?} value {k}: {a} vs {b}"
            );
        }
    }
}

/// `at` is the dot product of the terms' values (`Basis::values`) with
/// the coefficients, bit for bit, for both bases up to their highest
/// orders.
#[test]
fn at_is_the_terms_dot_the_coefficients() {
    for basis in [
        Basis::radial(1.5, 0.08),
        Basis::radial(1.5, 1e-3),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 1e-3),
    ] {
        let c = sample_correction(basis);
        let mut row = Vec::new();
        for k in 0..50 {
            let (x, y) = (-1.0 + 0.06 * k as f64, 1.5 - 0.04 * k as f64);
            basis.values(x, y, &mut row);
            let want: f64 = row.iter().zip(&c.coefficients).map(|(a, c)| a * c).sum();
            assert_eq!(
                c.at(x, y).to_bits(),
                want.to_bits(),
                "{basis:?} at ({x}, {y})"
            );
        }
    }
}

/// Along any line, the correction `along` it agrees with `at` at every
/// point to 1e-12 of the correction's largest value, for both bases at
/// their highest orders, lines through the centre (a lathe's rays) and
/// off it (a raster's rows, a window away from the centre).
#[test]
fn along_a_line_is_the_correction_at_its_points() {
    for basis in [
        Basis::radial(1.5, 0.08),
        Basis::radial(1.5, 1e-3),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 1e-3),
        Basis::map((20.0, 30.0), (-5.0, 5.0), 1.0),
    ] {
        let c = sample_correction(basis);
        let ((x0, x1), (y0, y1)) = match basis {
            Basis::Radial { radius, .. } => ((-radius, radius), (-radius, radius)),
            Basis::Map { centre, half, .. } => (
                (centre.0 - half.0, centre.0 + half.0),
                (centre.1 - half.1, centre.1 + half.1),
            ),
        };
        let mut points = Vec::new();
        for k in 0..400 {
            let (x, y) = (
                x0 + (x1 - x0) * (k % 20) as f64 / 19.0,
                y0 + (y1 - y0) * (k / 20) as f64 / 19.0,
            );
            points.push((x, y));
        }
        let largest = points
            .iter()
            .map(|&(x, y)| c.at(x, y).abs())
            .fold(0.0, f64::max);
        let mid = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let lines = [
            // A lathe's ray at 0.7 rad, from the axis (the centre).
            (mid, (0.7f64.cos(), 0.7f64.sin())),
            // A raster's column (x fixed, t = y) and row (t = x).
            ((x0 + 0.3 * (x1 - x0), 0.0), (0.0, 1.0)),
            ((0.0, y0 + 0.8 * (y1 - y0)), (1.0, 0.0)),
            // Askew through the middle, parameter scaled.
            (mid, (0.3, -0.2)),
        ];
        for (origin, dir) in lines {
            let along = c.along(origin, dir);
            let mut checked = 0;
            // The line's point nearest the middle of the box.
            let len2 = dir.0 * dir.0 + dir.1 * dir.1;
            let tc = ((mid.0 - origin.0) * dir.0 + (mid.1 - origin.1) * dir.1) / len2;
            for k in 0..=200 {
                // Over the aperture's span along the line, and past it.
                let t = tc - (x1 - x0).max(y1 - y0) / len2.sqrt() * (1.0 - k as f64 / 100.0);
                let (x, y) = (origin.0 + t * dir.0, origin.1 + t * dir.1);
                if x < x0 || x > x1 || y < y0 || y > y1 {
                    continue;
                }
                let (got, want) = (along.at(t), c.at(x, y));
                assert!(
                    (got - want).abs() <= 1e-12 * largest,
                    "{basis:?} along {origin:?} + t {dir:?} at t = {t}: {got} vs {want}"
                );
                checked += 1;
            }
            assert!(
                checked >= 20,
                "{basis:?} along {origin:?}: {checked} points"
            );
        }
    }
}

/// A correction's section along a ray from the origin (`Rays::section`)
/// is the correction there, and its derivatives along the ray are the
/// IR's exact ones projected on the ray (value, slope and curvature to
/// 1e-8 of their size and the correction's: 1e-7 nm here; a radial
/// term of order 12 is of degree 24 in the radius, its powers cancel to
/// about 1e-10 of the second derivative), at angles all round, for both bases at their
/// highest orders and a map centred off the origin; a map centred beyond
/// its half-widths has none.
#[test]
fn a_section_along_a_ray_is_the_correction_and_its_derivatives_there() {
    for basis in [
        Basis::radial(1.5, 1e-3),
        Basis::map((-1.5, 1.5), (-1.5, 1.5), 1e-3),
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
    ] {
        let c = sample_correction(basis);
        let rays = c.rays().expect("a centre within the half-widths");
        let f = Interpreter::new(&tapes(&c));
        let mut checked = 0;
        for k in 0..24 {
            let theta = 0.3 + k as f64 * std::f64::consts::TAU / 24.0;
            let (cos, sin) = (theta.cos(), theta.sin());
            let mut a = [0.0; ALONG_TERMS];
            let terms = rays.section(cos, sin, 0.7, &mut a);
            for i in 0..15 {
                let u = 0.1 * i as f64;
                // Horner, value and derivatives, as the planner's
                // `RaySection::at` takes them.
                let (mut v, mut d, mut dd) = (0.0, 0.0, 0.0);
                for &a in a[..terms].iter().rev() {
                    dd = dd * u + 2.0 * d;
                    d = d * u + v;
                    v = v * u + a;
                }
                let o = f.eval(u * cos, u * sin);
                let want = [
                    o[0],
                    o[1] * cos + o[2] * sin,
                    o[3] * cos * cos + 2.0 * o[4] * cos * sin + o[5] * sin * sin,
                ];
                assert!(
                    (v - 0.7 * c.at(u * cos, u * sin)).abs() <= 1e-8 * 1e-5,
                    "{basis:?} value at u = {u}, θ = {theta}"
                );
                for (k, (got, want)) in [v, d, dd].into_iter().zip(want).enumerate() {
                    assert!(
                        (got - want).abs() <= 1e-8 * (1e-5 + want.abs()),
                        "{basis:?} output {k} at u = {u}, θ = {theta}: {got} vs {want}"
                    );
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 24 * 15);
    }
    let far = sample_correction(Basis::map((10.0, 12.0), (-1.0, 1.0), 0.3));
    assert!(far.rays().is_none());
}

/// `nodes` (Horner's rule on monomials, its derivatives its own) computes
/// what `node` and the graph's derivatives of it compute, to 1e-12 of the
/// largest of each output over the points, on the JIT as on the
/// interpreter's; and its tape is smaller.
#[test]
fn the_correction_by_horner_is_the_legendre_sum_with_its_derivatives() {
    for basis in [
        Basis::map((-1.0, 2.0), (-0.5, 1.5), 0.3),
        Basis::map((-5.0, 5.0), (-5.0, 5.0), 1.0),
        Basis::map((-3.0, 3.0), (-2.0, 2.0), 0.1),
        Basis::radial(1.5, 0.1),
    ] {
        let c = sample_correction(basis);
        let legendre = tapes(&c);
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let outputs = c.nodes(&mut g, x, y, 0.7);
        let horner = SurfaceTape::with_outputs(g, outputs);
        let (fl, fh) = (Interpreter::new(&legendre), Interpreter::new(&horner));
        let pts: Vec<(f64, f64)> = (0..200)
            .map(|k| {
                let t = k as f64 / 199.0;
                let (x, y) = match basis {
                    Basis::Map { centre, half, .. } => (
                        centre.0 + half.0 * (2.0 * t - 1.0),
                        centre.1 + half.1 * (2.0 * ((7.0 * t) % 1.0) - 1.0),
                    ),
                    Basis::Radial { radius, .. } => (radius * t * 0.7, radius * t * 0.7),
                };
                (x, y)
            })
            .collect();
        let (want, got): (Vec<[f64; 6]>, Vec<[f64; 6]>) = pts
            .iter()
            .map(|&(x, y)| (fl.eval(x, y), fh.eval(x, y)))
            .unzip();
        for k in 0..6 {
            let largest = want.iter().map(|o| o[k].abs()).fold(0.0, f64::max);
            for (w, h) in want.iter().zip(&got) {
                assert!(
                    (w[k] - h[k]).abs() <= 1e-12 * largest,
                    "{basis:?} output {k}: {} vs {}",
                    h[k],
                    w[k]
                );
            }
        }
        if matches!(basis, Basis::Map { .. }) {
            let live = |t: &SurfaceTape| t.graph.nodes().len();
            assert!(
                live(&horner) < live(&legendre),
                "{basis:?}: {} nodes against {}",
                live(&horner),
                live(&legendre)
            );
        }
    }
}
