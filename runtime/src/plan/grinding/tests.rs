//! Tests of profile grinding with a wheel.

use super::*;
use crate::surface::{RotationalSurface, Sense};

/// Paper Table 2, convex column: R = 22.405, κ = 43.098, lens radius
/// 1.6 mm. The paper's A_j are not published, so the lens is the conic
/// alone (its sag at the edge is 60.8 µm, not the table's 279.19 µm: the
/// unknown A_j carry the difference).
fn table2_convex() -> RotationalSurface {
    RotationalSurface {
        radius: 22.405,
        conic: 43.098,
        sense: Sense::Convex,
        terms: vec![],
        aperture_radius: 1.6,
    }
}

/// Paper Table 2, concave column: R = −4.254 (paper sign: concave; ours
/// is `Sense::Concave` with |R|), κ = −3.359, lens radius 1.5 mm. Conic
/// only, as above (sag 247.5 µm against the table's 84.05 µm).
fn table2_concave() -> RotationalSurface {
    RotationalSurface {
        radius: 4.254,
        conic: -3.359,
        sense: Sense::Concave,
        terms: vec![],
        aperture_radius: 1.5,
    }
}

/// Table 2: D_t = 4.0 mm, γ = 0.5; δ and v_f per lens; §4.2: from the
/// centre to the right edge.
fn table2_pass(interval: f64, feed: f64, edge: f64) -> ProfileGrinding {
    ProfileGrinding {
        wheel_diameter: 4.0,
        interval,
        feed,
        smoothness: 0.5,
        start: 0.0,
        end: edge,
    }
}

/// A straight section z = m·x + c: its wheel-centre path is the same
/// line moved along the normal.
struct Line {
    slope: f64,
    height: f64,
}

impl Profile for Line {
    fn point(&self, r: f64) -> ProfilePoint {
        ProfilePoint {
            z: self.slope * r + self.height,
            dz: self.slope,
            d2z: 0.0,
        }
    }
}

fn sphere(sense: Sense) -> RotationalSurface {
    // Fixture: any sphere; R = 10 mm, aperture 3 mm chosen here.
    RotationalSurface {
        radius: 10.0,
        conic: 0.0,
        sense,
        terms: vec![],
        aperture_radius: 3.0,
    }
}

#[test]
fn wheel_centre_on_a_sphere_lies_on_the_concentric_sphere() {
    // Geometry: the normal of a sphere passes through its centre, so the
    // wheel centre is at R + D_t/2 from it over a dome (centre (0, −R))
    // and R − D_t/2 in a bowl (centre (0, R)). D_t = 4 mm from Table 2.
    let p = ProfileGrinding {
        wheel_diameter: 4.0,
        interval: 0.01,
        feed: 0.02,
        smoothness: 0.5,
        start: -3.0,
        end: 3.0,
    };
    for (sense, centre, radius) in [
        (Sense::Convex, Vector2::new(0.0, -10.0), 12.0),
        (Sense::Concave, Vector2::new(0.0, 10.0), 8.0),
    ] {
        let path = plan_profile_grinding(&p, &sphere(sense)).unwrap();
        assert_eq!(path.segments, 600);
        for g in &path.points {
            let d = (Vector2::new(g.x, g.z) - centre).norm();
            assert!((d - radius).abs() < 1e-12, "{sense:?} x={}: {d}", g.x);
        }
    }
}

#[test]
fn wheel_centres_do_not_gouge_table2_lenses() {
    // Every wheel centre is at least D_t/2 from every surface point
    // sampled every 0.15 µm across the whole lens (−edge..edge), for the
    // two Table 2 lenses with the table's D_t, δ and v_f.
    for (surf, interval, feed) in [
        (table2_convex(), 0.001, 0.020),
        (table2_concave(), 0.002, 0.010),
    ] {
        let edge = surf.aperture_radius;
        let p = table2_pass(interval, feed, edge);
        let path = plan_profile_grinding(&p, &surf).unwrap();
        let samples = 20_000;
        let surface: Vec<Vector2<f64>> = (0..=samples)
            .map(|k| {
                let x = -edge + 2.0 * edge * k as f64 / samples as f64;
                Vector2::new(x, surf.eval(x).z)
            })
            .collect();
        for g in path.points.iter().step_by(10) {
            let c = Vector2::new(g.x, g.z);
            let nearest = surface
                .iter()
                .map(|s| (s - c).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest >= 2.0 - 1e-12, "x={}: {nearest}", g.contact_x);
            // ... and the sampling is dense enough to find the contact.
            assert!(nearest < 2.0 + 1e-6, "x={}: {nearest}", g.contact_x);
        }
    }
}

#[test]
fn a_plane_needs_no_z_motion() {
    // Fixture: the flat z = 0.1 with Table 2's convex δ, v_f, γ.
    let flat = Line {
        slope: 0.0,
        height: 0.1,
    };
    let path = plan_profile_grinding(&table2_pass(0.001, 0.02, 1.6), &flat).unwrap();
    assert_eq!(path.segments, 1600);
    assert!(path.points.iter().all(|g| g.velocity == 0.0));
    assert!(path.points.iter().all(|g| (g.z - 2.1).abs() < 1e-15));
    assert_eq!(path.max_acceleration, 0.0);
}

#[test]
fn eq18_settles_on_a_constant_slope_and_eq19_matches_its_steps() {
    // Fixture: the line z = −0.2·x (a 0.2 slope, like a dome's side)
    // with Table 2's convex δ = 1 µm, v_f = 20 µm/s, γ = 0.5.
    // The z axis has to move at m·v_f = −4 µm/s. Eq 18's fixed point is
    // v* = m v_f/(1 − γ) = −8 µm/s (eq 9 leaves out v_{i−1}·t_a), reached
    // geometrically with ratio γ/(2 − γ) = 1/3 from rest.
    let (m, feed, interval, gamma) = (-0.2, 0.02, 0.001, 0.5);
    let line = Line {
        slope: m,
        height: 0.0,
    };
    let p = table2_pass(interval, feed, 0.1);
    let path = plan_profile_grinding(&p, &line).unwrap();
    assert_eq!(path.segments, 100);
    let settled = m * feed / (1.0 - gamma);
    let last = path.points.last().unwrap();
    assert!((last.velocity - settled).abs() < 1e-15, "{}", last.velocity);
    assert!((last.velocity / (m * feed) - 2.0).abs() < 1e-12);
    // From rest: v_0 = 2 Δq/(t_s (2 − γ)) = (4/3) m v_f.
    let v0 = path.points[1].velocity;
    assert!((v0 - 4.0 / 3.0 * m * feed).abs() < 1e-15, "{v0}");

    // Eq 19 against the velocity steps, and eq 9 (the paper's interval
    // model) against the centre-height steps q(x_{i+1}) − q(x_i) (eq 10).
    let t_s = interval / feed;
    for w in path.points.windows(2) {
        let (prev, here) = (w[0], w[1]);
        let a = feed / (gamma * interval) * (here.velocity - prev.velocity);
        assert!((here.acceleration - a).abs() <= 1e-9 * a.abs().max(1e-9));
        let t_a = gamma * t_s;
        let d = 0.5 * here.acceleration * t_a * t_a + here.velocity * (t_s - t_a);
        assert!((d - (here.z - prev.z)).abs() < 1e-15);
    }
    // Open loop, the axis gains γ t_s v_{i−1} per interval: over 100
    // intervals close to 99 γ t_s v* = 99·0.025·(−8 µm/s) ≈ −19.8 µm.
    assert!(path.open_loop_drift > 0.0195 && path.open_loop_drift < 0.0199);
}

/// dq/dx: slope of the wheel-centre height over contact x, from the
/// exact derivatives: q = z + r/√(1+z'²), q' = z' − r z' z''/(1+z'²)^{3/2}.
fn centre_slope(surf: &RotationalSurface, wheel_radius: f64, x: f64) -> f64 {
    let p = surf.eval(x);
    p.dz - wheel_radius * p.dz * p.d2z / (1.0 + p.dz * p.dz).powf(1.5)
}

/// Largest |q''| over the pass, by second differences of the centre
/// heights on the uniform contact grid.
fn max_centre_curvature(path: &GrindingPath, interval: f64) -> f64 {
    path.points
        .windows(3)
        .map(|w| ((w[2].z - 2.0 * w[1].z + w[0].z) / (interval * interval)).abs())
        .fold(0.0, f64::max)
}

/// Figures both Table 2 lenses must show, derived from eqs 17–19:
/// - intervals = lens radius / δ, time = lens radius / v_f;
/// - v settles at q'·v_f/(1 − γ), so max |v| is that at the edge, where
///   the centre path is steepest (lag ≪ 1 %);
/// - a_i = Δv/(γ t_s) with Δv ≈ q'' δ v_f/(1 − γ), so
///   max |a| ≈ max |q''| · v_f²/(γ (1 − γ)).
fn check_table2(surf: &RotationalSurface, p: &ProfileGrinding, path: &GrindingPath) {
    let edge = surf.aperture_radius;
    let gamma = p.smoothness;
    assert_eq!(path.segments, (edge / p.interval).round() as usize);
    assert_eq!(path.points.len(), path.segments + 1);
    assert!((path.total_time - edge / p.feed).abs() < 1e-9);
    assert!((path.interval_time - p.interval / p.feed).abs() < 1e-15);
    let v_edge = centre_slope(surf, 0.5 * p.wheel_diameter, edge) * p.feed / (1.0 - gamma);
    assert!(
        (path.max_speed - v_edge.abs()).abs() < 0.01 * v_edge.abs(),
        "{} vs {v_edge}",
        path.max_speed
    );
    assert!((path.points.last().unwrap().velocity - v_edge).abs() < 0.01 * v_edge.abs());
    let a_bound =
        max_centre_curvature(path, p.interval) * p.feed * p.feed / (gamma * (1.0 - gamma));
    assert!(
        (path.max_acceleration - a_bound).abs() < 0.02 * a_bound,
        "{} vs {a_bound}",
        path.max_acceleration
    );
    // The centre starts D_t/2 above the vertex.
    assert!((path.points[0].z - 0.5 * p.wheel_diameter).abs() < 1e-15);
    assert_eq!(path.points[0].x, 0.0);
}

#[test]
fn table2_convex_lens() {
    // Table 2 convex: D_t 4 mm, δ 1 µm, v_f 20 µm/s, γ 0.5, lens radius
    // 1.6 mm, from the centre to the edge (§4.2). Conic only.
    let surf = table2_convex();
    let p = table2_pass(0.001, 0.02, 1.6);
    let path = plan_profile_grinding(&p, &surf).unwrap();
    print_figures("convex", &path);
    check_table2(&surf, &p, &path);
    assert_eq!(path.segments, 1600);
    assert!((path.total_time - 80.0).abs() < 1e-12);
    assert!(path.min_concave_radius.is_none());
    // Conic sag at the edge 60.76 µm, slope −0.0811 (computed from
    // R, κ). The dome falls away from the centre, so the wheel descends:
    // every v < 0 (in the paper's +z, into the material, they are > 0).
    let edge = surf.eval(1.6);
    assert!((edge.z + 0.060_763_66).abs() < 1e-8 && (edge.dz + 0.081_113_5).abs() < 1e-7);
    assert!(path.points[1..].iter().all(|g| g.velocity < 0.0));
    // The normal tilts outwards: the last centre is beyond the edge.
    assert!(path.points.last().unwrap().x > 1.6);
}

#[test]
fn table2_concave_lens() {
    // Table 2 concave: D_t 4 mm, δ 2 µm, v_f 10 µm/s, γ 0.5, lens radius
    // 1.5 mm, from the centre to the edge. Conic only.
    let surf = table2_concave();
    let p = table2_pass(0.002, 0.01, 1.5);
    let path = plan_profile_grinding(&p, &surf).unwrap();
    print_figures("concave", &path);
    check_table2(&surf, &p, &path);
    assert_eq!(path.segments, 750);
    assert!((path.total_time - 150.0).abs() < 1e-12);
    // Conic sag at the edge 247.48 µm, slope 0.3101. The bowl rises
    // from the centre: every v > 0.
    let edge = surf.eval(1.5);
    assert!((edge.z - 0.247_475_87).abs() < 1e-8 && (edge.dz - 0.310_058_6).abs() < 1e-7);
    assert!(path.points[1..].iter().all(|g| g.velocity > 0.0));
    // Its smallest radius of curvature is the vertex radius 4.254 mm (a
    // hyperboloid flattens outwards), larger than the 2 mm wheel radius.
    let (rho, at) = path.min_concave_radius.unwrap();
    assert!((rho - 4.254).abs() < 1e-12 && at == 0.0, "{rho} at {at}");
    // The normal tilts inwards: the last centre is inside the edge.
    let last = path.points.last().unwrap();
    assert!(last.x < 1.5 && last.contact_x == 1.5);
}

/// The pre-plan check scans the planner's own points: the same figures,
/// the same refusal.
#[test]
fn the_pre_plan_check_agrees_with_the_planner() {
    let surf = table2_concave();
    let p = table2_pass(0.002, 0.01, 1.5);
    let scan = check_profile_grinding(&p, &surf).unwrap();
    let path = plan_profile_grinding(&p, &surf).unwrap();
    assert_eq!(scan.segments, path.segments);
    assert_eq!(scan.min_concave, path.min_concave_radius);
    let mut p = p;
    p.wheel_diameter = 9.0;
    let refused = check_profile_grinding(&p, &surf);
    assert!(
        matches!(refused, Err(GrindingError::WheelTooLarge { .. })),
        "{refused:?}"
    );
    assert_eq!(refused.err(), plan_profile_grinding(&p, &surf).err());
}

fn print_figures(name: &str, path: &GrindingPath) {
    println!(
        "{name}: {} segments, {} s, max |v| {:.6e} mm/s, max |a| {:.6e} mm/s², \
         open-loop drift {:.6e} mm, last centre ({:.6}, {:.6})",
        path.segments,
        path.total_time,
        path.max_speed,
        path.max_acceleration,
        path.open_loop_drift,
        path.points.last().unwrap().x,
        path.points.last().unwrap().z,
    );
}

#[test]
fn too_large_wheel_in_a_bowl_is_refused_where_the_bowl_is_tightest() {
    // Table 2 concave lens ground edge to edge with a 9 mm wheel (radius
    // 4.5 > the vertex radius 4.254): the tightest point is the vertex,
    // in the middle of the range.
    let mut p = table2_pass(0.002, 0.01, 1.5);
    p.start = -1.5;
    p.wheel_diameter = 9.0;
    match plan_profile_grinding(&p, &table2_concave()) {
        Err(GrindingError::WheelTooLarge {
            x,
            wheel_radius,
            curvature_radius,
        }) => {
            assert!(x.abs() < 1e-12, "{x}");
            assert_eq!(wheel_radius, 4.5);
            assert!((curvature_radius - 4.254).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // A prolate ellipse (κ = 0.5) tightens outwards: the error is at the
    // end of the range. Fixture chosen here: R = 4 mm, radius of
    // curvature (R² − κ r²)^{3/2}/R² = 3.7071... at r = 1.5.
    let ellipse = RotationalSurface {
        radius: 4.0,
        conic: 0.5,
        sense: Sense::Concave,
        terms: vec![],
        aperture_radius: 1.5,
    };
    p.start = 0.0;
    p.wheel_diameter = 7.8;
    match plan_profile_grinding(&p, &ellipse) {
        Err(GrindingError::WheelTooLarge {
            x,
            curvature_radius,
            ..
        }) => {
            assert_eq!(x, 1.5);
            let want = (16.0f64 - 0.5 * 2.25).powf(1.5) / 16.0;
            assert!((curvature_radius - want).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_parameters_and_surfaces_are_errors() {
    let surf = table2_convex();
    let good = table2_pass(0.001, 0.02, 1.6);
    let cases = [
        (
            ProfileGrinding {
                interval: 0.0,
                ..good.clone()
            },
            "interval",
        ),
        (
            ProfileGrinding {
                feed: -1.0,
                ..good.clone()
            },
            "feed",
        ),
        (
            ProfileGrinding {
                smoothness: 1.0,
                ..good.clone()
            },
            "smoothness",
        ),
        (
            ProfileGrinding {
                smoothness: f64::NAN,
                ..good.clone()
            },
            "smoothness",
        ),
        (
            ProfileGrinding {
                wheel_diameter: f64::INFINITY,
                ..good.clone()
            },
            "wheel diameter",
        ),
    ];
    for (p, which) in cases {
        match plan_profile_grinding(&p, &surf) {
            Err(GrindingError::InvalidParameter { name, .. }) => assert_eq!(name, which),
            other => panic!("{which}: {other:?}"),
        }
    }
    let empty = ProfileGrinding {
        end: 0.0,
        ..good.clone()
    };
    assert!(matches!(
        plan_profile_grinding(&empty, &surf),
        Err(GrindingError::EmptyRange { .. })
    ));
    let tiny = ProfileGrinding {
        interval: 1e-12,
        ..good.clone()
    };
    assert!(matches!(
        plan_profile_grinding(&tiny, &surf),
        Err(GrindingError::TooManySegments { .. })
    ));
    // The Table 2 convex conic ends at R/√(1+κ) = 3.374 mm.
    let beyond = ProfileGrinding { end: 3.5, ..good };
    match plan_profile_grinding(&beyond, &surf) {
        Err(GrindingError::NonFiniteSurface { x }) => assert!(x > 3.37 && x <= 3.5),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_short_last_interval_lands_on_the_end() {
    // 0.0105 mm at δ = 2 µm: five full intervals and one of 0.5 µm,
    // which takes 0.5 µm / v_f; total time is still length / v_f.
    let mut p = table2_pass(0.002, 0.01, 0.0105);
    p.start = 0.0;
    let path = plan_profile_grinding(&p, &table2_concave()).unwrap();
    assert_eq!(path.segments, 6);
    assert_eq!(path.points.last().unwrap().contact_x, 0.0105);
    assert!((path.total_time - 1.05).abs() < 1e-12);
    // Reversed direction: edge to centre.
    p.start = 0.0105;
    p.end = 0.0;
    let back = plan_profile_grinding(&p, &table2_concave()).unwrap();
    assert_eq!(back.segments, 6);
    assert_eq!(back.points.last().unwrap().contact_x, 0.0);
    assert!(back.points[1..].iter().all(|g| g.velocity < 0.0));
}
