//! Compiles a surface tape (`crate::surface::ir::SurfaceTape`) to native
//! code with cranelift: one kernel per tape that evaluates the six outputs
//! (z and its first and second derivatives) for a whole batch of points,
//! computing exactly what the reference `Interpreter` computes.
//!
//! The kernel is `extern "C" fn(xs, ys, out, n)`: the loop over the points
//! is inside the generated code, so a batch costs one call. The loop takes
//! two points per pass in the lanes of an `F64X2` (about twice the
//! throughput of one lane on arithmetic-heavy tapes, as measured by
//! `benches/surface_eval.rs`) and an odd last point in a scalar pass; both
//! passes compute the same bits for a point (the same IEEE operations, and
//! a lane never depends on its neighbour). The vector pass calls nothing
//! for sin, cos and exp: a pair with a lane their inline code does not
//! cover is taken again point by point (`define_kernel`).
//!
//! The nodes are emitted in an order that keeps few values waiting for
//! their last use (`emission_order`): the register allocator's work, most
//! of the compile time, follows how many values are live at once, and so
//! do the spills in the code. Among the nodes that free as many values,
//! the vector pass takes the one with the longest latency still ahead of
//! it (a square root or a division early, so that the core overlaps it
//! with the rest), the scalar pass the one with the most operations ahead.
//!
//! A loop of the tape (`Node::Repeat`) is one block that branches back to
//! itself, its body emitted once. A negation is mostly taken into the
//! product, quotient, sum or difference that reads it, where the identity
//! is exact (`Emitter::node`), else one xor with a sign mask.
//!
//! Arithmetic, `sqrt`, `abs` and negation are native instructions
//! (IEEE-exact, as in Rust); `min`/`max` are a select sequence with Rust's
//! `f64::min`/`max` behaviour (the non-NaN operand wins, ties return the
//! first operand); whole powers are expanded by repeated squaring in the
//! order compiler-rt's `__powidf2` (Rust's `f64::powi`) multiplies; sin,
//! cos and exp are inline on both lanes (`vecmath`, within 1 ulp of libm;
//! sin and cos of one argument share its reduction), points they do not
//! cover (huge, infinite or NaN arguments) going to the scalar pass, which
//! calls `fdlibm` (libm beyond its bounds); everything else
//! (tan … ln, pow, atan2) calls the interpreter's own
//! `apply_unary`/`apply_binary` through `extern "C"` wrappers registered as
//! JIT symbols, once per lane.

use std::collections::HashMap;
use std::fmt;
use std::sync::OnceLock;

use crate::surface::ir::{
    Binary, Id, Node, SurfaceFn, SurfaceTape, Unary, Var, apply_binary, apply_unary,
};
use cranelift_codegen::Context;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::immediates::Ieee64;
use cranelift_codegen::ir::{
    AbiParam, Endianness, FuncRef, InstBuilder, MemFlagsData, Type, UserFuncName, Value, types,
};
use cranelift_codegen::isa::OwnedTargetIsa;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{FuncId, Linkage, Module, default_libcall_names};

mod vecmath;

/// Why a tape could not be compiled (a cranelift or host error, never a
/// user error: every valid tape compiles).
#[derive(Debug)]
pub struct JitError(pub String);

impl fmt::Display for JitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "surface JIT: {}", self.0)
    }
}

impl std::error::Error for JitError {}

/// The generated kernel: for i in 0..n, writes the six outputs at
/// (xs[i], ys[i]) to out[6i .. 6i + 6].
type Kernel = unsafe extern "C" fn(xs: *const f64, ys: *const f64, out: *mut f64, n: usize);

/// A surface tape compiled to native code.
pub struct JitSurface {
    kernel: Kernel,
    /// Owns the executable memory `kernel` points into; freed on drop.
    module: ModuleGuard,
}

// `JitSurface` is `Send` without help: `JITModule` is `Send` and a function
// pointer is `Send`. Checked here so a cranelift change cannot silently
// take it away.
const _: fn() = || {
    fn send<T: Send>() {}
    send::<JitSurface>();
};

// SAFETY: through `&JitSurface` the only thing reachable is `kernel`, a
// function pointer to finalized, read-only code that touches nothing but
// its arguments (and calls pure, thread-safe libm wrappers). The module's
// interior state (a `RefCell` symbol cache) is never touched after
// `compile` returns: `ModuleGuard` exposes it to no `&self` method, only
// to its own `Drop`, which has exclusive access.
unsafe impl Sync for JitSurface {}

/// Keeps the `JITModule` alive as long as its code can be called and frees
/// its memory when dropped (cranelift's own `Drop` leaks it on purpose).
struct ModuleGuard(Option<JITModule>);

impl Drop for ModuleGuard {
    fn drop(&mut self) {
        if let Some(module) = self.0.take() {
            // SAFETY: the guard is dropped with (or instead of) the
            // `JitSurface` that holds the only copy of the kernel pointer,
            // so no code of this module runs or can be called afterwards.
            unsafe { module.free_memory() };
        }
    }
}

impl JitSurface {
    /// Compiles the live part of `tape` into one batch kernel.
    pub fn compile(tape: &SurfaceTape) -> Result<JitSurface, JitError> {
        let mut jb = JITBuilder::with_isa(host_isa()?, default_libcall_names());
        for f in Libm::ALL {
            jb.symbol(f.symbol(), f.address());
        }
        // From here on, an early return frees whatever was allocated.
        let mut guard = ModuleGuard(Some(JITModule::new(jb)));
        let module = guard.0.as_mut().expect("module is present until drop");
        let id = define_kernel(module, tape)?;
        module
            .finalize_definitions()
            .map_err(|e| JitError(format!("finalizing the kernel: {e}")))?;
        let code = module.get_finalized_function(id);
        // SAFETY: `code` is the finalized kernel, declared with the
        // signature built in `define_kernel`: four pointer-sized integer
        // parameters and no return value, in the host's default (C)
        // calling convention — exactly `Kernel`.
        let kernel = unsafe { std::mem::transmute::<*const u8, Kernel>(code) };
        Ok(JitSurface {
            kernel,
            module: guard,
        })
    }
}

impl SurfaceFn for JitSurface {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        // Hard asserts: the kernel trusts these lengths with raw pointers.
        assert_eq!(xs.len(), ys.len(), "xs and ys differ in length");
        assert_eq!(
            out.len(),
            6 * xs.len(),
            "out must hold six values per point"
        );
        debug_assert!(self.module.0.is_some());
        // SAFETY: the kernel reads xs[0..n], ys[0..n] and writes
        // out[0..6n], all in bounds by the asserts above; its code lives as
        // long as `self.module`.
        unsafe { (self.kernel)(xs.as_ptr(), ys.as_ptr(), out.as_mut_ptr(), xs.len()) }
    }
}

/// The host ISA, detected once per process (`OwnedTargetIsa` is an `Arc`).
fn host_isa() -> Result<OwnedTargetIsa, JitError> {
    static ISA: OnceLock<Result<OwnedTargetIsa, String>> = OnceLock::new();
    ISA.get_or_init(|| {
        let mut flags = settings::builder();
        let set = |fb: &mut settings::Builder, k: &str, v: &str| {
            fb.set(k, v).map_err(|e| format!("setting {k}={v}: {e}"))
        };
        // cranelift-jit requires both: absolute calls to the wrappers.
        set(&mut flags, "use_colocated_libcalls", "false")?;
        set(&mut flags, "is_pic", "false")?;
        // The tape reaching the JIT is already deduplicated and folded
        // (`ir::Graph`), so cranelift's e-graph pass finds nothing to gain:
        // measured with `benches/surface_eval.rs`, "none" compiles 25–35 %
        // faster (the 10 × 10 array 0.95 → 0.75 ms) and runs as fast or
        // faster (conic + A4…A16 batch 6.8 → 6.2 ns/point) than "speed".
        // The single-pass register allocator would halve compile time again
        // but doubles run time; the default (backtracking) is kept.
        set(&mut flags, "opt_level", "none")?;
        // The verifier costs compile time; keep it for debug builds.
        let verify = if cfg!(debug_assertions) {
            "true"
        } else {
            "false"
        };
        set(&mut flags, "enable_verifier", verify)?;
        let isa =
            cranelift_native::builder().map_err(|e| format!("host machine not supported: {e}"))?;
        isa.finish(settings::Flags::new(flags))
            .map_err(|e| format!("building the host ISA: {e}"))
    })
    .clone()
    .map_err(JitError)
}

/// How many points one pass of the tape evaluates: two side by side in
/// the lanes of an `F64X2` (cranelift has no 4-lane f64 on x86-64) in the
/// main loop, one (`F64`) for the odd point left at the end. A single
/// point is not evaluated in both lanes of a vector pass: the scalar pass
/// is about three times faster on one point (its selects are predicted
/// branches, not blends in the chain of dependencies), and planners that
/// follow a tool point by point call it once per point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lanes {
    One,
    Two,
}

impl Lanes {
    fn ty(self) -> Type {
        match self {
            Lanes::One => types::F64,
            Lanes::Two => types::F64X2,
        }
    }
}

/// Builds and defines the kernel function in `module`.
///
/// ```text
/// entry:  end = xs + 8n; goto head
/// head:   if at least two points are left goto pair, else goto tail
/// pair:   the tape on F64X2 for the points at (px, py), px[0] and px[1];
///         if a lane fell outside the inline sin, cos or exp goto single
/// store:  store both points' outputs; advance by two points; goto head
/// tail:   if px == end goto exit
/// single: the tape on F64 for the point at px (its libm calls made);
///         store; advance by one point; goto head
/// exit:   return
/// ```
///
/// The vector pass makes no call: a pair with a lane the inline code does
/// not cover (a huge, infinite or NaN argument, exp's overflow) stores
/// nothing and is taken again one point at a time, by the scalar pass
/// for its first point and the vector pass for what follows. The scalar
/// pass computes the same bits as the vector pass where both hold.
fn define_kernel(module: &mut JITModule, tape: &SurfaceTape) -> Result<FuncId, JitError> {
    let ptr = module.target_config().pointer_type();
    let mut sig = module.make_signature();
    for _ in 0..4 {
        sig.params.push(AbiParam::new(ptr));
    }
    let id = module
        .declare_function("lensc_surface_kernel", Linkage::Local, &sig)
        .map_err(|e| JitError(format!("declaring the kernel: {e}")))?;

    let mut ctx: Context = module.make_context();
    ctx.func.signature = sig;
    ctx.func.name = UserFuncName::user(0, id.as_u32());
    let mut fctx = FunctionBuilderContext::new();
    let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);

    let entry = b.create_block();
    let head = b.create_block();
    let pair = b.create_block();
    let store = b.create_block();
    let tail = b.create_block();
    let single = b.create_block();
    let exit = b.create_block();

    b.append_block_params_for_function_params(entry);
    b.switch_to_block(entry);
    let &[xs, ys, out, n] = b.block_params(entry) else {
        unreachable!("the kernel has four parameters")
    };
    let mut emit = Emitter {
        module,
        imports: HashMap::new(),
        trig: HashMap::new(),
        negative: HashMap::new(),
        covered: Vec::new(),
        sign: None,
    };
    let live = tape.live_nodes();
    let loops = Loops::of(tape, &live);
    let pending = pending_negations(tape, &live);
    let vector_order = emission_order(tape, &live, &loops, Lanes::Two);
    let scalar_order = emission_order(tape, &live, &loops, Lanes::One);
    let vector_bodies = body_orders(tape, &loops, Lanes::Two);
    let scalar_bodies = body_orders(tape, &loops, Lanes::One);
    let [px, py, po] = [(); 3].map(|_| b.declare_var(ptr));
    b.def_var(px, xs);
    b.def_var(py, ys);
    b.def_var(po, out);
    let bytes = b.ins().ishl_imm_u(n, 3);
    let end = b.ins().iadd(xs, bytes);
    b.ins().jump(head, &[]);

    // Two points left or more: px + 8 < end.
    b.switch_to_block(head);
    let cx = b.use_var(px);
    let second = b.ins().iadd_imm_u(cx, 8);
    let two = b.ins().icmp(IntCC::UnsignedLessThan, second, end);
    b.ins().brif(two, pair, &[], tail, &[]);

    b.switch_to_block(pair);
    let (cx, cy, co) = (b.use_var(px), b.use_var(py), b.use_var(po));
    let outputs = emit.pass(
        &mut b,
        tape,
        (&vector_order, &vector_bodies, &pending),
        Lanes::Two,
        cx,
        cy,
    )?;
    match emit.covered.split_first() {
        None => b.ins().jump(store, &[]),
        Some((&first, rest)) => {
            let all = rest.iter().fold(first, |acc, &m| b.ins().band(acc, m));
            let covered = b.ins().vall_true(all);
            b.ins().brif(covered, store, &[], single, &[])
        }
    };

    b.switch_to_block(store);
    store_outputs(&mut b, Lanes::Two, outputs, co);
    let nx = b.ins().iadd_imm_u(cx, 16);
    let ny = b.ins().iadd_imm_u(cy, 16);
    let no = b.ins().iadd_imm_u(co, 96);
    b.def_var(px, nx);
    b.def_var(py, ny);
    b.def_var(po, no);
    b.ins().jump(head, &[]);

    b.switch_to_block(tail);
    let cx = b.use_var(px);
    let more = b.ins().icmp(IntCC::NotEqual, cx, end);
    b.ins().brif(more, single, &[], exit, &[]);

    b.switch_to_block(single);
    let (cx, cy, co) = (b.use_var(px), b.use_var(py), b.use_var(po));
    let outputs = emit.pass(
        &mut b,
        tape,
        (&scalar_order, &scalar_bodies, &pending),
        Lanes::One,
        cx,
        cy,
    )?;
    store_outputs(&mut b, Lanes::One, outputs, co);
    let nx = b.ins().iadd_imm_u(cx, 8);
    let ny = b.ins().iadd_imm_u(cy, 8);
    let no = b.ins().iadd_imm_u(co, 48);
    b.def_var(px, nx);
    b.def_var(py, ny);
    b.def_var(po, no);
    b.ins().jump(head, &[]);

    b.switch_to_block(exit);
    b.ins().return_(&[]);
    b.seal_all_blocks();
    let frontend = emit.module.target_config();
    b.finalize(frontend);

    module
        .define_function(id, &mut ctx)
        .map_err(|e| JitError(format!("compiling the kernel: {e:?}")))?;
    Ok(id)
}

/// The operands of a node, each once (`x · x` reads x once).
fn operands(node: Node) -> impl Iterator<Item = Id> {
    let (a, b, c) = match node {
        // A loop's operands are its inputs (`Loops`).
        Node::Const(_) | Node::Var(_) | Node::Carried(_) | Node::Repeat { .. } => {
            (None, None, None)
        }
        Node::Unary(_, a) | Node::PowI(a, _) | Node::Step(a) => (Some(a), None, None),
        Node::Binary(_, a, b) => (Some(a), Some(b).filter(|&b| b != a), None),
        Node::Select(c, a, b) => (
            Some(c),
            Some(a).filter(|&a| a != c),
            Some(b).filter(|&b| b != c && b != a),
        ),
    };
    [a, b, c].into_iter().flatten()
}

/// The loops of a tape's live part (`Node::Repeat`): each is emitted as
/// one block that branches back to itself, its body once, and is
/// scheduled outside as one node that reads its inputs.
struct Loops {
    /// The body of each live loop, in the order it is emitted (the tape's).
    bodies: HashMap<Id, Vec<Id>>,
    /// Indexed by node (empty where the tape has no loop): what each loop
    /// reads from outside its body, its initial value first, each once.
    inputs: Vec<Vec<Id>>,
    /// Indexed by node (empty where the tape has no loop): whether it is
    /// in a body or is a loop's estimate, emitted inside its loop.
    inside: Vec<bool>,
}

impl Loops {
    fn of(tape: &SurfaceTape, live: &[Id]) -> Loops {
        let graph = &tape.graph;
        let mut loops = Loops {
            bodies: HashMap::new(),
            inputs: Vec::new(),
            inside: Vec::new(),
        };
        for &id in live {
            let Node::Repeat {
                carried,
                init,
                next,
                ..
            } = graph.node(id)
            else {
                continue;
            };
            if loops.inside.is_empty() {
                loops.inside = vec![false; graph.len()];
                loops.inputs = vec![Vec::new(); graph.len()];
            }
            let body = graph.loop_body(carried, next);
            loops.inside[carried.0 as usize] = true;
            for &i in &body {
                loops.inside[i.0 as usize] = true;
            }
            let mut inputs = vec![init];
            for &i in &body {
                for o in operands(graph.node(i)) {
                    let outside = o != carried && body.binary_search(&o).is_err();
                    if outside && !inputs.contains(&o) {
                        inputs.push(o);
                    }
                }
            }
            loops.inputs[id.0 as usize] = inputs;
            loops.bodies.insert(id, body);
        }
        loops
    }

    /// The nodes `id` reads, each once: its operands, or a loop's inputs.
    fn deps(&self, tape: &SurfaceTape, id: Id) -> impl Iterator<Item = Id> {
        let inputs = self
            .inputs
            .get(id.0 as usize)
            .map_or(&[][..], Vec::as_slice);
        operands(tape.graph.node(id)).chain(inputs.iter().copied())
    }

    fn is_inside(&self, id: Id) -> bool {
        self.inside.get(id.0 as usize).copied().unwrap_or(false)
    }
}

/// The largest live tape `emission_order` schedules (the examples' largest
/// is 640 nodes).
const SCHEDULED_NODES: usize = 4096;

/// The order the live nodes of a pass are emitted in: the tape's own, or
/// a schedule that keeps fewer values waiting for their last use,
/// whichever keeps fewer (summed over the pass). The order changes no
/// value (each node is the same IEEE operations on the same operands); it
/// changes how many values the register allocator must keep at once,
/// which is most of the compile time of a big tape and the spills of its
/// code, and how much of a pass the core can overlap.
/// Outside its loop, a loop is one node; its body is ordered the same way
/// on its own (`body_orders`).
fn emission_order(tape: &SurfaceTape, live: &[Id], loops: &Loops, lanes: Lanes) -> Vec<Id> {
    let live: Vec<Id> = live
        .iter()
        .copied()
        .filter(|&id| !loops.is_inside(id))
        .collect();
    // The schedule scans the ready nodes for each node it places: bounded
    // here so that a huge tape costs no quadratic time before cranelift.
    if live.len() > SCHEDULED_NODES {
        return live;
    }
    let ahead = match lanes {
        Lanes::One => Ahead::Operations,
        Lanes::Two => Ahead::Latency,
    };
    let scheduled = pressure_schedule(tape, loops, &live, ahead);
    if waiting(tape, loops, &scheduled) < waiting(tape, loops, &live) {
        scheduled
    } else {
        live
    }
}

/// The order each loop's body is emitted in, by the rule of
/// `emission_order`.
fn body_orders(tape: &SurfaceTape, loops: &Loops, lanes: Lanes) -> HashMap<Id, Vec<Id>> {
    let ahead = match lanes {
        Lanes::One => Ahead::Operations,
        Lanes::Two => Ahead::Latency,
    };
    loops
        .bodies
        .iter()
        .map(|(&id, body)| {
            let scheduled = pressure_schedule(tape, loops, body, ahead);
            let order = if body.len() <= SCHEDULED_NODES
                && waiting(tape, loops, &scheduled) < waiting(tape, loops, body)
            {
                scheduled
            } else {
                body.clone()
            };
            (id, order)
        })
        .collect()
}

/// How long the values of an order wait, in nodes, from their definition
/// to their last use (the outputs are used at the end of the pass).
fn waiting(tape: &SurfaceTape, loops: &Loops, order: &[Id]) -> usize {
    let mut last = vec![0usize; tape.graph.len()];
    for (i, &id) in order.iter().enumerate() {
        for o in loops.deps(tape, id) {
            last[o.0 as usize] = i;
        }
    }
    for o in tape.outputs {
        last[o.0 as usize] = order.len();
    }
    order
        .iter()
        .enumerate()
        .map(|(i, &id)| last[id.0 as usize].saturating_sub(i))
        .sum()
}

/// How `pressure_schedule` weighs the work between a node and the
/// outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ahead {
    /// Operations, each counted once: the scalar pass, which one point at
    /// a time (`eval`) runs fastest in this order (measured: the conic +
    /// A4…A16 one-point eval 15.3 ns against 19.2 ns by latency).
    Operations,
    /// Estimated cycles of latency (`latency`): the vector pass, where
    /// starting the long chains early lets the core overlap them with the
    /// rest of the pass (measured: the conic + A4…A16 batch 5.62 → 5.42
    /// ns/point).
    Latency,
}

/// A rough latency in cycles of a node's code on a current x86-64 core,
/// for ordering only: what matters is that square roots, divisions and
/// the inline or called functions weigh more than an add.
fn latency(node: Node) -> i32 {
    match node {
        Node::Const(_) | Node::Var(_) | Node::Carried(_) => 0,
        // Each step a chain of several long operations (a Newton step:
        // the function, its slope, a division).
        Node::Repeat { steps, .. } => 60 * steps.min(1000) as i32,
        Node::Unary(Unary::Neg | Unary::Abs, _) => 1,
        Node::Unary(Unary::Sqrt, _) => 20,
        Node::Unary(Unary::Floor, _) | Node::Step(_) | Node::Select(..) => 3,
        Node::Unary(_, _) => 60,
        Node::Binary(Binary::Div, _, _) => 13,
        Node::Binary(Binary::Pow | Binary::Atan2, _, _) => 60,
        Node::Binary(_, _, _) => 3,
        Node::PowI(_, k) => {
            // Squarings on the chain, plus the division of a negative power.
            let squarings = 32 - k.unsigned_abs().leading_zeros() as i32;
            3 * squarings.max(1) + if k < 0 { 13 } else { 0 }
        }
    }
}

/// A list schedule of the live nodes: of the nodes whose operands are
/// all emitted, next the one that is the last use of the most values;
/// among equals the one with the most work between it and the furthest
/// output (`ahead`), then the earliest in the tape. A differentiated tape
/// lists a value's whole chain before the derivatives that reuse its
/// intermediates; this interleaves them.
fn pressure_schedule(tape: &SurfaceTape, loops: &Loops, live: &[Id], ahead: Ahead) -> Vec<Id> {
    let n = tape.graph.len();
    let node = |id: Id| tape.graph.node(id);
    // What the list reads from outside it (a loop body's inputs) is there
    // all along.
    let mut listed = vec![false; n];
    for &id in live {
        listed[id.0 as usize] = true;
    }
    let deps = |id: Id| loops.deps(tape, id).filter(|o| listed[o.0 as usize]);
    // Work to the furthest output, negated: smaller is needed sooner.
    let mut level = vec![0i32; n];
    for &id in live.iter().rev() {
        let h = level[id.0 as usize];
        let step = match ahead {
            Ahead::Operations => 1,
            Ahead::Latency => latency(node(id)),
        };
        for o in deps(id) {
            level[o.0 as usize] = level[o.0 as usize].min(h - step);
        }
    }
    // Uses not yet emitted; an output is never released.
    let mut uses = vec![0u32; n];
    let mut unready = vec![0u32; n];
    let mut ready = Vec::new();
    for &id in live {
        for o in deps(id) {
            uses[o.0 as usize] += 1;
            unready[id.0 as usize] += 1;
        }
        if unready[id.0 as usize] == 0 {
            ready.push(id);
        }
    }
    // The users of node i, in tape order, are users[first[i]..first[i + 1]]
    // (one list for all: a vector per node made allocation most of the
    // schedule's time).
    let mut first = vec![0u32; n + 1];
    for i in 0..n {
        first[i + 1] = first[i] + uses[i];
    }
    let mut filled = first.clone();
    let mut users = vec![Id(0); first[n] as usize];
    for &id in live {
        for o in deps(id) {
            let slot = &mut filled[o.0 as usize];
            users[*slot as usize] = id;
            *slot += 1;
        }
    }
    for o in tape.outputs {
        uses[o.0 as usize] = u32::MAX / 2;
    }
    // The values each ready node is the last use of, kept up to date as
    // nodes are placed (recounted for every ready node at every step, this
    // was most of the schedule's time).
    let last_uses =
        |id: Id, uses: &[u32]| deps(id).filter(|o| uses[o.0 as usize] == 1).count() as u32;
    let mut kills = vec![0u32; n];
    for &id in &ready {
        kills[id.0 as usize] = last_uses(id, &uses);
    }
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(live.len());
    while !ready.is_empty() {
        let key = |id: Id| {
            let i = id.0 as usize;
            (std::cmp::Reverse(kills[i]), level[i], id.0)
        };
        let next = (0..ready.len())
            .min_by_key(|&k| key(ready[k]))
            .expect("ready is not empty");
        let id = ready.swap_remove(next);
        order.push(id);
        placed[id.0 as usize] = true;
        for o in deps(id) {
            let o = o.0 as usize;
            uses[o] -= 1;
            if uses[o] == 1 {
                // Its one user left now frees it, if that user is ready
                // (one not yet ready counts it when it becomes ready).
                let left = users[first[o] as usize..first[o + 1] as usize]
                    .iter()
                    .find(|u| !placed[u.0 as usize]);
                if let Some(&u) = left.filter(|u| unready[u.0 as usize] == 0) {
                    kills[u.0 as usize] += 1;
                }
            }
        }
        let i = id.0 as usize;
        for &u in &users[first[i] as usize..first[i + 1] as usize] {
            unready[u.0 as usize] -= 1;
            if unready[u.0 as usize] == 0 {
                kills[u.0 as usize] = last_uses(u, &uses);
                ready.push(u);
            }
        }
    }
    order
}

/// The values of a pass's nodes so far. A negation emits nothing: its
/// node holds its operand's value with `negated` set, and its users take
/// the sign in (`Emitter::node`) or apply it (`Emitter::plain`).
struct Values {
    val: Vec<Option<Value>>,
    /// Whether the value held is the negation of the node's.
    negated: Vec<bool>,
    /// Whether a node's value may be held with its negation pending
    /// (`pending_negations`).
    pending: Vec<bool>,
}

/// Where a negation may stay pending: at a node with one user (which
/// takes it in, or applies it in place of the node), or whose users all
/// take it in for free — sums and differences, even powers, and products,
/// quotients, odd powers and negations whose own pending negation is free
/// in the same sense. A difference may still apply it once (`Emitter::plain`
/// keeps the result). So no more negations are applied than the tape
/// writes; a value with several users of other kinds is negated once,
/// where it is computed.
fn pending_negations(tape: &SurfaceTape, live: &[Id]) -> Vec<bool> {
    let n = tape.graph.len();
    let mut users = vec![0u32; n];
    let mut free = vec![true; n];
    for o in tape.outputs {
        users[o.0 as usize] += 1;
        free[o.0 as usize] = false;
    }
    // Users come after their operands: backwards, each node's own
    // freedom is settled before its operands are judged by it.
    for &id in live.iter().rev() {
        let node = tape.graph.node(id);
        let takes_in = match node {
            Node::Binary(Binary::Add | Binary::Sub, _, _) => true,
            Node::PowI(_, k) if k % 2 == 0 => true,
            Node::Binary(Binary::Mul | Binary::Div, _, _)
            | Node::PowI(_, _)
            | Node::Unary(Unary::Neg, _) => free[id.0 as usize],
            _ => false,
        };
        for o in operands(node) {
            users[o.0 as usize] += 1;
            free[o.0 as usize] &= takes_in;
        }
        if let Node::Repeat { init, next, .. } = node {
            for o in [init, next] {
                users[o.0 as usize] += 1;
                free[o.0 as usize] = false;
            }
        }
    }
    (0..n).map(|i| users[i] == 1 || free[i]).collect()
}

/// A loop to emit: its node's fields and its body (`Loops`).
#[derive(Clone, Copy)]
struct Loop<'a> {
    carried: Id,
    init: Id,
    next: Id,
    steps: u32,
    body: &'a [Id],
}

/// Emits operations, importing each libm wrapper at most once.
struct Emitter<'m> {
    module: &'m mut JITModule,
    imports: HashMap<Libm, FuncRef>,
    /// sin and cos of each argument already reduced in this pass.
    trig: HashMap<Id, (Value, Value)>,
    /// The comparison `a < 0` of each node already tested in this pass (a
    /// lenslet array's outputs are all selected by one test).
    negative: HashMap<Id, Value>,
    /// The lane masks of where the inline sin, cos and exp of this (vector)
    /// pass hold.
    covered: Vec<Value>,
    /// −0 in every lane (the sign bit alone) once a negation of this pass
    /// needed it.
    sign: Option<Value>,
}

impl Emitter<'_> {
    /// One pass of the live tape for the point(s) at the cursors: loads x
    /// and y, evaluates every node in `order` (`emission_order`), returns the six outputs (on two lanes,
    /// with the masks of where the inline sin, cos and exp hold in
    /// `covered`).
    fn pass(
        &mut self,
        b: &mut FunctionBuilder,
        tape: &SurfaceTape,
        (order, bodies, pending): (&[Id], &HashMap<Id, Vec<Id>>, &[bool]),
        lanes: Lanes,
        cx: Value,
        cy: Value,
    ) -> Result<[Value; 6], JitError> {
        // Slices of f64 are 8-aligned, so a pair is not always 16-aligned.
        let load = match lanes {
            Lanes::One => MemFlagsData::trusted(),
            Lanes::Two => MemFlagsData::new().with_notrap(),
        };
        let x = b.ins().load(lanes.ty(), load, cx, 0);
        let y = b.ins().load(lanes.ty(), load, cy, 0);
        self.trig.clear();
        self.negative.clear();
        self.covered.clear();
        self.sign = None;
        let mut vals = Values {
            val: vec![None; tape.graph.len()],
            negated: vec![false; tape.graph.len()],
            pending: pending.to_vec(),
        };
        for &id in order {
            let (v, negated) = match tape.graph.node(id) {
                Node::Repeat {
                    carried,
                    init,
                    next,
                    steps,
                } => {
                    let body = bodies.get(&id).map_or(&[][..], Vec::as_slice);
                    let l = Loop {
                        carried,
                        init,
                        next,
                        steps,
                        body,
                    };
                    (self.repeat(b, tape, lanes, l, &mut vals, (x, y))?, false)
                }
                _ => self.node(b, tape, lanes, id, &mut vals, (x, y))?,
            };
            self.keep(b, lanes, &mut vals, id, (v, negated));
        }
        let mut outputs = [x; 6];
        for (k, &o) in tape.outputs.iter().enumerate() {
            outputs[k] = self.plain(b, lanes, &mut vals, o)?;
        }
        Ok(outputs)
    }

    /// Records node `id`'s value; a pending negation stays pending only
    /// where `Values::pending` allows, else it is applied now.
    fn keep(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        vals: &mut Values,
        id: Id,
        (v, negated): (Value, bool),
    ) {
        let i = id.0 as usize;
        let (v, negated) = if negated && !vals.pending[i] {
            (self.negate(b, lanes, v), false)
        } else {
            (v, negated)
        };
        vals.val[i] = Some(v);
        vals.negated[i] = negated;
    }

    /// The value of node `i` as computed, and whether it is the node's
    /// negation (`Values`).
    fn raw(vals: &Values, i: Id) -> Result<(Value, bool), JitError> {
        let v = vals.val[i.0 as usize]
            .ok_or_else(|| JitError(format!("node {} used before it is computed", i.0)))?;
        Ok((v, vals.negated[i.0 as usize]))
    }

    /// The value of node `i`, its pending negation applied (once: the
    /// result replaces it).
    fn plain(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        vals: &mut Values,
        i: Id,
    ) -> Result<Value, JitError> {
        let (v, negated) = Self::raw(vals, i)?;
        if !negated {
            return Ok(v);
        }
        let v = self.negate(b, lanes, v);
        vals.val[i.0 as usize] = Some(v);
        vals.negated[i.0 as usize] = false;
        Ok(v)
    }

    /// −a: the sign bit flipped, as `fneg` does, by one xor with a
    /// constant shared by the pass (cranelift's `fneg` builds its mask
    /// anew each time: three or four instructions and a register).
    fn negate(&mut self, b: &mut FunctionBuilder, lanes: Lanes, a: Value) -> Value {
        let sign = *self
            .sign
            .get_or_insert_with(|| constant(b, lanes, (-0f64).to_bits()));
        b.ins().bxor(a, sign)
    }

    /// The value of node `id` (no loop) from the values so far, and
    /// whether it is the node's negation (`Values`): a negation emits
    /// nothing, and products, quotients, sums and differences take their
    /// operands' pending negations in, where the identity is exact.
    fn node(
        &mut self,
        b: &mut FunctionBuilder,
        tape: &SurfaceTape,
        lanes: Lanes,
        id: Id,
        vals: &mut Values,
        (x, y): (Value, Value),
    ) -> Result<(Value, bool), JitError> {
        let graph = &tape.graph;
        Ok(match graph.node(id) {
            Node::Unary(Unary::Neg, a) => {
                let (v, negated) = Self::raw(vals, a)?;
                (v, !negated)
            }
            // (−a)·b = a·(−b) = −(a·b) and likewise for a quotient, bit
            // for bit: rounding to nearest is symmetric about zero, and
            // the sign of a product or quotient (of zero too) is the
            // exclusive or of its operands' signs.
            Node::Binary(op @ (Binary::Mul | Binary::Div), l, r) => {
                let ((vl, nl), (vr, nr)) = (Self::raw(vals, l)?, Self::raw(vals, r)?);
                let v = if op == Binary::Mul {
                    b.ins().fmul(vl, vr)
                } else {
                    b.ins().fdiv(vl, vr)
                };
                (v, nl != nr)
            }
            // a − b is a + (−b) in IEEE 754, and a sum does not depend on
            // the order of its operands: with −a or −b pending, a + b, a −
            // b, b − a serve exactly. Where the result would be −(a + b)
            // (which differs in the sign of a zero sum), the left
            // operand's negation is applied instead.
            Node::Binary(op @ (Binary::Add | Binary::Sub), l, r) => {
                let (nl, nr) = (Self::raw(vals, l)?.1, Self::raw(vals, r)?.1);
                let add = op == Binary::Add;
                // The result is l + (±vr): vr enters negated where it is
                // added with its negation pending or subtracted without.
                let r_minus = add == nr;
                let vr = Self::raw(vals, r)?.0;
                if nl && r_minus {
                    // −vl − vr would be −(vl + vr): apply l's negation.
                    let vl = self.plain(b, lanes, vals, l)?;
                    (b.ins().fsub(vl, vr), false)
                } else if nl {
                    // −vl + vr = vr − vl.
                    let vl = Self::raw(vals, l)?.0;
                    (b.ins().fsub(vr, vl), false)
                } else {
                    let vl = Self::raw(vals, l)?.0;
                    let v = if r_minus {
                        b.ins().fsub(vl, vr)
                    } else {
                        b.ins().fadd(vl, vr)
                    };
                    (v, false)
                }
            }
            // (−a)^n is a^n for even n and −(a^n) for odd n, bit for bit:
            // the squarings of the expansion lose the sign and each
            // product (or the reciprocal of a negative n) keeps it.
            Node::PowI(a, k) => {
                let (v, negated) = Self::raw(vals, a)?;
                (powi(b, lanes, v, k), negated && k % 2 != 0)
            }
            _ => {
                for o in operands(graph.node(id)) {
                    self.plain(b, lanes, vals, o)?;
                }
                (
                    self.node_plain(b, tape, lanes, id, &vals.val, (x, y))?,
                    false,
                )
            }
        })
    }

    /// The value of node `id` from its operands' values `val` (no pending
    /// negation among them).
    fn node_plain(
        &mut self,
        b: &mut FunctionBuilder,
        tape: &SurfaceTape,
        lanes: Lanes,
        id: Id,
        val: &[Option<Value>],
        (x, y): (Value, Value),
    ) -> Result<Value, JitError> {
        let graph = &tape.graph;
        // Operands come before their node in the order; should one not,
        // the kernel is not built (no panic).
        let get = |i: Id| {
            val[i.0 as usize]
                .ok_or_else(|| JitError(format!("node {} used before it is computed", i.0)))
        };
        Ok(match graph.node(id) {
            Node::Const(bits) => constant(b, lanes, bits),
            Node::Var(Var::X) => x,
            Node::Var(Var::Y) => y,
            Node::Unary(op @ (Unary::Sin | Unary::Cos), a) => {
                let (sin, cos) = self.sin_cos(b, lanes, a, get(a)?)?;
                if op == Unary::Sin { sin } else { cos }
            }
            Node::Unary(op, a) => self.unary(b, lanes, op, get(a)?)?,
            Node::Binary(op @ (Binary::Min | Binary::Max), l, r) => {
                let l = (get(l)?, graph.constant(l));
                let r = (get(r)?, graph.constant(r));
                min_max(b, lanes, op, l, r)
            }
            Node::Binary(op, a, c) => self.binary(b, lanes, op, get(a)?, get(c)?)?,
            Node::PowI(a, k) => powi(b, lanes, get(a)?, k),
            Node::Step(a) => {
                // 1 where a < 0 (false for NaN), else 0.
                let neg = self.negative(b, lanes, a, get(a)?);
                let zero = constant(b, lanes, 0f64.to_bits());
                let one = constant(b, lanes, 1f64.to_bits());
                select_known(b, lanes, neg, (one, Some(1.0)), (zero, Some(0.0)))
            }
            Node::Select(c, t, f) => {
                // t where c < 0 (false for NaN), else f.
                let neg = self.negative(b, lanes, c, get(c)?);
                let t = (get(t)?, graph.constant(t));
                let f = (get(f)?, graph.constant(f));
                select_known(b, lanes, neg, t, f)
            }
            // A loop's estimate is defined by its loop (`repeat`); loops
            // are not nested (`Graph::repeat`).
            Node::Carried(_) | Node::Repeat { .. } => get(id)?,
        })
    }

    /// A loop: one block that runs the body once per step and branches
    /// back to itself, the estimate and the count of steps its
    /// parameters (cranelift variables):
    ///
    /// ```text
    /// p = init; k = 0; goto step
    /// step: the body, over p; p = next; k += 1; if k < steps goto step
    /// after: the value is p
    /// ```
    ///
    /// The body's values from the last step remain visible after it (the
    /// block dominates what follows), which the caches rely on. On two
    /// lanes, the masks of where the body's inline sin, cos and exp hold
    /// are joined over every step.
    fn repeat(
        &mut self,
        b: &mut FunctionBuilder,
        tape: &SurfaceTape,
        lanes: Lanes,
        l: Loop,
        vals: &mut Values,
        xy: (Value, Value),
    ) -> Result<Value, JitError> {
        let init = self.plain(b, lanes, vals, l.init)?;
        if l.steps == 0 {
            return Ok(init);
        }
        let estimate = b.declare_var(lanes.ty());
        b.def_var(estimate, init);
        let count = b.declare_var(types::I32);
        let zero = b.ins().iconst(types::I32, 0);
        b.def_var(count, zero);
        let masked = lanes == Lanes::Two
            && l.body.iter().any(|&i| {
                matches!(
                    tape.graph.node(i),
                    Node::Unary(Unary::Sin | Unary::Cos | Unary::Exp, _)
                )
            });
        let covered = b.declare_var(types::I64X2);
        if masked {
            let ones = b.func.dfg.constants.insert(vec![0xffu8; 16].into());
            let all = b.ins().vconst(types::I64X2, ones);
            b.def_var(covered, all);
        }
        let step = b.create_block();
        let after = b.create_block();
        b.ins().jump(step, &[]);

        b.switch_to_block(step);
        vals.val[l.carried.0 as usize] = Some(b.use_var(estimate));
        vals.negated[l.carried.0 as usize] = false;
        let masks_before = self.covered.len();
        for &i in l.body {
            let value = self.node(b, tape, lanes, i, vals, xy)?;
            self.keep(b, lanes, vals, i, value);
        }
        if masked {
            let mut all = b.use_var(covered);
            for m in self.covered.split_off(masks_before) {
                all = b.ins().band(all, m);
            }
            b.def_var(covered, all);
        }
        let next = self.plain(b, lanes, vals, l.next)?;
        b.def_var(estimate, next);
        let k = b.use_var(count);
        let k = b.ins().iadd_imm_u(k, 1);
        b.def_var(count, k);
        let more = b
            .ins()
            .icmp_imm_u(IntCC::UnsignedLessThan, k, i64::from(l.steps));
        b.ins().brif(more, step, &[], after, &[]);

        b.switch_to_block(after);
        if masked {
            let all = b.use_var(covered);
            self.covered.push(all);
        }
        Ok(b.use_var(estimate))
    }

    /// The cached test `a < 0` (false for NaN) of node `id`: a flag with
    /// one lane, a lane mask with two.
    fn negative(&mut self, b: &mut FunctionBuilder, lanes: Lanes, id: Id, a: Value) -> Value {
        if let Some(&neg) = self.negative.get(&id) {
            return neg;
        }
        let zero = constant(b, lanes, 0f64.to_bits());
        let neg = b.ins().fcmp(FloatCC::LessThan, a, zero);
        self.negative.insert(id, neg);
        neg
    }

    /// sin a and cos a (node `arg`, value `a`), reduced once per argument:
    /// inline on two lanes, the mask of the lanes they cover joining
    /// `covered`; one call on one lane.
    fn sin_cos(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        arg: Id,
        a: Value,
    ) -> Result<(Value, Value), JitError> {
        if let Some(&pair) = self.trig.get(&arg) {
            return Ok(pair);
        }
        let pair = self.sin_cos_of(b, lanes, a)?;
        self.trig.insert(arg, pair);
        Ok(pair)
    }

    /// sin a and cos a, computed here.
    fn sin_cos_of(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        a: Value,
    ) -> Result<(Value, Value), JitError> {
        Ok(match lanes {
            Lanes::Two => {
                let (sin, cos, ok) = vecmath::sin_cos(b, a);
                self.covered.push(ok);
                (sin, cos)
            }
            Lanes::One => {
                let fref = self.import(b, Libm::SinCos)?;
                let call = b.ins().call(fref, &[a]);
                let &[sin, cos] = b.inst_results(call) else {
                    unreachable!("sin_cos returns two values")
                };
                (sin, cos)
            }
        })
    }

    fn unary(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        op: Unary,
        a: Value,
    ) -> Result<Value, JitError> {
        Ok(match op {
            Unary::Neg => self.negate(b, lanes, a),
            Unary::Sqrt => b.ins().sqrt(a),
            Unary::Abs => b.ins().fabs(a),
            Unary::Floor => b.ins().floor(a),
            Unary::Exp if lanes == Lanes::Two => {
                let (e, ok) = vecmath::exp(b, a);
                self.covered.push(ok);
                e
            }
            // The scalar pass calls the twins of the inline code.
            Unary::Exp => self.call(b, lanes, Libm::Exp, &[a])?,
            Unary::Sin | Unary::Cos => {
                let (sin, cos) = self.sin_cos_of(b, lanes, a)?;
                if op == Unary::Sin { sin } else { cos }
            }
            Unary::Tan => self.call(b, lanes, Libm::Tan, &[a])?,
            Unary::Asin => self.call(b, lanes, Libm::Asin, &[a])?,
            Unary::Acos => self.call(b, lanes, Libm::Acos, &[a])?,
            Unary::Atan => self.call(b, lanes, Libm::Atan, &[a])?,
            Unary::Ln => self.call(b, lanes, Libm::Ln, &[a])?,
        })
    }

    fn binary(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        op: Binary,
        l: Value,
        r: Value,
    ) -> Result<Value, JitError> {
        Ok(match op {
            Binary::Add => b.ins().fadd(l, r),
            Binary::Sub => b.ins().fsub(l, r),
            Binary::Mul => b.ins().fmul(l, r),
            Binary::Div => b.ins().fdiv(l, r),
            Binary::Pow => self.call(b, lanes, Libm::Pow, &[l, r])?,
            Binary::Atan2 => self.call(b, lanes, Libm::Atan2, &[l, r])?,
            Binary::Min | Binary::Max => min_max(b, lanes, op, (l, None), (r, None)),
        })
    }

    /// The import of a wrapper, declared once.
    fn import(&mut self, b: &mut FunctionBuilder, f: Libm) -> Result<FuncRef, JitError> {
        if let Some(&r) = self.imports.get(&f) {
            return Ok(r);
        }
        let mut sig = self.module.make_signature();
        for _ in 0..f.arity() {
            sig.params.push(AbiParam::new(types::F64));
        }
        for _ in 0..f.results() {
            sig.returns.push(AbiParam::new(types::F64));
        }
        let fid = self
            .module
            .declare_function(f.symbol(), Linkage::Import, &sig)
            .map_err(|e| JitError(format!("declaring {}: {e}", f.symbol())))?;
        let r = self.module.declare_func_in_func(fid, b.func);
        self.imports.insert(f, r);
        Ok(r)
    }

    /// Calls a scalar wrapper, once per lane.
    fn call(
        &mut self,
        b: &mut FunctionBuilder,
        lanes: Lanes,
        f: Libm,
        args: &[Value],
    ) -> Result<Value, JitError> {
        let fref = self.import(b, f)?;
        let call = |b: &mut FunctionBuilder, args: &[Value]| {
            let inst = b.ins().call(fref, args);
            b.inst_results(inst)[0]
        };
        Ok(match lanes {
            Lanes::One => call(b, args),
            Lanes::Two => {
                let lane = |b: &mut FunctionBuilder, i: u8| {
                    let a: Vec<Value> = args.iter().map(|&a| b.ins().extractlane(a, i)).collect();
                    call(b, &a)
                };
                let lo = lane(b, 0);
                let hi = lane(b, 1);
                let v = b.ins().scalar_to_vector(types::F64X2, lo);
                b.ins().insertlane(v, hi, 1)
            }
        })
    }
}

/// Stores the six outputs of the point(s) of a pass at `co`.
fn store_outputs(b: &mut FunctionBuilder, lanes: Lanes, outputs: [Value; 6], co: Value) {
    match lanes {
        Lanes::One => {
            for (k, &v) in outputs.iter().enumerate() {
                b.ins().store(MemFlagsData::trusted(), v, co, 8 * k as i32);
            }
        }
        Lanes::Two => {
            // Outputs k and k + 1 of the first point side by side, then
            // of the second: three 16-byte stores per point rather
            // than six 8-byte ones and six lane extractions.
            let bytes = |v: Value, b: &mut FunctionBuilder| {
                b.ins().bitcast(
                    types::I8X16,
                    MemFlagsData::new().with_endianness(Endianness::Little),
                    v,
                )
            };
            // Slices of f64 are 8-aligned, so a pair is not always
            // 16-aligned.
            let mem = MemFlagsData::new().with_notrap();
            let mask = |b: &mut FunctionBuilder, lanes: [std::ops::Range<u8>; 2]| {
                let [first, second] = lanes;
                let bytes: Vec<u8> = first.chain(second).collect();
                b.func.dfg.immediates.push(bytes.into())
            };
            // The first lane of each vector; the second.
            let low = mask(b, [0..8, 16..24]);
            let high = mask(b, [8..16, 24..32]);
            for k in (0..6).step_by(2) {
                let (a, c) = (bytes(outputs[k], b), bytes(outputs[k + 1], b));
                let first = b.ins().shuffle(a, c, low);
                let second = b.ins().shuffle(a, c, high);
                b.ins().store(mem, first, co, 8 * k as i32);
                b.ins().store(mem, second, co, 48 + 8 * k as i32);
            }
        }
    }
}

/// A constant, in every lane.
fn constant(b: &mut FunctionBuilder, lanes: Lanes, bits: u64) -> Value {
    match lanes {
        Lanes::One => b.ins().f64const(Ieee64::with_bits(bits)),
        Lanes::Two => {
            let mut bytes = bits.to_le_bytes().to_vec();
            bytes.extend_from_slice(&bits.to_le_bytes());
            let c = b.func.dfg.constants.insert(bytes.into());
            b.ins().vconst(types::F64X2, c)
        }
    }
}

/// `cond ? t : f` lane by lane, for a condition from `fcmp` or `icmp`: a
/// flag with one lane, a lane mask with two.
fn select(b: &mut FunctionBuilder, lanes: Lanes, cond: Value, t: Value, f: Value) -> Value {
    select_known(b, lanes, cond, (t, None), (f, None))
}

/// `select` where either operand may be a known constant: with two lanes a
/// +0 operand makes the blend a bitwise and (the mask's lanes are all ones
/// or all zeros, and +0 is all zero bits).
fn select_known(
    b: &mut FunctionBuilder,
    lanes: Lanes,
    cond: Value,
    (t, tc): (Value, Option<f64>),
    (f, fc): (Value, Option<f64>),
) -> Value {
    let plus_zero = |c: Option<f64>| c.is_some_and(|c| c.to_bits() == 0);
    match lanes {
        Lanes::One => b.ins().select(cond, t, f),
        Lanes::Two => {
            let mask = b.ins().bitcast(types::F64X2, MemFlagsData::new(), cond);
            if plus_zero(fc) {
                b.ins().band(mask, t)
            } else if plus_zero(tc) {
                b.ins().band_not(f, mask)
            } else {
                b.ins().bitselect(mask, t, f)
            }
        }
    }
}

/// Rust's `l.min(r)` / `l.max(r)` (LLVM minnum/maxnum on x86-64): l is
/// NaN → r; else r if r is strictly smaller (greater), else l. So a NaN r
/// yields l, and equal operands (±0) yield l. cranelift's fmin/fmax
/// propagate NaN and order −0 < +0 instead, so this is a select sequence;
/// with a constant operand (`Some(value)`), a shorter one that gives the
/// same bits for every other operand. Each select whose condition is `x <
/// y` and whose operands are x and y is a single `minpd`/`maxpd` on two
/// lanes (x if x < y, else y).
fn min_max(
    b: &mut FunctionBuilder,
    lanes: Lanes,
    op: Binary,
    (l, lc): (Value, Option<f64>),
    (r, rc): (Value, Option<f64>),
) -> Value {
    let min = op == Binary::Min;
    match (lc, rc) {
        // A non-NaN constant c on the right: c where l is NaN or c is
        // strictly smaller (greater), else l.
        (_, Some(c)) if !c.is_nan() => {
            if c != 0.0 {
                // Equal operands have the same bits, so "l where l < c
                // (> c), else c" is the same: one minpd (maxpd).
                let l_wins = if min {
                    b.ins().fcmp(FloatCC::LessThan, l, r)
                } else {
                    b.ins().fcmp(FloatCC::LessThan, r, l)
                };
                select(b, lanes, l_wins, l, r)
            } else {
                // ±0: equal is not the same bits; keep l on a tie.
                let cc = if min {
                    FloatCC::UnorderedOrGreaterThan
                } else {
                    FloatCC::UnorderedOrLessThan
                };
                let r_wins = b.ins().fcmp(cc, l, r);
                select_known(b, lanes, r_wins, (r, rc), (l, lc))
            }
        }
        _ => {
            // r where r is strictly smaller (greater), else l: one
            // minpd (maxpd); a NaN r yields l.
            let r_wins = if min {
                b.ins().fcmp(FloatCC::LessThan, r, l)
            } else {
                b.ins().fcmp(FloatCC::LessThan, l, r)
            };
            let m = select(b, lanes, r_wins, r, l);
            if lc.is_some_and(|c| !c.is_nan()) {
                // l is no NaN.
                return m;
            }
            let l_nan = b.ins().fcmp(FloatCC::Unordered, l, l);
            select(b, lanes, l_nan, r, m)
        }
    }
}

/// a^n by repeated squaring, multiplying in the order of compiler-rt's
/// `__powidf2`, which Rust's `f64::powi` is: r = 1; for each bit of |n|
/// from the lowest, r *= a if set, then a *= a; 1/r for negative n. (The
/// leading `1 · a` is exact and left out.)
fn powi(b: &mut FunctionBuilder, lanes: Lanes, a: Value, n: i32) -> Value {
    let mut e = n.unsigned_abs();
    let mut square = a;
    let mut acc: Option<Value> = None;
    while e != 0 {
        if e & 1 == 1 {
            acc = Some(match acc {
                None => square,
                Some(r) => b.ins().fmul(r, square),
            });
        }
        e >>= 1;
        if e != 0 {
            square = b.ins().fmul(square, square);
        }
    }
    let r = match acc {
        Some(r) => r,
        None => constant(b, lanes, 1f64.to_bits()),
    };
    if n < 0 {
        let one = constant(b, lanes, 1f64.to_bits());
        b.ins().fdiv(one, r)
    } else {
        r
    }
}

/// The functions the kernel calls rather than inlines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Libm {
    /// sin and cos of one argument, two results.
    SinCos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    Pow,
    Atan2,
}

impl Libm {
    const ALL: [Libm; 9] = [
        Libm::SinCos,
        Libm::Tan,
        Libm::Asin,
        Libm::Acos,
        Libm::Atan,
        Libm::Exp,
        Libm::Ln,
        Libm::Pow,
        Libm::Atan2,
    ];

    fn symbol(self) -> &'static str {
        match self {
            Libm::SinCos => "lensc_jit_sin_cos",
            Libm::Tan => "lensc_jit_tan",
            Libm::Asin => "lensc_jit_asin",
            Libm::Acos => "lensc_jit_acos",
            Libm::Atan => "lensc_jit_atan",
            Libm::Exp => "lensc_jit_exp",
            Libm::Ln => "lensc_jit_ln",
            Libm::Pow => "lensc_jit_pow",
            Libm::Atan2 => "lensc_jit_atan2",
        }
    }

    fn arity(self) -> usize {
        match self {
            Libm::Pow | Libm::Atan2 => 2,
            _ => 1,
        }
    }

    fn results(self) -> usize {
        match self {
            Libm::SinCos => 2,
            _ => 1,
        }
    }

    fn address(self) -> *const u8 {
        type F1 = extern "C" fn(f64) -> f64;
        type F2 = extern "C" fn(f64, f64) -> f64;
        match self {
            Libm::SinCos => lensc_jit_sin_cos as extern "C" fn(f64) -> Pair as *const u8,
            Libm::Tan => lensc_jit_tan as F1 as *const u8,
            Libm::Asin => lensc_jit_asin as F1 as *const u8,
            Libm::Acos => lensc_jit_acos as F1 as *const u8,
            Libm::Atan => lensc_jit_atan as F1 as *const u8,
            Libm::Exp => lensc_jit_exp as F1 as *const u8,
            Libm::Ln => lensc_jit_ln as F1 as *const u8,
            Libm::Pow => lensc_jit_pow as F2 as *const u8,
            Libm::Atan2 => lensc_jit_atan2 as F2 as *const u8,
        }
    }
}

// The C-ABI entry points the kernel calls. sin, cos and exp are the twins
// of the kernel's inline code (`vecmath`, within 1 ulp of libm); each other
// is the interpreter's own function for that operation, so both backends
// share one implementation.
macro_rules! libm_entries {
    ($($name:ident = $kind:ident::$op:ident ($($arg:ident),+);)*) => {
        $(extern "C" fn $name($($arg: f64),+) -> f64 {
            libm_entries!(@apply $kind::$op, $($arg),+)
        })*
    };
    (@apply Unary::$op:ident, $a:ident) => { apply_unary(Unary::$op, $a) };
    (@apply Binary::$op:ident, $a:ident, $b:ident) => { apply_binary(Binary::$op, $a, $b) };
}

/// Two doubles returned in registers (xmm0, xmm1 in the C ABI of
/// x86-64), as cranelift returns two `F64` results.
#[repr(C)]
struct Pair(f64, f64);

extern "C" fn lensc_jit_sin_cos(a: f64) -> Pair {
    let (sin, cos) = crate::surface::fdlibm::sin_cos(a);
    Pair(sin, cos)
}

extern "C" fn lensc_jit_exp(a: f64) -> f64 {
    crate::surface::fdlibm::exp(a)
}

libm_entries! {
    lensc_jit_tan = Unary::Tan(a);
    lensc_jit_asin = Unary::Asin(a);
    lensc_jit_acos = Unary::Acos(a);
    lensc_jit_atan = Unary::Atan(a);
    lensc_jit_ln = Unary::Ln(a);
    lensc_jit_pow = Binary::Pow(a, b);
    lensc_jit_atan2 = Binary::Atan2(a, b);
}

#[cfg(test)]
mod tests {
    use super::JitSurface;
    use crate::surface::ir::SurfaceTape;

    impl crate::surface::conformance::Backend for JitSurface {
        fn build(tape: &SurfaceTape) -> Self {
            JitSurface::compile(tape).expect("the tape compiles")
        }
    }

    crate::surface::conformance::surface_fn_tests!(JitSurface);
}
