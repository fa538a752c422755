//! The surface expression IR: a deduplicating arena of nodes over the
//! coordinates `x`, `y` (mm), simplified as it is built, with exact
//! derivatives as a graph transform and a reference interpreter.
//!
//! Nodes are only ever appended, and a node's operands are always earlier
//! nodes, so the arena is a topologically ordered tape: evaluating it front
//! to back computes every node after its operands. Backends (the
//! interpreter here, cranelift JIT in the compiler) walk the same tape.

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
}

/// A deduplicating, simplifying expression arena.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
    /// Memo of `derivative`: (node, variable) → derivative node.
    derivatives: HashMap<(Id, Var), Id>,
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

    /// Copies the expression `root` of `other` into this graph with its
    /// coordinates replaced by the nodes `x` and `y` (composition), and
    /// returns the copy of every node it needed, indexed like `other`.
    pub fn import(&mut self, other: &Graph, x: Id, y: Id) -> Vec<Id> {
        let mut map: Vec<Id> = Vec::with_capacity(other.len());
        for &n in other.nodes() {
            let m = |i: Id| map[i.0 as usize];
            let id = match n {
                Node::Const(bits) => self.constant_node(f64::from_bits(bits)),
                Node::Var(Var::X) => x,
                Node::Var(Var::Y) => y,
                Node::Unary(op, a) => self.unary(op, m(a)),
                Node::Binary(op, a, b) => self.binary(op, m(a), m(b)),
                Node::PowI(a, k) => self.powi(m(a), k),
                Node::Step(a) => self.step(m(a)),
                Node::Select(c, a, b) => self.select(m(c), m(a), m(b)),
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
            Node::Const(_) | Node::Step(_) | Node::Unary(Unary::Floor, _) => {
                self.constant_node(0.0)
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
            match self.graph.nodes()[i] {
                Node::Unary(_, a) | Node::PowI(a, _) | Node::Step(a) => live[a.0 as usize] = true,
                Node::Binary(_, a, b) => {
                    live[a.0 as usize] = true;
                    live[b.0 as usize] = true;
                }
                Node::Select(c, a, b) => {
                    live[c.0 as usize] = true;
                    live[a.0 as usize] = true;
                    live[b.0 as usize] = true;
                }
                Node::Const(_) | Node::Var(_) => {}
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
    /// (slot of the result, operation) in tape order.
    ops: Vec<Op>,
    outputs: [usize; 6],
    slots: usize,
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
}

impl Interpreter {
    pub fn new(tape: &SurfaceTape) -> Interpreter {
        let live = tape.live_nodes();
        let mut slot_of = vec![usize::MAX; tape.graph.len()];
        let mut ops = Vec::with_capacity(live.len());
        for (slot, id) in live.iter().enumerate() {
            slot_of[id.0 as usize] = slot;
            let s = |i: Id| slot_of[i.0 as usize];
            ops.push(match tape.graph.node(*id) {
                Node::Const(bits) => Op::Const(f64::from_bits(bits)),
                Node::Var(v) => Op::Var(v),
                Node::Unary(op, a) => Op::Unary(op, s(a)),
                Node::Binary(op, a, b) => Op::Binary(op, s(a), s(b)),
                Node::PowI(a, n) => Op::PowI(s(a), n),
                Node::Step(a) => Op::Step(s(a)),
                Node::Select(c, a, b) => Op::Select(s(c), s(a), s(b)),
            });
        }
        let outputs = tape.outputs.map(|o| slot_of[o.0 as usize]);
        Interpreter {
            slots: ops.len(),
            ops,
            outputs,
        }
    }
}

impl SurfaceFn for Interpreter {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        assert_eq!(xs.len(), ys.len());
        assert_eq!(out.len(), 6 * xs.len());
        let mut v = vec![0.0f64; self.slots];
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            for (k, op) in self.ops.iter().enumerate() {
                v[k] = match *op {
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
