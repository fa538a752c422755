//! Surface kernels compiled once for each distinct tape and shared: a
//! build asks the JIT for the same tape several times (a spiral's surface
//! by its analysis, its tool checks, its trajectory, the axis it runs
//! past, its estimate, its planner and its report: seven compilations of
//! one tape, measured with `benches/compensate.rs`), and the compilation
//! of a large tape (a compensated surface's 1,400 live nodes) costs more
//! than evaluating it at the points those callers ask.
//!
//! A tape is known again by its nodes and outputs, compared whole (a hash
//! only finds the candidates): equal tapes compile to the same code, so a
//! shared kernel computes the very bits a fresh one would. The most
//! recently asked `CAPACITY` kernels are kept; one dropped from the list
//! lives on while an evaluator still holds it.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

use lensc_runtime::surface::ir::{Id, Node, SurfaceFn, SurfaceTape};
use lensc_runtime::surface::jit::{JitError, JitSurface};

/// How many compiled kernels the process keeps for tapes asked again (a
/// build asks at most four distinct tapes of the JIT: the surface, its
/// height alone, its slopes alone, a roller's axial section).
pub const CAPACITY: usize = 8;

/// A compiled kernel, shared by every evaluator of its tape.
#[derive(Clone)]
pub struct Shared(Arc<JitSurface>);

impl SurfaceFn for Shared {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        self.0.eval_batch(xs, ys, out)
    }
}

impl Shared {
    /// Whether two evaluators run the same compiled code.
    pub fn same(&self, other: &Shared) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A tape as it is recognised: every node and the outputs.
struct Key {
    hash: u64,
    nodes: Vec<Node>,
    outputs: [Id; 6],
}

impl Key {
    fn of(tape: &SurfaceTape) -> Key {
        let nodes = tape.graph.nodes().to_vec();
        let mut h = DefaultHasher::new();
        nodes.hash(&mut h);
        tape.outputs.hash(&mut h);
        Key {
            hash: h.finish(),
            nodes,
            outputs: tape.outputs,
        }
    }

    fn is(&self, other: &Key) -> bool {
        self.hash == other.hash && self.outputs == other.outputs && self.nodes == other.nodes
    }
}

/// The kernels compiled, most recently asked last.
pub struct Compiled {
    kept: Mutex<Vec<(Key, Shared)>>,
    capacity: usize,
}

/// The process's kernels (`crate::evaluate::evaluator` asks it).
pub static COMPILED: Compiled = Compiled::new(CAPACITY);

impl Compiled {
    pub const fn new(capacity: usize) -> Compiled {
        Compiled {
            kept: Mutex::new(Vec::new()),
            capacity,
        }
    }

    /// The kernel of `tape`: one compiled before for an equal tape, or
    /// compiled now (outside the lock: builds on other threads do not
    /// wait for it) and kept.
    pub fn kernel(&self, tape: &SurfaceTape) -> Result<Shared, JitError> {
        let key = Key::of(tape);
        if let Some(k) = self.find(&key) {
            return Ok(k);
        }
        let fresh = Shared(Arc::new(JitSurface::compile(tape)?));
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        // Another thread may have compiled it meanwhile: keep one.
        if let Some(i) = kept.iter().position(|(k, _)| k.is(&key)) {
            return Ok(kept[i].1.clone());
        }
        kept.push((key, fresh.clone()));
        if kept.len() > self.capacity {
            kept.remove(0);
        }
        Ok(fresh)
    }

    /// Drops every kept kernel (a bench that times a build as a fresh
    /// process makes it, compilations included).
    pub fn clear(&self) {
        self.kept.lock().unwrap_or_else(|e| e.into_inner()).clear();
    }

    /// A kept kernel for `key`, made the most recent.
    fn find(&self, key: &Key) -> Option<Shared> {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let i = kept.iter().position(|(k, _)| k.is(key))?;
        let entry = kept.remove(i);
        let shared = entry.1.clone();
        kept.push(entry);
        Some(shared)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::surface::ir::Graph;

    /// z = a·x² + y (a distinct tape for each `a`).
    fn tape(a: f64) -> SurfaceTape {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let x2 = g.mul(x, x);
        let c = g.constant_node(a);
        let ax2 = g.mul(c, x2);
        let z = g.add(ax2, y);
        SurfaceTape::new(g, z)
    }

    #[test]
    fn a_tape_asked_again_is_not_compiled_again_and_gives_the_same_bits() {
        let cache = Compiled::new(2);
        let first = cache.kernel(&tape(0.5)).unwrap();
        // An equal tape built anew (not a clone) is the same kernel.
        let again = cache.kernel(&tape(0.5)).unwrap();
        assert!(first.same(&again));
        let fresh = JitSurface::compile(&tape(0.5)).unwrap();
        for (x, y) in [(0.3, -1.25), (1e-3, 7.0), (-2.5, 0.0)] {
            let (a, b) = (again.eval(x, y), fresh.eval(x, y));
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        // Another tape is another kernel, with its own values.
        let other = cache.kernel(&tape(0.25)).unwrap();
        assert!(!first.same(&other));
        assert_eq!(other.eval(2.0, 0.0)[0], 1.0);
    }

    #[test]
    fn only_the_most_recently_asked_kernels_are_kept() {
        let cache = Compiled::new(2);
        let a = cache.kernel(&tape(1.0)).unwrap();
        let b = cache.kernel(&tape(2.0)).unwrap();
        // Asking a again makes b the oldest, dropped for c.
        assert!(a.same(&cache.kernel(&tape(1.0)).unwrap()));
        let _c = cache.kernel(&tape(3.0)).unwrap();
        assert!(a.same(&cache.kernel(&tape(1.0)).unwrap()));
        assert!(!b.same(&cache.kernel(&tape(2.0)).unwrap()));
        // The dropped kernel still evaluates for whoever holds it.
        assert_eq!(b.eval(1.0, 0.0)[0], 2.0);
    }
}
