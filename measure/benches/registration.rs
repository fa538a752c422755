//! Registration of a 1000 × 1000 map (the target: under a second
//! in release on the 2-core machine), against a baseline measured in the
//! same run: one pass of the surface's JIT kernel (value and derivatives)
//! over the same points. Prints both times and their ratio.
//!
//! cargo bench -p lensc-measure --bench registration

use std::time::Instant;

use lensc_measure::register::{self, Options};
use lensc_runtime::surface::ir::{Graph, SurfaceFn, SurfaceTape};
use lensc_runtime::surface::jit::JitSurface;

/// A conic (R 2 mm, k −3) with A4, convex: the shape of the tests.
fn tape() -> SurfaceTape {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let xx = g.mul(x, x);
    let yy = g.mul(y, y);
    let r2 = g.add(xx, yy);
    let c = g.constant_node(-0.5);
    let kc2 = g.constant_node(-0.5);
    let t = g.mul(kc2, r2);
    let one = g.constant_node(1.0);
    let u = g.sub(one, t);
    let root = g.sqrt(u);
    let den = g.add(one, root);
    let num = g.mul(c, r2);
    let conic = g.div(num, den);
    let a4 = g.constant_node(-0.01);
    let r4 = g.mul(r2, r2);
    let poly = g.mul(a4, r4);
    let z = g.add(conic, poly);
    SurfaceTape::new(g, z)
}

fn main() {
    let f = JitSurface::compile(&tape()).expect("the kernel compiles");
    let n = 1000;
    let truth = [2e-4, 50e-6, -20e-6, 5e-3, -3e-3, 0.0];
    let mut pts = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (
                -0.8 + 1.6 * i as f64 / (n - 1) as f64,
                -0.8 + 1.6 * j as f64 / (n - 1) as f64,
            );
            if x * x + y * y <= 0.64 {
                pts.push([x, y, 0.0]);
            }
        }
    }
    let h = register::predict(&f, &pts, &truth);
    for (p, h) in pts.iter_mut().zip(&h) {
        p[2] = h[0];
    }
    // Baseline: one evaluation pass of the kernel over the points.
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().map(|p| (p[0], p[1])).unzip();
    let mut out = vec![0.0; 6 * pts.len()];
    let mut base = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        f.eval_batch(&xs, &ys, &mut out);
        base = base.min(t.elapsed().as_secs_f64());
    }
    let mut reg = f64::INFINITY;
    let mut found = None;
    for _ in 0..3 {
        let t = Instant::now();
        found = Some(register::register_heights(&f, &pts, Options::default()).expect("converges"));
        reg = reg.min(t.elapsed().as_secs_f64());
    }
    let found = found.expect("ran");
    println!(
        "registration of a {n} × {n} map ({} points in the aperture): {:.3} s ({} iterations); one kernel pass {:.4} s; ratio {:.1}",
        pts.len(),
        reg,
        found.iterations,
        base,
        reg / base
    );
    for (got, want) in found.values.iter().zip(&truth).take(5) {
        assert!((got - want).abs() <= 1e-6f64.max(0.05 * want.abs()));
    }
}
