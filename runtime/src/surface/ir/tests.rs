//! Tests of the surface IR and its interpreter.

use super::*;

#[test]
fn builds_deduplicate_and_fold() {
    let mut g = Graph::new();
    let x = g.x();
    let y = g.y();
    let a = g.add(x, y);
    let b = g.add(y, x);
    assert_eq!(a, b, "commutative operands are ordered");
    let two = g.constant_node(2.0);
    let three = g.constant_node(3.0);
    let six = g.mul(two, three);
    assert_eq!(g.constant(six), Some(6.0));
    let zero = g.constant_node(0.0);
    assert_eq!(g.add(x, zero), x);
    assert_eq!(g.mul(x, zero), zero);
    let nx = g.neg(x);
    assert_eq!(g.neg(nx), x);
}

/// Central differences of the interpreter's own z and first derivatives.
fn check_against_finite_differences(build: impl Fn(&mut Graph) -> Id, pts: &[(f64, f64)]) {
    let mut g = Graph::new();
    let z = build(&mut g);
    let tape = SurfaceTape::new(g, z);
    let f = Interpreter::new(&tape);
    let h = 1e-5;
    for &(x, y) in pts {
        let o = f.eval(x, y);
        let px = f.eval(x + h, y);
        let mx = f.eval(x - h, y);
        let py = f.eval(x, y + h);
        let my = f.eval(x, y - h);
        let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * (1.0 + a.abs());
        assert!(
            close(o[1], (px[0] - mx[0]) / (2.0 * h), 1e-8),
            "dz/dx at {x},{y}: {} vs fd {}",
            o[1],
            (px[0] - mx[0]) / (2.0 * h)
        );
        assert!(
            close(o[2], (py[0] - my[0]) / (2.0 * h), 1e-8),
            "dz/dy at {x},{y}"
        );
        assert!(
            close(o[3], (px[1] - mx[1]) / (2.0 * h), 1e-7),
            "d2z/dx2 at {x},{y}"
        );
        assert!(
            close(o[4], (py[1] - my[1]) / (2.0 * h), 1e-7),
            "d2z/dxdy at {x},{y}"
        );
        assert!(
            close(o[5], (py[2] - my[2]) / (2.0 * h), 1e-7),
            "d2z/dy2 at {x},{y}"
        );
    }
}

#[test]
fn derivatives_of_every_operation_agree_with_finite_differences() {
    let pts = [(0.3, 0.2), (0.7, -0.4), (-0.5, 0.6)];
    check_against_finite_differences(
        |g| {
            let (x, y) = (g.x(), g.y());
            let s = g.unary(Unary::Sin, x);
            let c = g.unary(Unary::Cos, y);
            let t = g.unary(Unary::Tan, x);
            let xy = g.mul(x, y);
            let e = g.unary(Unary::Exp, xy);
            let sum = g.add(s, c);
            let sum = g.add(sum, t);
            g.add(sum, e)
        },
        &pts,
    );
    check_against_finite_differences(
        |g| {
            let (x, y) = (g.x(), g.y());
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let r2 = g.add(x2, y2);
            let one = g.constant_node(1.0);
            let u = g.add(one, r2);
            let s = g.sqrt(u);
            let l = g.unary(Unary::Ln, u);
            let q = g.div(s, l);
            let at = g.binary(Binary::Atan2, y, x);
            let h = g.constant_node(0.5);
            let xh = g.mul(x, h);
            let asn = g.unary(Unary::Asin, xh);
            let acs = g.unary(Unary::Acos, xh);
            let atn = g.unary(Unary::Atan, y);
            let p = g.binary(Binary::Pow, u, xh);
            let d = xy_minus(g);
            let ab = g.unary(Unary::Abs, d);
            let mn = g.binary(Binary::Min, x, y);
            let mx = g.binary(Binary::Max, x2, y);
            let mut acc = q;
            for t in [at, asn, acs, atn, p, ab, mn, mx] {
                acc = g.add(acc, t);
            }
            acc
        },
        &pts,
    );
}

fn xy_minus(g: &mut Graph) -> Id {
    let (x, y) = (g.x(), g.y());
    g.sub(x, y)
}

#[test]
fn tan_plus_sin() {
    let mut g = Graph::new();
    let x = g.x();
    let t = g.unary(Unary::Tan, x);
    let s = g.unary(Unary::Sin, x);
    let z = g.add(s, t);
    let f = Interpreter::new(&SurfaceTape::new(g, z));
    let o = f.eval(0.3, 0.0);
    let want = 0.3f64.cos() + 1.0 / 0.3f64.cos().powi(2);
    assert!((o[1] - want).abs() < 1e-14, "{} vs {want}", o[1]);
}

#[test]
fn paraboloid_outputs_are_exact() {
    // z = (x² + y²)/(2R): dz/dx = x/R, d²z/dx² = 1/R, d²z/dxdy = 0.
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let r2 = {
        let a = g.powi(x, 2);
        let b = g.powi(y, 2);
        g.add(a, b)
    };
    let two_r = g.constant_node(8.0);
    let z = g.div(r2, two_r);
    let f = Interpreter::new(&SurfaceTape::new(g, z));
    let o = f.eval(1.2, -0.4);
    let want = [
        (1.2f64 * 1.2 + 0.4 * 0.4) / 8.0,
        1.2 / 4.0,
        -0.4 / 4.0,
        0.25,
        0.0,
        0.25,
    ];
    for (a, b) in o.iter().zip(want) {
        assert!((a - b).abs() <= 1e-16, "{o:?} vs {want:?}");
    }
}
