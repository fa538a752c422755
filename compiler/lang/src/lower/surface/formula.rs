//! Freeform surfaces: a checked formula z(x, y) lowered node by node.

use lensc_grammar::ast::{BinaryOp, Expr, ExprKind, UnaryOp};
use lensc_runtime::surface::ir::{Binary, Graph, Id, Unary};

use super::radius_squared;
use crate::schema::Freeform;
use crate::units;
use crate::value::Formula;

/// A freeform surface: its formula `z(x, y) = …`.
pub(super) fn freeform_height(g: &mut Graph, p: &Freeform, x: Id, y: Id) -> Id {
    lower_formula(g, &p.z, x, y)
}

/// Lowers a checked formula body (in base units: mm and rad) at the
/// coordinates `x`, `y`.
pub fn lower_formula(g: &mut Graph, f: &Formula, x: Id, y: Id) -> Id {
    lower_expr(g, f, (x, y), &f.body)
}

fn lower_expr(g: &mut Graph, f: &Formula, at: (Id, Id), e: &Expr) -> Id {
    let (x, y) = at;
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
            "x" if f.params.iter().any(|p| p == "x") => x,
            "y" if f.params.iter().any(|p| p == "y") => y,
            "r" if f.params.iter().any(|p| p == "r") => {
                let r2 = radius_squared(g, x, y);
                g.sqrt(r2)
            }
            other => g.constant_node(f.constants.get(other).copied().unwrap_or(f64::NAN)),
        },
        ExprKind::Unary {
            op: UnaryOp::Neg,
            operand,
        } => {
            let a = lower_expr(g, f, at, operand);
            g.neg(a)
        }
        ExprKind::Binary { op, lhs, rhs } => {
            let a = lower_expr(g, f, at, lhs);
            let b = lower_expr(g, f, at, rhs);
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
            let a: Vec<Id> = args
                .iter()
                .map(|a| lower_expr(g, f, at, &a.value))
                .collect();
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
