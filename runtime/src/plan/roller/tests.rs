//! Tests of the roller helix planner.

use super::*;

/// Job 1 of seed 002 (eq 10): z = 0.02 (sin 5x + cos(10y/3)) − 0.04 mm,
/// with its exact derivatives.
struct Sinusoid;

impl SurfaceFn for Sinusoid {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            let (s5, c5) = (5.0 * x).sin_cos();
            let (sy, cy) = (10.0 * y / 3.0).sin_cos();
            out[6 * i..6 * i + 6].copy_from_slice(&[
                0.02 * (s5 + cy) - 0.04,
                0.1 * c5,
                -0.02 * 10.0 / 3.0 * sy,
                -0.5 * s5,
                0.0,
                -0.02 * 100.0 / 9.0 * cy,
            ]);
        }
    }
}

/// A level design z = h.
struct Level(f64);

impl SurfaceFn for Level {
    fn eval_batch(&self, xs: &[f64], _: &[f64], out: &mut [f64]) {
        for o in out.chunks_exact_mut(6).take(xs.len()) {
            o.copy_from_slice(&[self.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        }
    }
}

/// A convex cylinder across the roller: each axial section is the
/// circle of radius rc about (x0, −rc), z = sqrt(rc² − (x − x0)²) − rc.
struct Ridge {
    rc: f64,
    x0: f64,
}

impl SurfaceFn for Ridge {
    fn eval_batch(&self, xs: &[f64], _: &[f64], out: &mut [f64]) {
        for (i, &x) in xs.iter().enumerate() {
            let d = x - self.x0;
            let q = (self.rc * self.rc - d * d).sqrt();
            out[6 * i..6 * i + 6].copy_from_slice(&[
                q - self.rc,
                -d / q,
                0.0,
                -self.rc * self.rc / (q * q * q),
                0.0,
                0.0,
            ]);
        }
    }
}

/// A V-groove across the roller, z = k |x − x0|: a concave corner.
struct Groove {
    k: f64,
    x0: f64,
}

impl SurfaceFn for Groove {
    fn eval_batch(&self, xs: &[f64], _: &[f64], out: &mut [f64]) {
        for (i, &x) in xs.iter().enumerate() {
            let s = if x < self.x0 { -1.0 } else { 1.0 };
            out[6 * i..6 * i + 6].copy_from_slice(&[
                self.k * (x - self.x0).abs(),
                s * self.k,
                0.0,
                0.0,
                0.0,
                0.0,
            ]);
        }
    }
}

/// Seed 002, section 3.1 and table 1: roller radius 3 mm (6π / 2π),
/// blank 3.01 mm, cut from z = 0.5 to 6 mm, rough 1° / 0.1 mm, finish
/// 0.1° / 0.005 mm. The paper gives no depth of cut or allowance: none.
fn job1() -> RollerHelix {
    RollerHelix {
        roller_radius: 3.0,
        y_start: 0.0,
        passes: vec![
            HelixPass {
                c_step: 1f64.to_radians(),
                pitch: 0.1,
                finish_allowance: 0.0,
            },
            HelixPass {
                c_step: 0.1f64.to_radians(),
                pitch: 0.005,
                finish_allowance: 0.0,
            },
        ],
        z_start: 0.5,
        z_end: 6.0,
        blank_radius: 3.01,
        depth_of_cut: None,
        design_length_around: Some(6.0 * std::f64::consts::PI),
        spindle_speed: None,
        chords: crate::plan::chords::ChordPlacement::OnPath,
    }
}

/// Table 1: tool radius 1.417567 mm.
const RHO1: f64 = 1.417567;

fn rough_only(mut h: RollerHelix) -> RollerHelix {
    h.passes.truncate(1);
    h
}

#[test]
fn job1_tool_checks_reproduce_section_4() {
    // Seed 002 section 4: minimum radius of curvature 2 mm, slopes
    // 3.81° (cutting) and 5.71° (axial); tool 1.417567 mm, clearance
    // 12.5°, opening 100° (table 1): all three constraints met.
    let region = DesignRegion {
        x: (0.0, TAU),
        y: (0.0, 3.0 * TAU),
        samples: (1257, 1885),
    };
    let tool = RollerTool {
        nose_radius: RHO1,
        clearance_angle: 12.5f64.to_radians(),
        opening_angle: 100f64.to_radians(),
    };
    let c = check_roller_tool(&Sinusoid, &region, 3.0, &tool).expect("checks");
    assert_eq!(format!("{:.2}", c.min_radius_axial), "2.00", "{c:?}");
    assert_eq!(format!("{:.2}", c.min_radius_overall), "2.00", "{c:?}");
    assert_eq!(format!("{:.2}", c.max_slope_cutting.to_degrees()), "3.81");
    assert_eq!(format!("{:.2}", c.max_slope_axial.to_degrees()), "5.71");
    // On the roller the cutting slope is 3 · 0.0667 / 2.94 (deepest
    // where the slope peaks: z = −0.06): 3.89°, still well inside 12.5°.
    assert_eq!(
        format!("{:.2}", c.max_slope_cutting_on_roller.to_degrees()),
        "3.89"
    );
    assert_eq!(c.concave_corners, 0);
    assert!(c.radius_ok && c.clearance_ok && c.opening_ok && c.passes());
    // A 2.5 mm nose does not fit the 2 mm bowls; a 5° clearance is
    // below the slope; a 10° opening is below twice the axial slope.
    let bad = RollerTool {
        nose_radius: 2.5,
        clearance_angle: 3f64.to_radians(),
        opening_angle: 10f64.to_radians(),
    };
    let c = check_roller_tool(&Sinusoid, &region, 3.0, &bad).expect("checks");
    assert!(!c.radius_ok && !c.clearance_ok && !c.opening_ok);
}

#[test]
fn roller_radius_and_wrap() {
    // Eq 1 and section 3.1: R = 6π / 2π = 3 mm.
    assert!((roller_radius_for(6.0 * std::f64::consts::PI) - 3.0).abs() < 1e-15);
    let fit = check_wrap(3.0, 6.0 * std::f64::consts::PI).expect("fits");
    assert_eq!(fit.gap, 0.0);
    // The paper's rounded 18.84 mm on a 3 mm roller: a 4.96 µm gap.
    let fit = check_wrap(3.0, 18.84).expect("fits");
    assert!((fit.gap - (6.0 * std::f64::consts::PI - 18.84)).abs() < 1e-12);
    let e = check_wrap(2.99, 6.0 * std::f64::consts::PI).expect_err("overlap");
    assert!(matches!(e, RollerError::Overlap { .. }), "{e:?}");
    // Job 1 closes smoothly: 10 periods around (section 3.1).
    let (dz, ds) = seam_step(&Sinusoid, 3.0, 0.0, (0.0, TAU), 100);
    assert!(dz < 1e-14 && ds < 1e-13, "{dz} {ds}");
}

#[test]
fn on_a_level_design_the_centre_is_a_nose_radius_above() {
    let h = RollerHelix {
        design_length_around: None,
        ..rough_only(job1())
    };
    let z = -0.0125;
    let path = plan_roller_helix(&h, RHO1, &Level(z)).expect("plans");
    assert!(
        path.points[0].iter().all(|p| p.x == 3.0 + (z + RHO1)),
        "{:?}",
        path.points[0][0]
    );
}

#[test]
fn over_a_circular_section_the_centre_is_on_the_concentric_circle() {
    let d = Ridge { rc: 5.0, x0: 3.2 };
    for y in [0.0, 1.3] {
        let section = AxialSection { design: &d, y };
        for x in [1.3, 2.0, 3.2, 3.9, 5.0] {
            let h = centre_height(&section, RHO1, x);
            let want = ((5.0 + RHO1).powi(2) - (x - 3.2f64).powi(2)).sqrt() - 5.0;
            assert!((h - want).abs() < 1e-12, "x {x}: {h} vs {want}");
            let s = centre_height_scanned(&section, RHO1, x);
            assert!((s - want).abs() < 1e-12, "scanned x {x}: {s} vs {want}");
        }
    }
}

/// A row of concave circular dimples of radius r, `pitch` apart along
/// the axis, the deepest winning (ridges between them), counting the
/// calls made of it.
struct Dimples {
    r: f64,
    pitch: f64,
    calls: std::cell::Cell<usize>,
}

impl Profile for Dimples {
    fn point(&self, u: f64) -> ProfilePoint {
        self.calls.set(self.calls.get() + 1);
        let d = u - self.pitch * (u / self.pitch).round();
        let q = (self.r * self.r - d * d).sqrt();
        ProfilePoint {
            z: self.r - q,
            dz: d / q,
            d2z: self.r * self.r / (q * q * q),
        }
    }
}

#[test]
fn along_a_row_of_dimples_each_centre_takes_a_few_calls_and_is_exact() {
    // Seed 002's microlenses in section: 0.1 mm pitch, 0.2525 mm radius at
    // the bottom (a² / c), the 0.074239 mm nose; one centre every 0.1 µm
    // along a whole pitch, each search started at the last contact.
    let s = Dimples {
        r: 0.2525,
        pitch: 0.1,
        calls: std::cell::Cell::new(0),
    };
    let rho = 0.074239;
    let (mut offset, mut on_ridge) = (0.0, 0);
    let n = 1000;
    for i in 0..n {
        let x = 0.01 + 0.1 * f64::from(i) / f64::from(n);
        let (h, u) = centre_height_from(&s, rho, x, x + offset);
        offset = u - x;
        let calls = s.calls.take();
        // The reference: bracketed Newton and bisection over the window,
        // to 1e-9 mm in u (below the corner by up to that times the slope).
        let (exact, _) = envelope::piece_max(&s, rho, x, x - rho, x + rho);
        s.calls.take();
        assert!(
            h >= exact - 1e-13 && h <= exact + 1e-9,
            "x {x}: {h} vs {exact}"
        );
        let ridge = (u / 0.1 - 0.5).fract().abs() < 1e-9;
        if ridge {
            on_ridge += 1;
        }
        // piece_max alone takes about thirty on a ridge.
        assert!(calls <= if ridge { 16 } else { 6 }, "x {x}: {calls} calls");
    }
    // The nose rests on the ridge at 0.05 mm while |x − 0.05| is under
    // ρ (p/2) / r = 14.7 µm: 294 of the 1000 centres.
    assert!((290..=298).contains(&on_ridge), "{on_ridge} on the ridge");
}

#[test]
fn in_a_groove_the_nose_rests_on_both_flanks() {
    // z = k |x − x0|: contact on each flank at ρ sin θ from the centre,
    // height k |d| + ρ sqrt(1 + k²) for |d| below ρ sin θ.
    let g = Groove { k: 0.2, x0: 2.0 };
    let h = RollerHelix {
        z_start: 1.0,
        z_end: 3.0,
        blank_radius: 4.0,
        design_length_around: None,
        ..rough_only(job1())
    };
    let rho = 0.5;
    let path = plan_roller_helix(&h, rho, &g).expect("plans");
    assert!(path.concave_corners > 0);
    let reach = rho * 0.2 / 1.04f64.sqrt();
    let mut seen = 0;
    for p in &path.points[0] {
        let d = p.z - 2.0;
        if d.abs() < reach {
            let want = 3.0 + 0.2 * d.abs() + rho * 1.04f64.sqrt();
            assert!((p.x - want).abs() < 1e-12, "at {}: {} vs {want}", p.z, p.x);
            seen += 1;
        }
    }
    assert!(seen > 100, "{seen}");
}

#[test]
fn job1_is_gouge_free_and_the_helix_advances_a_pitch_per_revolution() {
    let h = rough_only(job1());
    let path = plan_roller_helix(&h, RHO1, &Sinusoid).expect("plans");
    let pts = &path.points[0];
    // Rough pass: 5.5 mm / 0.1 mm = 55 revolutions of 360 steps, plus
    // the end point (table 1).
    assert_eq!(pts.len(), 55 * 360 + 1);
    assert_eq!(path.passes[0].points, pts.len());
    assert_eq!(path.passes[0].revolutions, 55.0);
    assert_eq!(pts[0].z, 0.5);
    assert_eq!(pts.last().expect("end").z, 6.0);
    assert!((pts.last().expect("end").c - 55.0 * TAU).abs() < 1e-9);
    for w in pts.windows(361).step_by(97) {
        assert!((w[360].z - w[0].z - 0.1).abs() < 1e-12);
        assert!((w[360].c - w[0].c - TAU).abs() < 1e-12);
    }
    assert!(pts.windows(2).all(|w| w[1].c > w[0].c && w[1].z > w[0].z));
    // X stays between R + z_min + ρ and R + z_max + ρ.
    let s = &path.passes[0];
    assert!(
        s.x_min >= 3.0 - 0.08 + RHO1 && s.x_max <= 3.0 + RHO1,
        "{s:?}"
    );
    // No design point of the cutting-plane section inside the nose.
    for p in pts.iter().step_by(37) {
        let y = 3.0 * p.c.rem_euclid(TAU);
        let hc = p.x - 3.0;
        for j in 0..=400 {
            let u = p.z - RHO1 + 2.0 * RHO1 * j as f64 / 400.0;
            let z = Sinusoid.eval(u, y)[0];
            let dist = (u - p.z).hypot(z - hc);
            assert!(dist >= RHO1 - 1e-12, "gouge at c {} u {u}: {dist}", p.c);
        }
    }
}

#[test]
fn the_paper_offset_method_agrees_with_the_exact_centre() {
    // Eqs 6–9 on the job-1 section sampled every h, against the exact
    // envelope: the difference shrinks as h² (measured: 10.6 nm at
    // 10 µm, 0.106 nm at 1 µm; the paper does not give its sampling).
    let mut worst = Vec::new();
    for h in [0.01, 0.001] {
        let (mut below, mut above) = (0.0f64, 0.0f64);
        for c in [0.0, 0.4, 1.7, 3.0, 5.5] {
            let y = 3.0 * c;
            let n = (4.0 / h) as usize;
            let section: Vec<(f64, f64)> = (0..=n)
                .map(|i| {
                    let u = 1.0 + 4.0 * i as f64 / n as f64;
                    (u, 3.0 + Sinusoid.eval(u, y)[0])
                })
                .collect();
            let offset = liu_offset(&section, RHO1);
            let exact_section = AxialSection {
                design: &Sinusoid,
                y,
            };
            for j in 0..=200 {
                let x = 2.5 + j as f64 / 200.0;
                let liu = liu_centre(&offset, x).expect("inside");
                let exact = 3.0 + centre_height(&exact_section, RHO1, x);
                below = below.max(exact - liu);
                above = above.max(liu - exact);
            }
        }
        eprintln!(
            "eqs 6–9 at h = {h} mm: X up to {below:.3e} mm below the exact centre \
             (a gouge), up to {above:.3e} mm above"
        );
        worst.push(below.max(above));
    }
    assert!(worst[0] < 2e-5, "{worst:?}");
    assert!(worst[1] < worst[0] / 50.0, "{worst:?}");
}

#[test]
fn the_plan_is_the_same_for_any_thread_count() {
    let h = rough_only(job1());
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| plan_roller_helix(&h, RHO1, &Sinusoid).expect("plans"))
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(one, three);
    assert_eq!(one.passes[0].fingerprint, three.passes[0].fingerprint);
}

#[test]
fn job1_finish_pass_streams_its_points() {
    // Table 1: 5.5 mm / 0.005 mm = 1100 revolutions of 3600 steps, plus
    // the end point; streamed, not stored.
    let mut h = job1();
    h.passes.remove(0);
    h.spindle_speed = Some(TAU * 60.0 / 60.0); // 60 rpm: not in the paper.
    let start = std::time::Instant::now();
    let (mut n, mut last_z, mut chunks) = (0usize, f64::NEG_INFINITY, 0usize);
    let path = plan_roller_helix_into(&h, RHO1, &Sinusoid, |pass, pts| {
        assert_eq!(pass, 0);
        assert!(pts[0].z > last_z);
        last_z = pts[pts.len() - 1].z;
        n += pts.len();
        chunks += 1;
    })
    .expect("plans");
    eprintln!(
        "job 1 finish pass: {n} points in {:.2?} ({} threads)",
        start.elapsed(),
        rayon::current_num_threads()
    );
    assert_eq!(n, 1100 * 3600 + 1);
    assert_eq!(chunks, 1101);
    let s = &path.passes[0];
    assert_eq!(s.points, n);
    assert!((s.revolutions - 1100.0).abs() < 1e-9);
    assert!((s.time.expect("time") - 1100.0).abs() < 1e-9, "{s:?}");
    assert!(path.points.is_empty());
}

#[test]
fn depth_of_cut_splits_a_pass_into_cycles() {
    // Blank 3.01 mm (seed 002) over a design down to 2.92 mm: 0.09 mm of
    // stock. Rough allowance 5 µm and 20 µm per cycle are assumptions
    // (the paper gives neither): 0.085 mm in 5 cycles, the first 5 µm.
    let mut h = job1();
    h.passes[0].finish_allowance = 0.005;
    h.depth_of_cut = Some(0.02);
    let path = plan_roller_helix_into(&h, RHO1, &Sinusoid, |_, _| {}).expect("plans");
    let r = &path.passes[0];
    assert_eq!(r.cycle_offsets.len(), 5);
    for (o, want) in r.cycle_offsets.iter().zip([0.08, 0.06, 0.04, 0.02, 0.0]) {
        assert!((o - want).abs() < 1e-15, "{:?}", r.cycle_offsets);
    }
    assert!((path.design_z_min + 0.08).abs() < 1e-6);
    assert!(r.max_depth_of_cut <= 0.02);
    let f = &path.passes[1];
    assert_eq!(f.cycle_offsets, vec![0.0]);
    assert!((f.max_depth_of_cut - 0.005).abs() < 1e-15);
    // The rough X carries the allowance.
    assert!((r.x_min - f.x_min - 0.005).abs() < 1e-3, "{r:?} {f:?}");
}

#[test]
fn invalid_input_is_refused_with_its_figures() {
    let base = rough_only(job1());
    let plan = |h: &RollerHelix, rho: f64| plan_roller_helix_into(h, rho, &Sinusoid, |_, _| {});
    let mut h = base.clone();
    h.passes[0].pitch = 0.0;
    assert!(matches!(
        plan(&h, RHO1),
        Err(RollerError::Invalid { what: "pitch", .. })
    ));
    let mut h = base.clone();
    h.passes[0].c_step = f64::NAN;
    assert!(matches!(plan(&h, RHO1), Err(RollerError::Invalid { .. })));
    let mut h = base.clone();
    h.z_end = 0.2;
    assert!(matches!(plan(&h, RHO1), Err(RollerError::Invalid { .. })));
    assert!(matches!(
        plan(&base, -1.0),
        Err(RollerError::Invalid { .. })
    ));
    let mut h = base.clone();
    h.passes[0].c_step = 1e-12;
    assert!(matches!(plan(&h, RHO1), Err(RollerError::Invalid { .. })));
    // A 2.5 mm nose against the 2 mm bowls (seed 002, section 4).
    let Err(RollerError::NoseTooLarge { min_radius, .. }) = plan(&base, 2.5) else {
        panic!("nose accepted")
    };
    assert!((min_radius - 2.0).abs() < 1e-3, "{min_radius}");
    let mut h = base.clone();
    h.blank_radius = 2.99;
    assert!(matches!(
        plan(&h, RHO1),
        Err(RollerError::BlankBelowDesign { .. })
    ));
    let mut h = job1();
    h.passes[1].finish_allowance = 0.01;
    assert!(matches!(
        plan(&h, RHO1),
        Err(RollerError::AllowanceRises { pass: 1, .. })
    ));
    let mut h = base.clone();
    h.roller_radius = 2.9;
    h.blank_radius = 3.0;
    assert!(matches!(plan(&h, RHO1), Err(RollerError::Overlap { .. })));
    // The design undefined where the nose goes (a ridge 1 mm wide).
    let mut h = base;
    h.design_length_around = None;
    let e = plan_roller_helix_into(&h, 0.1, &Ridge { rc: 0.5, x0: 1.0 }, |_, _| {})
        .expect_err("undefined");
    assert!(matches!(e, RollerError::Undefined { .. }), "{e:?}");
    let region = DesignRegion {
        x: (1.0, 0.0),
        y: (0.0, 1.0),
        samples: (10, 10),
    };
    let tool = RollerTool {
        nose_radius: 1.0,
        clearance_angle: 0.1,
        opening_angle: 1.0,
    };
    assert!(matches!(
        check_roller_tool(&Sinusoid, &region, 3.0, &tool),
        Err(RollerError::Invalid { .. })
    ));
}

/// A 50 nm sinusoid of 4 periods over ±45°, sampled every 0.5°.
fn wavy_edge() -> crate::machine::edge::EdgeProfile {
    use crate::machine::edge::{EdgeProfile, Sample};
    let samples: Vec<Sample> = (0..=180)
        .map(|i| {
            let a = -45.0 + 0.5 * i as f64;
            Sample {
                angle_deg: a,
                deviation_um: 0.05 * (4.0 * std::f64::consts::PI * a / 45.0).sin(),
                line: i + 1,
                at: 0,
            }
        })
        .collect();
    EdgeProfile::from_samples(&samples).unwrap()
}

#[test]
fn with_a_measured_edge_each_centre_is_the_brute_force_envelope() {
    // Job 1's pattern (axial slopes to ±5.7°) over half a millimetre,
    // rough pass only: every point's X is the lowest that clears the
    // axial section with the wavy edge, found by brute force.
    let h = RollerHelix {
        z_end: 1.0,
        ..rough_only(job1())
    };
    let edge = wavy_edge();
    let nose = Nose {
        radius: RHO1,
        edge: Some(&edge),
    };
    let mut points = Vec::new();
    plan_roller_helix_edged(&h, &nose, &Sinusoid, &Sinusoid, |_, pts| {
        points.extend_from_slice(pts)
    })
    .expect("plans");
    let circle = plan_roller_helix(&h, RHO1, &Sinusoid).expect("plans");
    assert_eq!(points.len(), circle.points[0].len());
    let (mut worst, mut moved): (f64, f64) = (0.0, 0.0);
    for (p, q) in points.iter().zip(&circle.points[0]).step_by(37) {
        let section = AxialSection {
            design: &Sinusoid,
            y: h.design_y(p.c),
        };
        // max over u of z(u) + L(u − z), sampled every 10 nm and refined
        // by golden section about the best sample.
        let f = |u: f64| {
            nose.lift(u - p.z)
                .map_or(f64::NEG_INFINITY, |(l, _)| section.point(u).z + l)
        };
        let n = 60_000;
        let (a, b) = (p.z - 0.3, p.z + 0.3);
        let best = (0..=n)
            .map(|i| a + (b - a) * i as f64 / n as f64)
            .max_by(|u, v| f(*u).total_cmp(&f(*v)))
            .unwrap();
        let (mut lo, mut hi) = (best - 1e-5, best + 1e-5);
        for _ in 0..100 {
            let (m1, m2) = (lo + 0.382 * (hi - lo), hi - 0.382 * (hi - lo));
            if f(m1) < f(m2) {
                lo = m1;
            } else {
                hi = m2;
            }
        }
        let brute = h.roller_radius + f(lo).max(f(best));
        worst = worst.max((p.x - brute).abs());
        moved = moved.max((p.x - q.x).abs());
    }
    // Within a picometre of the envelope; tens of nanometres from the
    // circle's.
    assert!(worst < 1e-9, "off the envelope by {} nm", worst * 1e6);
    assert!(moved > 20e-6, "the edge moved X {} nm", moved * 1e6);
}

#[test]
fn a_measured_edge_over_concave_corners_is_refused() {
    // The V-groove's corner makes the planner scan each window: that
    // search places a circle only, so an edge is refused, not ignored.
    let h = RollerHelix {
        z_end: 1.0,
        design_length_around: None,
        blank_radius: 4.0,
        ..rough_only(job1())
    };
    let edge = wavy_edge();
    let nose = Nose {
        radius: 0.5,
        edge: Some(&edge),
    };
    let groove = Groove { k: 0.05, x0: 0.75 };
    let e = plan_roller_helix_edged(&h, &nose, &groove, &groove, |_, _| {}).expect_err("refused");
    assert!(matches!(e, RollerError::EdgeAtCorners { .. }), "{e:?}");
    // The circle is planned.
    plan_roller_helix(&h, 0.5, &groove).expect("plans");
}
