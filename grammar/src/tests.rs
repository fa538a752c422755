//! Parser unit tests: precedence, units, spans, recovery.

use crate::ast::*;
use crate::{FileId, parse};

fn expr(src: &str) -> Expr {
    let (file, diags) = parse(&format!("let a = {src}\n"), FileId(0));
    assert!(diags.is_empty(), "{diags:?}");
    match file.items.into_iter().next().expect("item").kind {
        ItemKind::Let { value, .. } => value,
        other => panic!("{other:?}"),
    }
}

/// A compact rendering of an expression tree.
fn show(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Quantity { value, unit: None } => format!("{value}"),
        ExprKind::Quantity {
            value,
            unit: Some(u),
        } => {
            let parts: Vec<String> = u
                .parts
                .iter()
                .map(|p| format!("{}^{}", p.name, p.power))
                .collect();
            format!("{value}[{}]", parts.join(" "))
        }
        ExprKind::Name(n) => n.clone(),
        ExprKind::Unary { operand, .. } => format!("(-{})", show(operand)),
        ExprKind::Binary { op, lhs, rhs } => {
            format!("({} {} {})", show(lhs), op.symbol(), show(rhs))
        }
        ExprKind::Call { callee, args } => {
            let a: Vec<String> = args.iter().map(|a| show(&a.value)).collect();
            format!("{}({})", show(callee), a.join(", "))
        }
        other => format!("{other:?}"),
    }
}

#[test]
fn precedence_and_associativity() {
    assert_eq!(
        show(&expr("1 + 2 * 3 ^ 2 ^ 2")),
        "(1 + (2 * (3 ^ (2 ^ 2))))"
    );
    assert_eq!(show(&expr("-x ^ 2")), "(-(x ^ 2))");
    assert_eq!(show(&expr("1 - 2 - 3")), "((1 - 2) - 3)");
    assert_eq!(
        show(&expr("0 mm .. 1 mm + 2 mm")),
        "(0[mm^1] .. (1[mm^1] + 2[mm^1]))"
    );
    assert_eq!(show(&expr("2 ^ -1")), "(2 ^ (-1))");
}

#[test]
fn units_attach_to_numbers() {
    assert_eq!(show(&expr("5 rad/mm * x")), "(5[rad^1 mm^-1] * x)");
    assert_eq!(show(&expr("10 rad/(3 mm)")), "(10[rad^1] / 3[mm^1])");
    assert_eq!(show(&expr("9.81 m/s^2")), "9.81[m^1 s^-2]");
    assert_eq!(show(&expr("1.2e-5 mm^-3")), "0.000012[mm^-3]");
    assert_eq!(show(&expr("7°")), "7[°^1]");
    assert_eq!(show(&expr("85 µm")), "85[µm^1]");
    assert_eq!(show(&expr("2 mm / x")), "(2[mm^1] / x)");
}

#[test]
fn a_unit_does_not_swallow_the_next_parameter() {
    let (file, diags) = parse(
        "surface s = conic {\n radius: 1 mm\n conic: -20\n sense: convex\n}\n",
        FileId(0),
    );
    assert!(diags.is_empty(), "{diags:?}");
    let ItemKind::Decl { value, .. } = &file.items[0].kind else {
        panic!()
    };
    let ExprKind::WithBlock { block, .. } = &value.kind else {
        panic!()
    };
    let names: Vec<&str> = block
        .entries
        .iter()
        .map(|e| e.name().name.as_str())
        .collect();
    assert_eq!(names, ["radius", "conic", "sense"]);
}

#[test]
fn spans_are_byte_offsets() {
    let src = "let a = 3 µm + 2 mm\n";
    let e = expr("3 µm + 2 mm");
    let ExprKind::Binary { rhs, .. } = &e.kind else {
        panic!()
    };
    // `µ` is two bytes: the right operand starts at byte 16, not 15.
    assert_eq!(&src[rhs.span.range()], "2 mm");
    assert_eq!(rhs.span.start, 16);
}

#[test]
fn every_broken_item_is_reported() {
    let (file, diags) = parse(
        "let a = (1 mm\nlet b = 2 mm\nlet c = 3 mm +\nlet d = 4 mm\n",
        FileId(0),
    );
    assert_eq!(diags.len(), 2, "{diags:?}");
    assert_eq!(file.items.len(), 2, "the good items still parse");
}

#[test]
fn formulas_and_named_arguments() {
    let (file, diags) = parse(
        "surface p = freeform {\n z(x, y) = 0.02 mm * sin(5 rad/mm * x)\n domain: rect(x: 0 mm .. 1 mm, y: 0 mm .. 2 mm)\n}\n",
        FileId(0),
    );
    assert!(diags.is_empty(), "{diags:?}");
    let ItemKind::Decl { value, .. } = &file.items[0].kind else {
        panic!()
    };
    let ExprKind::WithBlock { block, .. } = &value.kind else {
        panic!()
    };
    assert!(matches!(&block.entries[0], Entry::Formula { params, .. } if params.len() == 2));
    let Entry::Param { value, .. } = &block.entries[1] else {
        panic!()
    };
    let ExprKind::Call { args, .. } = &value.kind else {
        panic!()
    };
    assert_eq!(args[0].name.as_ref().map(|n| n.name.as_str()), Some("x"));
}
