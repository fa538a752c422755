//! Registration recovers the placement a synthetic measurement was made
//! with, from the design surface itself: within 5 % or 1 nm (µrad for
//! tilts, over the aperture) of each parameter.

use super::*;
use lensc_runtime::surface::ir::{Graph, Interpreter, SurfaceTape};

/// A hyperbolic asphere (R 2 mm, k −3, A4 0.01 mm⁻³), convex, plus
/// `xy` · x·y (a non-rotational term when not zero).
pub(crate) fn asphere(xy: f64) -> Interpreter {
    Interpreter::new(&asphere_tape(xy))
}

/// `asphere`'s tape.
fn asphere_tape(xy: f64) -> SurfaceTape {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let r2 = {
        let xx = g.mul(x, x);
        let yy = g.mul(y, y);
        g.add(xx, yy)
    };
    let c = g.constant_node(-1.0 / 2.0);
    let kc2 = g.constant_node((1.0 - 3.0) * 0.25);
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
    let mut z = g.add(conic, poly);
    if xy != 0.0 {
        let k = g.constant_node(xy);
        let xyn = g.mul(x, y);
        let term = g.mul(k, xyn);
        z = g.add(z, term);
    }
    SurfaceTape::new(g, z)
}

/// A map of the design placed by `p`, over a disc of radius 0.8 mm.
pub(crate) fn synthetic_map(f: &dyn SurfaceFn, p: &[f64; 6], n: usize) -> Vec<[f64; 3]> {
    let mut pts = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let x = -0.8 + 1.6 * i as f64 / (n - 1) as f64;
            let y = -0.8 + 1.6 * j as f64 / (n - 1) as f64;
            if x * x + y * y <= 0.64 {
                pts.push([x, y, 0.0]);
            }
        }
    }
    let h = predict(f, &pts, p);
    pts.iter().zip(h).map(|(q, h)| [q[0], q[1], h[0]]).collect()
}

fn assert_recovers(found: &Registration, truth: &[f64; 6]) {
    for k in 0..6 {
        if !found.fitted[k] {
            continue;
        }
        let (f, t) = (found.values[k], truth[k]);
        // 1 nm for lengths, 1 nm over the 0.8 mm radius for angles.
        let abs: f64 = if matches!(k, 0 | 3 | 4) {
            1e-6
        } else {
            1e-6 / 0.8
        };
        assert!(
            (f - t).abs() <= abs.max(0.05 * t.abs()),
            "{}: found {f:e}, made with {t:e}",
            PARAMETERS[k]
        );
    }
}

#[test]
fn a_map_recovers_piston_tilt_and_decentre_of_a_rotational_asphere() {
    let f = asphere(0.0);
    let truth = [2e-4, 50e-6, -20e-6, 5e-3, -3e-3, 0.0];
    let pts = synthetic_map(&f, &truth, 81);
    let found = register_heights(&f, &pts, Options::default()).expect("converges");
    assert!(
        !found.fitted[5],
        "clocking of a surface of revolution is left out"
    );
    assert!(found.fitted[3] && found.fitted[4], "{:?}", found.left_out);
    assert_recovers(&found, &truth);
}

#[test]
fn a_map_recovers_clocking_of_a_freeform() {
    let f = asphere(0.05);
    let truth = [-1e-4, 30e-6, 10e-6, -2e-3, 4e-3, 0.01];
    let pts = synthetic_map(&f, &truth, 81);
    let found = register_heights(&f, &pts, Options::default()).expect("converges");
    assert!(found.fitted[5]);
    assert_recovers(&found, &truth);
}

#[test]
fn a_profile_fits_x_only() {
    let f = asphere(0.0);
    let truth = [1e-4, 40e-6, 0.0, 6e-3, 0.0, 0.0];
    let pts: Vec<[f64; 3]> = (0..401)
        .map(|i| [-0.8 + 1.6 * i as f64 / 400.0, 0.0, 0.0])
        .collect();
    let h = predict(&f, &pts, &truth);
    let pts: Vec<[f64; 3]> = pts.iter().zip(h).map(|(q, h)| [q[0], 0.0, h[0]]).collect();
    let found = register_heights(
        &f,
        &pts,
        Options {
            two_d: false,
            ..Options::default()
        },
    )
    .expect("converges");
    assert_eq!(found.fitted, [true, true, false, true, false, false]);
    assert_recovers(&found, &truth);
}

#[test]
fn icp_recovers_a_rigid_placement_of_a_cloud() {
    let f = asphere(0.05);
    // The part: rotated by small angles and moved.
    let (tx, ty, gz) = (40e-6, -25e-6, 0.008);
    let rot = nalgebra::Rotation3::from_euler_angles(ty, -tx, gz).into_inner();
    let t = nalgebra::Vector3::new(3e-3, -2e-3, 1e-4);
    let mut pts = Vec::new();
    for j in 0..41 {
        for i in 0..41 {
            let (x, y) = (-0.7 + 1.4 * i as f64 / 40.0, -0.7 + 1.4 * j as f64 / 40.0);
            if x * x + y * y <= 0.49 {
                let s = nalgebra::Vector3::new(x, y, f.eval(x, y)[0]);
                let q = rot * s + t;
                pts.push([q.x, q.y, q.z]);
            }
        }
    }
    let found = register_cloud(&f, &pts, Options::default()).expect("converges");
    let truth = [
        t.z,
        rot[(2, 0)] / rot[(2, 2)],
        rot[(2, 1)] / rot[(2, 2)],
        t.x,
        t.y,
        rot[(1, 0)].atan2(rot[(0, 0)]),
    ];
    assert!(found.fitted.iter().all(|b| *b), "{:?}", found.left_out);
    assert_recovers(&found, &truth);
}

#[test]
fn a_paraboloid_cannot_tell_decentre_from_tilt_and_says_so() {
    // z = −r²/(2R): a decentre d changes z by r·d/R, exactly a tilt.
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let xx = g.mul(x, x);
    let yy = g.mul(y, y);
    let r2 = g.add(xx, yy);
    let c = g.constant_node(-0.25);
    let z = g.mul(c, r2);
    let f = Interpreter::new(&SurfaceTape::new(g, z));
    let pts = synthetic_map(&f, &[1e-4, 20e-6, 0.0, 0.0, 0.0, 0.0], 41);
    let found = register_heights(&f, &pts, Options::default()).expect("converges");
    assert!(!found.fitted[3] && !found.fitted[4], "{found:?}");
    assert!(found.left_out.iter().any(|(p, _)| *p == "decentre_x"));
    assert_recovers(&found, &[1e-4, 20e-6, 0.0, 0.0, 0.0, 0.0]);
}

#[test]
fn too_few_iterations_is_not_converged_not_a_guess() {
    let f = asphere(0.0);
    let pts = synthetic_map(&f, &[2e-4, 50e-6, -20e-6, 5e-3, -3e-3, 0.0], 41);
    let e = register_heights(
        &f,
        &pts,
        Options {
            max_iterations: 1,
            ..Options::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(e, RegisterError::NotConverged { iterations: 1, .. }),
        "{e:?}"
    );
    let e = register_heights(&f, &pts[..4], Options::default()).unwrap_err();
    assert_eq!(e, RegisterError::TooFewPoints { points: 4 });
}

/// The registration with its surface evaluated in parallel is the serial
/// one, bit for bit, on one thread or three, through the interpreter and
/// the JIT: only evaluations run in parallel (each point's its own), the
/// sums run over the points in order.
#[test]
fn a_parallel_registration_is_the_serial_one_bit_for_bit() {
    let f = asphere(0.05);
    let truth = [-1e-4, 30e-6, 10e-6, -2e-3, 4e-3, 0.01];
    // Some 20,000 points, several chunks and a part of one; a little
    // noise, so the sums carry rounding that an order of summing shows.
    let mut pts = synthetic_map(&f, &truth, 161);
    assert!(pts.len() > 4 * CHUNK && !pts.len().is_multiple_of(CHUNK));
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    for q in &mut pts {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        q[2] += ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e-6;
    }
    let jit = lensc_runtime::surface::jit::JitSurface::compile(&asphere_tape(0.05))
        .expect("the kernel compiles");
    let kernels: [&(dyn SurfaceFn + Sync); 2] = [&f, &jit];
    for k in kernels {
        let serial = register_heights(k, &pts, Options::default()).expect("converges");
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let parallel = pool
                .install(|| register_heights_parallel(k, &pts, Options::default()))
                .expect("converges");
            assert_eq!(parallel.iterations, serial.iterations);
            for (a, b) in parallel.values.iter().zip(&serial.values) {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{threads} threads: {a:e} against {b:e}"
                );
            }
        }
    }
}
