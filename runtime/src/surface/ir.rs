//! The surface expression IR: a deduplicating arena of nodes over the
//! coordinates `x`, `y` (mm), simplified as it is built, with exact
//! derivatives as a graph transform and a reference interpreter.
//!
//! Nodes are only ever appended, and a node's operands are always earlier
//! nodes, so the arena is a topologically ordered tape: evaluating it front
//! to back computes every node after its operands. Backends (the
//! interpreter here, cranelift JIT in the compiler) walk the same tape.
//! A loop (`Node::Repeat`) is the one place the walk goes back: its body,
//! in the tape once, is run for each of its steps.

use std::collections::HashMap;

/// Index of a node in its `Graph`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(pub u32);

/// The coordinate a derivative is taken along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Var {
    X,
    Y,
}

/// Functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Unary {
    Neg,
    Sqrt,
    Abs,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    /// Largest whole number not above the argument (cell indices of arrays);
    /// its derivative is zero wherever it is defined.
    Floor,
}

impl Unary {
    /// Every function of one argument (for suites that try them all).
    pub const ALL: [Unary; 12] = [
        Unary::Neg,
        Unary::Sqrt,
        Unary::Abs,
        Unary::Sin,
        Unary::Cos,
        Unary::Tan,
        Unary::Asin,
        Unary::Acos,
        Unary::Atan,
        Unary::Exp,
        Unary::Ln,
        Unary::Floor,
    ];
}

/// Functions of two arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    /// a^b for any real b (a > 0 where b is not an integer).
    Pow,
    Atan2,
    Min,
    Max,
}

impl Binary {
    /// Every function of two arguments.
    pub const ALL: [Binary; 8] = [
        Binary::Add,
        Binary::Sub,
        Binary::Mul,
        Binary::Div,
        Binary::Pow,
        Binary::Atan2,
        Binary::Min,
        Binary::Max,
    ];
}

/// One node. Constants are stored by their bits so the arena can
/// deduplicate them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    Const(u64),
    Var(Var),
    Unary(Unary, Id),
    Binary(Binary, Id, Id),
    /// a^n for a whole number n (exact derivative everywhere, fast).
    PowI(Id, i32),
    /// 1 where the argument is negative, else 0 — the derivative of `Abs`,
    /// `Min` and `Max` needs a step; its own derivative is zero.
    Step(Id),
    /// `a` where `c` < 0, else `b` (so NaN in `c` selects `b`). Unlike a
    /// product with a step, the branch not taken never leaks a NaN:
    /// lenslets are evaluated only inside their apertures.
    Select(Id, Id, Id),
    /// Inside the body of a loop (`Repeat`), the estimate the step before
    /// left; a leaf, like a coordinate. The number tells a graph's loops
    /// apart.
    Carried(u32),
    /// `steps` steps of a loop: the estimate p₀ = `init`, then p_{k+1} =
    /// `next` evaluated with `carried` standing for p_k; the node's value
    /// is p_steps. The loop's body is every node `next` needs that
    /// depends on `carried` (`Graph::loop_body`): those nodes are
    /// evaluated only inside the loop, and nothing else uses them. The
    /// value is that of the steps written out one after another
    /// (`Graph::unroll`), bit for bit: the same operations on the same
    /// operands, in the same order; only the body is written once (a
    /// Newton iteration's six steps, a sixth of the nodes for a backend
    /// to compile).
    Repeat {
        carried: Id,
        init: Id,
        next: Id,
        steps: u32,
    },
}

impl Node {
    /// The nodes this one reads (a loop reads its carried estimate, its
    /// initial value and its body's result), in order, repeats included.
    pub fn operands(self) -> impl Iterator<Item = Id> {
        let (a, b, c) = match self {
            Node::Const(_) | Node::Var(_) | Node::Carried(_) => (None, None, None),
            Node::Unary(_, a) | Node::PowI(a, _) | Node::Step(a) => (Some(a), None, None),
            Node::Binary(_, a, b) => (Some(a), Some(b), None),
            Node::Select(c, a, b) => (Some(c), Some(a), Some(b)),
            Node::Repeat {
                carried,
                init,
                next,
                ..
            } => (Some(carried), Some(init), Some(next)),
        };
        [a, b, c].into_iter().flatten()
    }
}

/// A deduplicating, simplifying expression arena.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
    /// Memo of `derivative`: (node, variable) → derivative node.
    derivatives: HashMap<(Id, Var), Id>,
    /// Loops begun (`carried`): the number of the next one.
    loops: u32,
}

impl Graph {
    pub fn new() -> Graph {
        Graph::default()
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    pub fn node(&self, id: Id) -> Node {
        self.nodes[id.0 as usize]
    }

    /// The constant value of a node, if it is one.
    pub fn constant(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    fn intern(&mut self, n: Node) -> Id {
        if let Some(&id) = self.index.get(&n) {
            return id;
        }
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(n);
        self.index.insert(n, id);
        id
    }

    pub fn constant_node(&mut self, v: f64) -> Id {
        // One zero: -0.0 and 0.0 are the same constant for every use here.
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    pub fn var(&mut self, v: Var) -> Id {
        self.intern(Node::Var(v))
    }

    pub fn x(&mut self) -> Id {
        self.var(Var::X)
    }

    pub fn y(&mut self) -> Id {
        self.var(Var::Y)
    }

    pub fn unary(&mut self, op: Unary, a: Id) -> Id {
        if let Some(c) = self.constant(a) {
            return self.constant_node(apply_unary(op, c));
        }
        match (op, self.node(a)) {
            (Unary::Neg, Node::Unary(Unary::Neg, inner)) => return inner,
            (Unary::Abs, Node::Unary(Unary::Abs, _)) => return a,
            _ => {}
        }
        self.intern(Node::Unary(op, a))
    }

    pub fn binary(&mut self, op: Binary, a: Id, b: Id) -> Id {
        let (ca, cb) = (self.constant(a), self.constant(b));
        if let (Some(x), Some(y)) = (ca, cb) {
            return self.constant_node(apply_binary(op, x, y));
        }
        match op {
            Binary::Add => {
                if ca == Some(0.0) {
                    return b;
                }
                if cb == Some(0.0) {
                    return a;
                }
                if let Node::Unary(Unary::Neg, nb) = self.node(b) {
                    return self.binary(Binary::Sub, a, nb);
                }
            }
            Binary::Sub => {
                if cb == Some(0.0) {
                    return a;
                }
                if ca == Some(0.0) {
                    return self.unary(Unary::Neg, b);
                }
                if a == b {
                    return self.constant_node(0.0);
                }
            }
            Binary::Mul => {
                // x·0 = 0 holds for every finite x, and surface formulas
                // are finite wherever they are defined.
                if ca == Some(0.0) || cb == Some(0.0) {
                    return self.constant_node(0.0);
                }
                if ca == Some(1.0) {
                    return b;
                }
                if cb == Some(1.0) {
                    return a;
                }
                if ca == Some(-1.0) {
                    return self.unary(Unary::Neg, b);
                }
                if cb == Some(-1.0) {
                    return self.unary(Unary::Neg, a);
                }
                if a == b {
                    return self.powi(a, 2);
                }
            }
            Binary::Div => {
                if cb == Some(1.0) {
                    return a;
                }
                if ca == Some(0.0) {
                    return self.constant_node(0.0);
                }
                if let Some(c) = cb
                    && c.is_normal()
                    && c.to_bits() & ((1u64 << 52) - 1) == 0
                    && (1.0 / c).is_normal()
                {
                    // Powers of two only: their reciprocal is exact, so the
                    // cheaper multiplication gives the same bits.
                    let r = self.constant_node(1.0 / c);
                    return self.binary(Binary::Mul, a, r);
                }
            }
            Binary::Pow => {
                if let Some(e) = cb
                    && e.fract() == 0.0
                    && e.abs() <= 64.0
                {
                    return self.powi(a, e as i32);
                }
            }
            _ => {}
        }
        // Commutative operators take their operands in a fixed order so
        // that `a + b` and `b + a` are one node.
        let (a, b) = match op {
            Binary::Add | Binary::Mul | Binary::Min | Binary::Max if b < a => (b, a),
            _ => (a, b),
        };
        self.intern(Node::Binary(op, a, b))
    }

    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        if let Some(c) = self.constant(a) {
            return self.constant_node(c.powi(n));
        }
        match n {
            0 => self.constant_node(1.0),
            1 => a,
            _ => self.intern(Node::PowI(a, n)),
        }
    }

    /// `a` where `c` < 0, else `b`.
    pub fn select(&mut self, c: Id, a: Id, b: Id) -> Id {
        if let Some(cv) = self.constant(c) {
            return if cv < 0.0 { a } else { b };
        }
        if a == b {
            return a;
        }
        self.intern(Node::Select(c, a, b))
    }

    pub fn floor(&mut self, a: Id) -> Id {
        self.unary(Unary::Floor, a)
    }

    fn step(&mut self, a: Id) -> Id {
        if let Some(c) = self.constant(a) {
            return self.constant_node(if c < 0.0 { 1.0 } else { 0.0 });
        }
        self.intern(Node::Step(a))
    }

    // Short names for building formulas by hand.
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        self.binary(Binary::Add, a, b)
    }
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        self.binary(Binary::Sub, a, b)
    }
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        self.binary(Binary::Mul, a, b)
    }
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        self.binary(Binary::Div, a, b)
    }
    pub fn neg(&mut self, a: Id) -> Id {
        self.unary(Unary::Neg, a)
    }
    pub fn sqrt(&mut self, a: Id) -> Id {
        self.unary(Unary::Sqrt, a)
    }

    /// The estimate of a new loop (`Node::Carried`): build the loop's
    /// body over it, then close the loop with `repeat`.
    pub fn carried(&mut self) -> Id {
        let k = self.loops;
        self.loops += 1;
        self.intern(Node::Carried(k))
    }

    /// `steps` steps of the loop whose body computes `next` from the
    /// estimate `carried` (from `carried()`), starting at `init`: a
    /// `Repeat` node, equal bit for bit to the steps written out. Where a
    /// loop would gain nothing or could not be one, the value itself: no
    /// step (`init`), a body that ignores the estimate (`next`), a body
    /// that leaves it as it is (`init`), a body holding another loop (the
    /// steps written out: loops are not nested).
    pub fn repeat(&mut self, carried: Id, init: Id, next: Id, steps: u32) -> Id {
        if steps == 0 || next == carried {
            return init;
        }
        let body = self.loop_body(carried, next);
        if body.is_empty() {
            return next;
        }
        let nested = body
            .iter()
            .any(|&i| matches!(self.node(i), Node::Repeat { .. }));
        if nested || !matches!(self.node(carried), Node::Carried(_)) {
            return self.unroll_steps(carried, &body, init, next, steps);
        }
        self.intern(Node::Repeat {
            carried,
            init,
            next,
            steps,
        })
    }

    /// The body of a loop: the nodes `next` needs that depend on
    /// `carried` (`carried` itself left out), in tape order.
    pub fn loop_body(&self, carried: Id, next: Id) -> Vec<Id> {
        let (lo, hi) = (carried.0 as usize, next.0 as usize);
        if hi <= lo {
            return Vec::new();
        }
        let at = |o: Id| (o.0 as usize).checked_sub(lo);
        let mut depends = vec![false; hi - lo + 1];
        depends[0] = true;
        for i in lo + 1..=hi {
            depends[i - lo] = self.nodes[i]
                .operands()
                .any(|o| at(o).is_some_and(|k| depends[k]));
        }
        let mut needed = vec![false; hi - lo + 1];
        needed[hi - lo] = true;
        for i in (lo + 1..=hi).rev() {
            if needed[i - lo] && depends[i - lo] {
                for k in self.nodes[i].operands().filter_map(at) {
                    needed[k] = true;
                }
            }
        }
        (lo + 1..=hi)
            .filter(|&i| needed[i - lo] && depends[i - lo])
            .map(|i| Id(i as u32))
            .collect()
    }

    /// The steps of a loop written out, as ordinary nodes (`id` itself if
    /// it is no loop): each a copy of the body over the estimate the one
    /// before left.
    pub fn unroll(&mut self, id: Id) -> Id {
        match self.node(id) {
            Node::Repeat {
                carried,
                init,
                next,
                steps,
            } => {
                let body = self.loop_body(carried, next);
                self.unroll_steps(carried, &body, init, next, steps)
            }
            _ => id,
        }
    }

    fn unroll_steps(&mut self, carried: Id, body: &[Id], init: Id, next: Id, steps: u32) -> Id {
        let mut p = init;
        let mut map: HashMap<Id, Id> = HashMap::new();
        for _ in 0..steps {
            map.clear();
            map.insert(carried, p);
            for &i in body {
                let n = self.node(i);
                let copy = self.rebuild(n, |o| map.get(&o).copied().unwrap_or(o));
                map.insert(i, copy);
            }
            p = map.get(&next).copied().unwrap_or(next);
        }
        p
    }

    /// Node `n` built again in this graph over the operands `m` gives
    /// (simplified as any new node is); a leaf is itself.
    fn rebuild(&mut self, n: Node, m: impl Fn(Id) -> Id) -> Id {
        match n {
            Node::Const(_) | Node::Var(_) | Node::Carried(_) => self.intern(n),
            Node::Unary(op, a) => self.unary(op, m(a)),
            Node::Binary(op, a, b) => self.binary(op, m(a), m(b)),
            Node::PowI(a, k) => self.powi(m(a), k),
            Node::Step(a) => self.step(m(a)),
            Node::Select(c, a, b) => self.select(m(c), m(a), m(b)),
            Node::Repeat {
                carried,
                init,
                next,
                steps,
            } => self.repeat(m(carried), m(init), m(next), steps),
        }
    }

    /// Copies the expression `root` of `other` into this graph with its
    /// coordinates replaced by the nodes `x` and `y` (composition), and
    /// returns the copy of every node it needed, indexed like `other`.
    /// Each of `other`'s loops becomes a loop of this graph.
    pub fn import(&mut self, other: &Graph, x: Id, y: Id) -> Vec<Id> {
        let mut map: Vec<Id> = Vec::with_capacity(other.len());
        for &n in other.nodes() {
            let id = match n {
                Node::Const(bits) => self.constant_node(f64::from_bits(bits)),
                Node::Var(Var::X) => x,
                Node::Var(Var::Y) => y,
                Node::Carried(_) => self.carried(),
                _ => self.rebuild(n, |i| map[i.0 as usize]),
            };
            map.push(id);
        }
        map
    }

    /// d(node)/d(var), built in this graph. Exact: each rule is the
    /// derivative of the node's function, applied through the chain rule.
    pub fn derivative(&mut self, id: Id, var: Var) -> Id {
        if let Some(&d) = self.derivatives.get(&(id, var)) {
            return d;
        }
        let d = match self.node(id) {
            // A loop's estimate is held fixed: only the loop as a whole
            // has a derivative, that of its steps written out.
            Node::Const(_) | Node::Step(_) | Node::Unary(Unary::Floor, _) | Node::Carried(_) => {
                self.constant_node(0.0)
            }
            Node::Repeat { .. } => {
                let steps = self.unroll(id);
                if steps == id {
                    self.constant_node(0.0)
                } else {
                    self.derivative(steps, var)
                }
            }
            Node::Select(c, a, b) => {
                let da = self.derivative(a, var);
                let db = self.derivative(b, var);
                self.select(c, da, db)
            }
            Node::Var(v) => self.constant_node(if v == var { 1.0 } else { 0.0 }),
            Node::PowI(a, n) => {
                let da = self.derivative(a, var);
                let p = self.powi(a, n - 1);
                let n = self.constant_node(f64::from(n));
                let np = self.mul(n, p);
                self.mul(np, da)
            }
            Node::Unary(Unary::Neg, a) => {
                let da = self.derivative(a, var);
                self.neg(da)
            }
            Node::Unary(op, a) => {
                let da = self.derivative(a, var);
                let outer = self.unary_slope(op, id, a);
                self.mul(outer, da)
            }
            Node::Binary(op, a, b) => {
                let da = self.derivative(a, var);
                let db = self.derivative(b, var);
                self.binary_derivative(op, id, (a, da), (b, db))
            }
        };
        self.memo(id, var, d)
    }

    /// f′(a) of `id` = f(a), a function of one argument other than
    /// negation (the chain rule's outer factor).
    fn unary_slope(&mut self, op: Unary, id: Id, a: Id) -> Id {
        match op {
            // d sqrt(a) = da / (2 sqrt(a))
            Unary::Sqrt => {
                let two = self.constant_node(2.0);
                let t = self.mul(two, id);
                let one = self.constant_node(1.0);
                self.div(one, t)
            }
            // d |a| = sign(a) da, with sign = 1 − 2·step(a)
            Unary::Abs => {
                let s = self.step(a);
                let two = self.constant_node(2.0);
                let t = self.mul(two, s);
                let one = self.constant_node(1.0);
                self.sub(one, t)
            }
            Unary::Sin => self.unary(Unary::Cos, a),
            Unary::Cos => {
                let s = self.unary(Unary::Sin, a);
                self.neg(s)
            }
            // d tan(a) = (1 + tan²a) da
            Unary::Tan => {
                let t2 = self.powi(id, 2);
                let one = self.constant_node(1.0);
                self.add(one, t2)
            }
            // d asin(a) = da / sqrt(1 − a²); acos is its negative
            Unary::Asin | Unary::Acos => {
                let a2 = self.powi(a, 2);
                let one = self.constant_node(1.0);
                let r = self.sub(one, a2);
                let s = self.sqrt(r);
                let inv = self.div(one, s);
                if op == Unary::Asin {
                    inv
                } else {
                    self.neg(inv)
                }
            }
            // d atan(a) = da / (1 + a²)
            Unary::Atan => {
                let a2 = self.powi(a, 2);
                let one = self.constant_node(1.0);
                let r = self.add(one, a2);
                self.div(one, r)
            }
            Unary::Exp => id,
            Unary::Ln => {
                let one = self.constant_node(1.0);
                self.div(one, a)
            }
            Unary::Neg | Unary::Floor => unreachable!("handled by `derivative`"),
        }
    }

    /// d(a op b) from the operands and their derivatives; `id` is the node
    /// a op b itself.
    fn binary_derivative(
        &mut self,
        op: Binary,
        id: Id,
        (a, da): (Id, Id),
        (b, db): (Id, Id),
    ) -> Id {
        match op {
            Binary::Add => self.add(da, db),
            Binary::Sub => self.sub(da, db),
            Binary::Mul => {
                let l = self.mul(da, b);
                let r = self.mul(a, db);
                self.add(l, r)
            }
            // d(a/b) = (da − (a/b) db) / b
            Binary::Div => {
                let q = self.mul(id, db);
                let num = self.sub(da, q);
                self.div(num, b)
            }
            // d(a^b) = a^b (db ln a + b da / a)
            Binary::Pow => {
                let ln = self.unary(Unary::Ln, a);
                let l = self.mul(db, ln);
                let ba = self.div(b, a);
                let r = self.mul(ba, da);
                let s = self.add(l, r);
                self.mul(id, s)
            }
            // atan2(a, b): d = (b da − a db) / (a² + b²)
            Binary::Atan2 => {
                let l = self.mul(b, da);
                let r = self.mul(a, db);
                let num = self.sub(l, r);
                let a2 = self.powi(a, 2);
                let b2 = self.powi(b, 2);
                let den = self.add(a2, b2);
                self.div(num, den)
            }
            // With s = step(a − b) (1 where a < b):
            // min(a, b) = b + s(a − b), d min = db + s(da − db);
            // max(a, b) = a + s(b − a), d max = da + s(db − da).
            Binary::Min | Binary::Max => {
                let diff = self.sub(a, b);
                let s = self.step(diff);
                let (lo, hi) = if op == Binary::Min {
                    (da, db)
                } else {
                    (db, da)
                };
                let dd = self.sub(lo, hi);
                let t = self.mul(s, dd);
                self.add(hi, t)
            }
        }
    }

    fn memo(&mut self, id: Id, var: Var, d: Id) -> Id {
        self.derivatives.insert((id, var), d);
        d
    }
}

pub fn apply_unary(op: Unary, a: f64) -> f64 {
    match op {
        Unary::Neg => -a,
        Unary::Sqrt => a.sqrt(),
        Unary::Abs => a.abs(),
        Unary::Sin => a.sin(),
        Unary::Cos => a.cos(),
        Unary::Tan => a.tan(),
        Unary::Asin => a.asin(),
        Unary::Acos => a.acos(),
        Unary::Atan => a.atan(),
        Unary::Exp => a.exp(),
        Unary::Ln => a.ln(),
        Unary::Floor => a.floor(),
    }
}

/// A function of one argument as surface kernels evaluate it: sin, cos
/// and exp by `fdlibm` (the JIT's own, within 1 ulp of libm), the rest as
/// `apply_unary`.
pub fn kernel_unary(op: Unary, a: f64) -> f64 {
    match op {
        Unary::Sin => super::fdlibm::sin(a),
        Unary::Cos => super::fdlibm::cos(a),
        Unary::Exp => super::fdlibm::exp(a),
        _ => apply_unary(op, a),
    }
}

pub fn apply_binary(op: Binary, a: f64, b: f64) -> f64 {
    match op {
        Binary::Add => a + b,
        Binary::Sub => a - b,
        Binary::Mul => a * b,
        Binary::Div => a / b,
        Binary::Pow => a.powf(b),
        Binary::Atan2 => a.atan2(b),
        Binary::Min => a.min(b),
        Binary::Max => a.max(b),
    }
}

/// The outputs every surface kernel computes at a point, in this order.
pub const OUTPUTS: [&str; 6] = ["z", "dzdx", "dzdy", "d2zdx2", "d2zdxdy", "d2zdy2"];

/// A surface height z(x, y) with its exact first and second derivatives,
/// as roots in one graph (they share every common subexpression).
#[derive(Clone, Debug)]
pub struct SurfaceTape {
    pub graph: Graph,
    /// z, ∂z/∂x, ∂z/∂y, ∂²z/∂x², ∂²z/∂x∂y, ∂²z/∂y².
    pub outputs: [Id; 6],
}

impl SurfaceTape {
    /// Differentiates `z` (a node of `graph`) twice along x and y.
    pub fn new(mut graph: Graph, z: Id) -> SurfaceTape {
        let zx = graph.derivative(z, Var::X);
        let zy = graph.derivative(z, Var::Y);
        let zxx = graph.derivative(zx, Var::X);
        let zxy = graph.derivative(zx, Var::Y);
        let zyy = graph.derivative(zy, Var::Y);
        SurfaceTape {
            graph,
            outputs: [z, zx, zy, zxx, zxy, zyy],
        }
    }

    /// A tape whose six outputs were built by the caller (for instance by
    /// the chain rule through an intermediate variable); they must be the
    /// exact value and derivatives, in the order of `OUTPUTS`.
    pub fn with_outputs(graph: Graph, outputs: [Id; 6]) -> SurfaceTape {
        SurfaceTape { graph, outputs }
    }

    /// The tape of the surface's sections at fixed y (a roller's axial
    /// sections): z, ∂z/∂x and ∂²z/∂x² computed exactly as this tape
    /// computes them, the three outputs that take a derivative along y
    /// NaN — not computed, so a kernel compiled from it does none of
    /// their work (their nodes are dead).
    pub fn axial_section(&self) -> SurfaceTape {
        let mut graph = self.graph.clone();
        let none = graph.constant_node(f64::NAN);
        let [z, zx, _, zxx, _, _] = self.outputs;
        SurfaceTape {
            graph,
            outputs: [z, zx, none, zxx, none, none],
        }
    }

    /// The tape of the height alone (what a simulation compares its cut
    /// with): z computed exactly as this tape computes it, the five
    /// derivatives NaN — not computed, so a kernel compiled from it does
    /// none of their work. Measured (benches/compensate.rs, the off-axis
    /// segment): 61 ns a point against 176 for all six outputs.
    pub fn height_only(&self) -> SurfaceTape {
        let mut graph = self.graph.clone();
        let none = graph.constant_node(f64::NAN);
        SurfaceTape {
            graph,
            outputs: [self.outputs[0], none, none, none, none, none],
        }
    }

    /// The tape of the height and its slopes alone (what a map's
    /// registration asks of the design): z, ∂z/∂x and ∂z/∂y computed
    /// exactly as this tape computes them, the three second derivatives
    /// NaN — not computed.
    pub fn slopes_only(&self) -> SurfaceTape {
        let mut graph = self.graph.clone();
        let none = graph.constant_node(f64::NAN);
        let [z, zx, zy, ..] = self.outputs;
        SurfaceTape {
            graph,
            outputs: [z, zx, zy, none, none, none],
        }
    }

    /// The nodes the outputs need, in tape order (dead nodes dropped).
    pub fn live_nodes(&self) -> Vec<Id> {
        let n = self.graph.len();
        let mut live = vec![false; n];
        for o in self.outputs {
            live[o.0 as usize] = true;
        }
        for i in (0..n).rev() {
            if !live[i] {
                continue;
            }
            for o in self.graph.nodes()[i].operands() {
                live[o.0 as usize] = true;
            }
        }
        (0..n).filter(|&i| live[i]).map(|i| Id(i as u32)).collect()
    }
}

/// Evaluates a surface at points: the one interface every backend offers.
pub trait SurfaceFn {
    /// For each point i, writes the six outputs (see `OUTPUTS`) to
    /// `out[6 i .. 6 i + 6]`. `xs`, `ys` have equal lengths and `out` six
    /// times that.
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]);

    /// The six outputs at one point.
    fn eval(&self, x: f64, y: f64) -> [f64; 6] {
        let mut out = [0.0; 6];
        self.eval_batch(&[x], &[y], &mut out);
        out
    }
}

/// The reference interpreter: walks the live tape for every point.
pub struct Interpreter {
    /// The operations outside every loop body in tape order; the result
    /// of the k-th goes to slot k.
    ops: Vec<Op>,
    /// The loops' bodies: (slot of the result, operation), each body in
    /// tape order, one after another.
    body: Vec<(usize, Op)>,
    loops: Vec<Loop>,
    outputs: [usize; 6],
    slots: usize,
}

/// A loop, by slots: the estimate, its initial value, the body's result
/// and the body's operations, `body[first..end]`.
#[derive(Clone, Copy, Debug)]
struct Loop {
    carried: usize,
    init: usize,
    next: usize,
    steps: u32,
    first: usize,
    end: usize,
}

#[derive(Clone, Copy, Debug)]
enum Op {
    Const(f64),
    Var(Var),
    Unary(Unary, usize),
    Binary(Binary, usize, usize),
    PowI(usize, i32),
    Step(usize),
    Select(usize, usize, usize),
    /// A loop's estimate: set by the loop, kept as it is by the walk.
    Carried,
    /// The loop `loops[k]`.
    Repeat(usize),
}

impl Op {
    /// The operation of node `n` with its operands' slots by `s`; a loop
    /// is left for its slots as an estimate, no step run (`Interpreter`
    /// builds `Op::Repeat`).
    fn of(n: Node, s: impl Fn(Id) -> usize) -> Op {
        match n {
            Node::Const(bits) => Op::Const(f64::from_bits(bits)),
            Node::Var(v) => Op::Var(v),
            Node::Unary(op, a) => Op::Unary(op, s(a)),
            Node::Binary(op, a, b) => Op::Binary(op, s(a), s(b)),
            Node::PowI(a, n) => Op::PowI(s(a), n),
            Node::Step(a) => Op::Step(s(a)),
            Node::Select(c, a, b) => Op::Select(s(c), s(a), s(b)),
            Node::Carried(_) | Node::Repeat { .. } => Op::Carried,
        }
    }
}

impl Interpreter {
    pub fn new(tape: &SurfaceTape) -> Interpreter {
        let live = tape.live_nodes();
        let graph = &tape.graph;
        // The live loops' bodies, which the walk outside them skips.
        let mut bodies: HashMap<Id, Vec<Id>> = HashMap::new();
        let mut in_body = vec![false; graph.len()];
        for &id in &live {
            if let Node::Repeat { carried, next, .. } = graph.node(id) {
                let body = graph.loop_body(carried, next);
                for &i in &body {
                    in_body[i.0 as usize] = true;
                }
                bodies.insert(id, body);
            }
        }
        let mut slot_of = vec![usize::MAX; graph.len()];
        let (outside, inside): (Vec<Id>, Vec<Id>) =
            live.iter().partition(|id| !in_body[id.0 as usize]);
        for (slot, id) in outside.iter().chain(&inside).enumerate() {
            slot_of[id.0 as usize] = slot;
        }
        let s = |i: Id| slot_of[i.0 as usize];
        let mut loops = Vec::new();
        let mut body = Vec::new();
        let mut ops = Vec::with_capacity(outside.len());
        for &id in &outside {
            ops.push(match graph.node(id) {
                Node::Repeat {
                    carried,
                    init,
                    next,
                    steps,
                } => {
                    let first = body.len();
                    // Bodies hold no loop (`Graph::repeat`): one level.
                    for &i in bodies.get(&id).map_or(&[][..], Vec::as_slice) {
                        body.push((s(i), Op::of(graph.node(i), s)));
                    }
                    loops.push(Loop {
                        carried: s(carried),
                        init: s(init),
                        next: s(next),
                        steps,
                        first,
                        end: body.len(),
                    });
                    Op::Repeat(loops.len() - 1)
                }
                n => Op::of(n, s),
            });
        }
        let outputs = tape.outputs.map(s);
        Interpreter {
            slots: live.len(),
            ops,
            body,
            loops,
            outputs,
        }
    }

    /// Runs loop `k` on the values `v` so far: its steps' value.
    #[inline(never)]
    fn run_loop(&self, k: usize, v: &mut [f64], x: f64, y: f64) -> f64 {
        let l = self.loops[k];
        v[l.carried] = v[l.init];
        for _ in 0..l.steps {
            for &(slot, op) in &self.body[l.first..l.end] {
                v[slot] = value(op, v, slot, x, y);
            }
            v[l.carried] = v[l.next];
        }
        v[l.carried]
    }
}

/// The value of operation `op`, whose result goes to slot `k`, from the
/// values `v` so far (a loop's estimate keeps its slot's value; loops
/// themselves are run by `Interpreter::run_loop`).
#[inline(always)]
fn value(op: Op, v: &[f64], k: usize, x: f64, y: f64) -> f64 {
    match op {
        Op::Const(c) => c,
        Op::Var(Var::X) => x,
        Op::Var(Var::Y) => y,
        Op::Unary(u, a) => kernel_unary(u, v[a]),
        Op::Binary(b, a, c) => apply_binary(b, v[a], v[c]),
        Op::PowI(a, n) => v[a].powi(n),
        Op::Step(a) => {
            if v[a] < 0.0 {
                1.0
            } else {
                0.0
            }
        }
        Op::Select(c, a, b) => {
            if v[c] < 0.0 {
                v[a]
            } else {
                v[b]
            }
        }
        Op::Carried | Op::Repeat(_) => v[k],
    }
}

impl SurfaceFn for Interpreter {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        assert_eq!(xs.len(), ys.len(), "xs and ys differ in length");
        assert_eq!(
            out.len(),
            6 * xs.len(),
            "out must hold six values per point"
        );
        let mut v = vec![0.0f64; self.slots];
        // A tape without loops (nearly all) in a walk that never calls
        // out: the loop-aware walk's call (which may write any slot) makes
        // the compiler reload the slots' address at every operation, and
        // the walk measured 10–20 % slower (benches/surface_eval.rs).
        if self.loops.is_empty() {
            for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
                for (k, &op) in self.ops.iter().enumerate() {
                    v[k] = value(op, &v, k, x, y);
                }
                for (k, &s) in self.outputs.iter().enumerate() {
                    out[6 * i + k] = v[s];
                }
            }
            return;
        }
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            for (k, &op) in self.ops.iter().enumerate() {
                v[k] = match op {
                    Op::Repeat(l) => self.run_loop(l, &mut v, x, y),
                    op => value(op, &v, k, x, y),
                };
            }
            for (k, &s) in self.outputs.iter().enumerate() {
                out[6 * i + k] = v[s];
            }
        }
    }
}

#[cfg(test)]
mod tests;
