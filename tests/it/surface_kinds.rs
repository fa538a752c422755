//! Every surface of every example, through both backends: the JIT agrees
//! with the interpreter by the runtime's conformance check
//! (`surface::conformance::against_reference`), and the interpreter's exact
//! derivatives agree with central differences of its own heights.

use crate::common;

use lensc_build::driver;
use lensc_lang::loader::RealFs;
use lensc_runtime::surface::conformance::against_reference;
use lensc_runtime::surface::ir::{Interpreter, SurfaceFn};
use lensc_runtime::surface::jit::JitSurface;

/// (file, surface name, lowered surface) for every example surface.
fn example_surfaces() -> Vec<(String, String, lensc_lang::lower::surface::LoweredSurface)> {
    let mut all = Vec::new();
    for ex in common::examples() {
        let c = driver::check_path(&RealFs, &ex).expect("read");
        assert!(!c.has_errors(), "{}", ex.display());
        for name in common::surface_names(&ex) {
            let l = driver::declared_surface(&c, &name)
                .unwrap_or_else(|e| panic!("{}: {e}", ex.display()));
            all.push((ex.display().to_string(), name, l));
        }
    }
    assert!(all.len() >= 15, "only {} example surfaces", all.len());
    all
}

/// An n × n grid over the domain's bounding box, inside the domain.
fn grid(l: &lensc_lang::lower::surface::LoweredSurface, n: usize) -> (Vec<f64>, Vec<f64>) {
    let ((x0, x1), (y0, y1)) = l.domain.bounds();
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for j in 0..n {
        for i in 0..n {
            // Off the exact grid lines, so cell boundaries are not hit exactly.
            let x = x0 + (x1 - x0) * (i as f64 + 0.37) / n as f64;
            let y = y0 + (y1 - y0) * (j as f64 + 0.61) / n as f64;
            if l.domain.contains(x, y) {
                xs.push(x);
                ys.push(y);
            }
        }
    }
    (xs, ys)
}

#[test]
fn jit_matches_interpreter_on_every_example_surface() {
    for (file, name, l) in example_surfaces() {
        let (xs, ys) = grid(&l, 61);
        let jit = JitSurface::compile(&l.tape).unwrap_or_else(|e| panic!("{file} {name}: {e}"));
        let want = against_reference(&Interpreter::new(&l.tape), &jit, &xs, &ys)
            .unwrap_or_else(|e| panic!("{file} {name}: {e}"));
        let finite = want.iter().filter(|v| v.is_finite()).count();
        assert!(
            finite == want.len(),
            "{file} {name}: {} of {} outputs are not finite",
            want.len() - finite,
            want.len()
        );
    }
}

#[test]
fn derivatives_agree_with_central_differences() {
    for (file, name, l) in example_surfaces() {
        let f = Interpreter::new(&l.tape);
        let (xs, ys) = grid(&l, 9);
        let ((x0, x1), _) = l.domain.bounds();
        let h = 1e-6 * (x1 - x0).max(1e-3);
        let mut checked = 0;
        for (&x, &y) in xs.iter().zip(&ys) {
            let o = f.eval(x, y);
            let (px, mx, py, my) = (
                f.eval(x + h, y),
                f.eval(x - h, y),
                f.eval(x, y + h),
                f.eval(x, y - h),
            );
            // Skip stencils that straddle a lenslet's rim or a cell boundary:
            // there the height has a kink and differences mean nothing.
            let smooth = [px, mx, py, my].iter().all(|p| {
                (p[3] - o[3]).abs() <= 1e-3 * (1.0 + o[3].abs())
                    && (p[5] - o[5]).abs() <= 1e-3 * (1.0 + o[5].abs())
            });
            if !smooth {
                continue;
            }
            checked += 1;
            let fd = |a: f64, b: f64| (a - b) / (2.0 * h);
            let tol = |v: f64| 1e-6 * (1.0 + v.abs());
            assert!(
                (o[1] - fd(px[0], mx[0])).abs() <= tol(o[1]),
                "{file} {name} dz/dx at ({x}, {y}): {} vs {}",
                o[1],
                fd(px[0], mx[0])
            );
            assert!(
                (o[2] - fd(py[0], my[0])).abs() <= tol(o[2]),
                "{file} {name} dz/dy at ({x}, {y})"
            );
            assert!(
                (o[3] - fd(px[1], mx[1])).abs() <= 1e-5 * (1.0 + o[3].abs()),
                "{file} {name} d2z/dx2 at ({x}, {y})"
            );
            assert!(
                (o[4] - fd(py[1], my[1])).abs() <= 1e-5 * (1.0 + o[4].abs()),
                "{file} {name} d2z/dxdy at ({x}, {y})"
            );
            assert!(
                (o[5] - fd(py[2], my[2])).abs() <= 1e-5 * (1.0 + o[5].abs()),
                "{file} {name} d2z/dy2 at ({x}, {y})"
            );
        }
        assert!(checked > 0, "{file} {name}: no smooth point to check");
    }
}
