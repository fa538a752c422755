//! Lowering checked surfaces to the runtime's expression IR: the height
//! z(x, y) in mm as a `SurfaceTape` (with its exact derivatives) and the
//! domain it is defined on.

use lensc_grammar::ast::{BinaryOp, Expr, ExprKind, UnaryOp};
use lensc_runtime::analysis::Domain;
use lensc_runtime::ir::{Binary, Graph, Id, SurfaceTape, Unary, Var};

use crate::check::aperture_radius;
use crate::units;
use crate::value::{self, Formula, Object, Value};

/// A surface ready to evaluate.
pub struct LoweredSurface {
    pub tape: SurfaceTape,
    pub domain: Domain,
}

/// Why a checked surface cannot be lowered (yet).
#[derive(Debug, PartialEq)]
pub enum LowerError {
    /// The kind (or a part of it) has no IR lowering yet.
    Unsupported(&'static str),
    /// The aperture or domain is of a shape the surface cannot use.
    Aperture(&'static str),
}

/// Lowers a checked surface object.
pub fn lower_surface(o: &Object) -> Result<LoweredSurface, LowerError> {
    let f = &o.fields;
    match o.kind.name {
        "sphere" | "conic" | "asphere" => {
            let ap =
                value::object(f, "aperture").ok_or(LowerError::Aperture("missing aperture"))?;
            let domain = domain_of(ap)?;
            let radius = value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?;
            let k = value::num(f, "conic").unwrap_or(0.0);
            let sign = if value::word(f, "sense") == Some("convex") {
                -1.0
            } else {
                1.0
            };
            let terms: Vec<(u32, f64)> = (1..=20u32)
                .filter_map(|j| value::num(f, &format!("A{j}")).map(|a| (j, a)))
                .collect();
            let mut g = Graph::new();
            let z = rotational_sag(&mut g, radius, k, &terms, sign);
            Ok(LoweredSurface {
                tape: SurfaceTape::new(g, z),
                domain,
            })
        }
        "freeform" => {
            let dom = value::object(f, "domain").ok_or(LowerError::Aperture("missing domain"))?;
            let domain = domain_of(dom)?;
            let Some(Value::Formula(formula)) = value::field(f, "z").map(|fl| &fl.value) else {
                return Err(LowerError::Unsupported("freeform without a formula"));
            };
            let mut g = Graph::new();
            let z = lower_formula(&mut g, formula);
            Ok(LoweredSurface {
                tape: SurfaceTape::new(g, z),
                domain,
            })
        }
        other => Err(LowerError::Unsupported(other)),
    }
}

fn domain_of(ap: &Object) -> Result<Domain, LowerError> {
    match ap.kind.name {
        "circle" => aperture_radius(ap)
            .map(|radius| Domain::Circle { radius })
            .ok_or(LowerError::Aperture("circle")),
        "rect" => match (value::range(&ap.fields, "x"), value::range(&ap.fields, "y")) {
            (Some(x), Some(y)) => Ok(Domain::Rect { x, y }),
            _ => Err(LowerError::Aperture("rect")),
        },
        _ => Err(LowerError::Aperture("unknown aperture")),
    }
}

/// z = s · (c r² / (1 + sqrt(1 − (1+k) c² r²)) + Σ A_j (r²)^(j/2)), written
/// in r² = x² + y² so it is smooth through the axis.
pub fn rotational_sag(g: &mut Graph, radius: f64, k: f64, terms: &[(u32, f64)], sign: f64) -> Id {
    let (x, y) = (g.x(), g.y());
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let r2 = g.add(x2, y2);
    let c = 1.0 / radius;
    let cr2 = {
        let cc = g.constant_node(c);
        g.mul(cc, r2)
    };
    let root = {
        let q = g.constant_node((1.0 + k) * c * c);
        let qr2 = g.mul(q, r2);
        let one = g.constant_node(1.0);
        let u = g.sub(one, qr2);
        g.sqrt(u)
    };
    let one = g.constant_node(1.0);
    let den = g.add(one, root);
    let mut sag = g.div(cr2, den);
    for &(j, a) in terms {
        let t = if j % 2 == 0 {
            g.powi(r2, (j / 2) as i32)
        } else {
            let half = g.constant_node(f64::from(j) / 2.0);
            g.binary(Binary::Pow, r2, half)
        };
        let ac = g.constant_node(a);
        let term = g.mul(ac, t);
        sag = g.add(sag, term);
    }
    let s = g.constant_node(sign);
    g.mul(s, sag)
}

/// Lowers a checked formula body (in base units: mm and rad).
pub fn lower_formula(g: &mut Graph, f: &Formula) -> Id {
    lower_expr(g, f, &f.body)
}

fn lower_expr(g: &mut Graph, f: &Formula, e: &Expr) -> Id {
    match &e.kind {
        ExprKind::Quantity { value, unit } => {
            let factor: f64 = unit
                .iter()
                .flat_map(|u| &u.parts)
                .map(|p| units::lookup(&p.name).map_or(f64::NAN, |d| d.factor.powi(p.power)))
                .product();
            g.constant_node(value * factor)
        }
        ExprKind::Name(n) => match n.as_str() {
            "x" if f.params.iter().any(|p| p == "x") => g.var(Var::X),
            "y" if f.params.iter().any(|p| p == "y") => g.var(Var::Y),
            "r" if f.params.iter().any(|p| p == "r") => {
                let (x, y) = (g.x(), g.y());
                let x2 = g.powi(x, 2);
                let y2 = g.powi(y, 2);
                let r2 = g.add(x2, y2);
                g.sqrt(r2)
            }
            other => g.constant_node(f.constants.get(other).copied().unwrap_or(f64::NAN)),
        },
        ExprKind::Unary {
            op: UnaryOp::Neg,
            operand,
        } => {
            let a = lower_expr(g, f, operand);
            g.neg(a)
        }
        ExprKind::Binary { op, lhs, rhs } => {
            let a = lower_expr(g, f, lhs);
            let b = lower_expr(g, f, rhs);
            let op = match op {
                BinaryOp::Add => Binary::Add,
                BinaryOp::Sub => Binary::Sub,
                BinaryOp::Mul => Binary::Mul,
                BinaryOp::Div => Binary::Div,
                BinaryOp::Pow | BinaryOp::Range => Binary::Pow,
            };
            g.binary(op, a, b)
        }
        ExprKind::Call { callee, args } => {
            let name = match &callee.kind {
                ExprKind::Name(n) => n.as_str(),
                _ => "",
            };
            let a: Vec<Id> = args.iter().map(|a| lower_expr(g, f, &a.value)).collect();
            let unary = |op| move |g: &mut Graph, a: &[Id]| g.unary(op, a[0]);
            match name {
                "sin" => unary(Unary::Sin)(g, &a),
                "cos" => unary(Unary::Cos)(g, &a),
                "tan" => unary(Unary::Tan)(g, &a),
                "asin" => unary(Unary::Asin)(g, &a),
                "acos" => unary(Unary::Acos)(g, &a),
                "atan" => unary(Unary::Atan)(g, &a),
                "sqrt" => unary(Unary::Sqrt)(g, &a),
                "abs" => unary(Unary::Abs)(g, &a),
                "exp" => unary(Unary::Exp)(g, &a),
                "ln" => unary(Unary::Ln)(g, &a),
                "atan2" => g.binary(Binary::Atan2, a[0], a[1]),
                "min" | "max" => {
                    let op = if name == "min" {
                        Binary::Min
                    } else {
                        Binary::Max
                    };
                    a[1..].iter().fold(a[0], |acc, &b| g.binary(op, acc, b))
                }
                _ => g.constant_node(f64::NAN),
            }
        }
        // The checker admits no other node in a formula.
        _ => g.constant_node(f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::ir::{Interpreter, SurfaceFn};
    use lensc_runtime::surface::{RotationalSurface, Sense};

    /// The IR sag (in r² form, differentiated symbolically) against the
    /// runtime's closed-form profile (differentiated by hand), along x and,
    /// by symmetry, along y.
    #[test]
    fn ir_sag_matches_closed_form_profile() {
        let terms = vec![(3, 2e-4), (4, 1.5e-4), (6, -3e-6), (8, 2e-8), (16, 1e-14)];
        for (radius, k, sense) in [(22.405, 43.098, Sense::Convex), (4.254, -3.359, Sense::Concave), (8.5, -0.62, Sense::Convex), (5.0, 0.0, Sense::Concave)] {
            let closed = RotationalSurface { radius, conic: k, sense, terms: terms.clone(), aperture_radius: 1.5 };
            let mut g = Graph::new();
            let z = rotational_sag(&mut g, radius, k, &terms, sense.sign());
            let f = Interpreter::new(&SurfaceTape::new(g, z));
            for r in [0.05, 0.4, 0.9, 1.5] {
                let p = closed.eval(r);
                let ox = f.eval(r, 0.0);
                let oy = f.eval(0.0, r);
                let tol = |a: f64| 1e-13 * (1.0 + a.abs());
                assert!((ox[0] - p.z).abs() <= tol(p.z), "z R={radius} r={r}: {} vs {}", ox[0], p.z);
                assert!((ox[1] - p.dz).abs() <= tol(p.dz), "dz/dx R={radius} r={r}: {} vs {}", ox[1], p.dz);
                assert!((ox[3] - p.d2z).abs() <= tol(p.d2z), "d2z/dx2 R={radius} r={r}: {} vs {}", ox[3], p.d2z);
                assert!((oy[0] - p.z).abs() <= tol(p.z) && (oy[2] - p.dz).abs() <= tol(p.dz) && (oy[5] - p.d2z).abs() <= tol(p.d2z));
                assert!(ox[2].abs() < 1e-15 && ox[4].abs() < 1e-15, "no slope across the section");
            }
        }
    }

    /// A sphere's sag against R − sqrt(R² − r²) in 2-D, off the axes
    /// (written r²/(R + sqrt(R² − r²)) to avoid cancellation).
    #[test]
    fn sphere_sag_off_axis() {
        let mut g = Graph::new();
        let z = rotational_sag(&mut g, 20.0, 0.0, &[], 1.0);
        let f = Interpreter::new(&SurfaceTape::new(g, z));
        for (x, y) in [(0.3, 0.4), (-0.6, 0.8), (0.85, -0.1)] {
            let r2 = x * x + y * y;
            let want = r2 / (20.0 + (400.0f64 - r2).sqrt());
            let got = f.eval(x, y)[0];
            assert!((got - want).abs() <= 4e-16 * want, "{got} vs {want}");
        }
    }
}
