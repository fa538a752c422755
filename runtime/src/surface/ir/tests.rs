//! Tests of the surface IR; its interpreter passes the evaluator
//! conformance suite (`surface::conformance`).

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

crate::surface::conformance::surface_fn_tests!(Interpreter);
