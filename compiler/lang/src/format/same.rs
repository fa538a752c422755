//! Whether two syntax trees are the same program: every node equal but
//! for where it was written (spans are ignored, nothing else).

use lensc_grammar::ast::*;

pub(super) fn files(a: &File, b: &File) -> bool {
    all(&a.items, &b.items, item)
}

fn all<T>(a: &[T], b: &[T], same: fn(&T, &T) -> bool) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same(x, y))
}

fn ident(a: &Ident, b: &Ident) -> bool {
    a.name == b.name
}

fn item(a: &Item, b: &Item) -> bool {
    match (&a.kind, &b.kind) {
        (ItemKind::Use(UseTarget::Std(x)), ItemKind::Use(UseTarget::Std(y))) => all(x, y, ident),
        (
            ItemKind::Use(UseTarget::File { path: x, .. }),
            ItemKind::Use(UseTarget::File { path: y, .. }),
        ) => x == y,
        (ItemKind::Let { name: n, value: v }, ItemKind::Let { name: m, value: w }) => {
            ident(n, m) && expr(v, w)
        }
        (
            ItemKind::Decl {
                kind: k,
                name: n,
                value: v,
            },
            ItemKind::Decl {
                kind: l,
                name: m,
                value: w,
            },
        ) => k == l && ident(n, m) && expr(v, w),
        (ItemKind::Job { name: n, body: x }, ItemKind::Job { name: m, body: y }) => {
            ident(n, m) && block(x, y)
        }
        _ => false,
    }
}

fn block(a: &Block, b: &Block) -> bool {
    all(&a.entries, &b.entries, entry)
}

fn entry(a: &Entry, b: &Entry) -> bool {
    match (a, b) {
        (Entry::Param { name: n, value: v }, Entry::Param { name: m, value: w }) => {
            ident(n, m) && expr(v, w)
        }
        (
            Entry::Formula {
                name: n,
                params: p,
                body: x,
            },
            Entry::Formula {
                name: m,
                params: q,
                body: y,
            },
        ) => ident(n, m) && all(p, q, ident) && expr(x, y),
        _ => false,
    }
}

fn arg(a: &Arg, b: &Arg) -> bool {
    let names = match (&a.name, &b.name) {
        (Some(n), Some(m)) => ident(n, m),
        (None, None) => true,
        _ => false,
    };
    names && expr(&a.value, &b.value)
}

fn unit_part(a: &UnitPart, b: &UnitPart) -> bool {
    a.name == b.name && a.power == b.power
}

fn expr(a: &Expr, b: &Expr) -> bool {
    use ExprKind as K;
    match (&a.kind, &b.kind) {
        (K::Quantity { value: v, unit: u }, K::Quantity { value: w, unit: t }) => {
            v.to_bits() == w.to_bits()
                && match (u, t) {
                    (Some(u), Some(t)) => all(&u.parts, &t.parts, unit_part),
                    (None, None) => true,
                    _ => false,
                }
        }
        (K::Str(x), K::Str(y)) | (K::Name(x), K::Name(y)) => x == y,
        (K::Unary { op: o, operand: x }, K::Unary { op: p, operand: y }) => o == p && expr(x, y),
        (
            K::Binary {
                op: o,
                lhs: l,
                rhs: r,
            },
            K::Binary {
                op: p,
                lhs: m,
                rhs: s,
            },
        ) => o == p && expr(l, m) && expr(r, s),
        (K::Call { callee: f, args: x }, K::Call { callee: g, args: y }) => {
            expr(f, g) && all(x, y, arg)
        }
        (K::WithBlock { base: f, block: x }, K::WithBlock { base: g, block: y }) => {
            expr(f, g) && block(x, y)
        }
        (K::Block(x), K::Block(y)) => block(x, y),
        (K::List(x), K::List(y)) => all(x, y, expr),
        _ => false,
    }
}
