//! Tests of the raster (ball-end milling) planner.

use super::*;
use crate::surface::ir::{Graph, Interpreter, SurfaceTape};

/// Lin 2022 (seed 000) eq 8, a conic of revolution in closed form:
/// z = s c q² / (1 + √(1 − (1+k) c² q²)), c = 1/R, s = +1 concave,
/// −1 convex, with exact derivatives (g = ∂z/∂x / x, h as below):
/// z_x = g x, z_xx = g + h x², z_xy = h x y, z_yy = g + h y².
struct Conic {
    radius: f64,
    k: f64,
    s: f64,
}

impl SurfaceFn for Conic {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            let c = 1.0 / self.radius;
            let u = 1.0 - (1.0 + self.k) * c * c * (x * x + y * y);
            let root = u.sqrt();
            let z = self.s * c * (x * x + y * y) / (1.0 + root);
            let g = self.s * c / root;
            let h = self.s * (1.0 + self.k) * c * c * c / (u * root);
            out[6 * i..6 * i + 6].copy_from_slice(&[
                z,
                g * x,
                g * y,
                g + h * x * x,
                h * x * y,
                g + h * y * y,
            ]);
        }
    }
}

fn convex(radius: f64, k: f64) -> Conic {
    Conic { radius, k, s: -1.0 }
}

/// An inclined plane z = a x + b y: every section is straight.
struct Ramp {
    a: f64,
    b: f64,
}

impl SurfaceFn for Ramp {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            out[6 * i..6 * i + 6].copy_from_slice(&[
                self.a * x + self.b * y,
                self.a,
                self.b,
                0.0,
                0.0,
                0.0,
            ]);
        }
    }
}

/// A surface defined on the disc of `radius` about the axis only (NaN
/// beyond it), like a conic at its root.
struct Only<S> {
    surface: S,
    radius: f64,
}

impl<S: SurfaceFn> SurfaceFn for Only<S> {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        self.surface.eval_batch(xs, ys, out);
        for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
            if x.hypot(y) > self.radius {
                out[6 * i..6 * i + 6].fill(f64::NAN);
            }
        }
    }
}

/// Lin's microshaper: nose radius 85 µm (seed 000, Fig. 1).
const LIN_NOSE: f64 = 0.085;
const KNIFE: RasterTool = RasterTool::Knife {
    nose_radius: LIN_NOSE,
};

fn raster(along: Axis, stepover: f64, tol: f64) -> Raster {
    Raster {
        along,
        zigzag: false,
        stepover,
        chord_tolerance: tol,
        max_step: None,
        lin_angle: None,
        retract: 0.5,
        chords: crate::plan::chords::ChordPlacement::OnPath,
    }
}

fn plane_of(along: Axis, p: [f64; 3]) -> f64 {
    match along {
        Axis::X => p[1],
        Axis::Y => p[0],
    }
}

fn u_of(along: Axis, p: [f64; 3]) -> f64 {
    match along {
        Axis::X => p[0],
        Axis::Y => p[1],
    }
}

/// Knife centres over a sphere of radius R: at u along the cut the
/// edge sees the cross-section, a circle of radius √(R² − u²) about the
/// sphere's axis, offset by ρ (outward on the dome, inward in the bowl);
/// the centre lies on that offset circle and on its plane — a closed
/// form, so exact.
#[test]
fn knife_centres_on_a_sphere_lie_on_the_offset_cross_section() {
    for (s, along) in [(-1.0, Axis::X), (-1.0, Axis::Y), (1.0, Axis::X)] {
        let sphere = Conic {
            radius: 1.0,
            k: 0.0,
            s,
        };
        let r = raster(along, 0.05, 1e-5);
        let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
        let mut worst = 0.0f64;
        for pass in &path.passes {
            let v = plane_of(along, pass[0]);
            for &p in pass {
                assert_eq!(plane_of(along, p), v);
                let rs = (1.0 - u_of(along, p).powi(2)).sqrt();
                let d = v.hypot(p[2] - s);
                worst = worst.max((d - (rs - s * LIN_NOSE)).abs());
            }
        }
        assert!(worst < 1e-12, "s={s} {along:?}: {worst:e}");
    }
}

/// Ball centres over a sphere of radius R lie on the sphere of radius
/// R ± ρ about its centre, each on its path plane.
#[test]
fn ball_centres_on_a_sphere_lie_on_the_offset_sphere() {
    let ball = RasterTool::Ball { radius: 0.1 };
    for (s, along) in [(-1.0, Axis::X), (-1.0, Axis::Y), (1.0, Axis::Y)] {
        let sphere = Conic {
            radius: 1.0,
            k: 0.0,
            s,
        };
        let r = raster(along, 0.05, 1e-5);
        let path = plan_raster(&r, &ball, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
        let mut worst = 0.0f64;
        for pass in &path.passes {
            let v = plane_of(along, pass[0]);
            // Planes are v0 + k·stepover, k possibly negative for the ball.
            let k = (v + 0.8) / 0.05;
            assert!((k - k.round()).abs() < 1e-9, "plane {v}");
            for &p in pass {
                assert_eq!(plane_of(along, p), v);
                let d = (p[0] * p[0] + p[1] * p[1] + (p[2] - s).powi(2)).sqrt();
                worst = worst.max((d - (1.0 - s * 0.1)).abs());
            }
        }
        assert!(worst < 1e-12, "s={s} {along:?}: {worst:e}");
    }
}

/// Every chord's midpoint is within the tolerance of the exact centre
/// curve (on a sphere: a circle of known radius in each plane), and on
/// the inside of it.
#[test]
fn chords_stay_within_tolerance_on_a_sphere() {
    let sphere = convex(1.0, 0.0);
    let tol = 1e-5;
    for tool in [KNIFE, RasterTool::Ball { radius: 0.1 }] {
        let r = raster(Axis::X, 0.05, tol);
        let path = plan_raster(&r, &tool, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
        let mut worst = 0.0f64;
        for pass in &path.passes {
            let v = pass[0][1];
            // The exact centre height at u on this plane: on the offset
            // cross-section (knife) or the offset sphere (ball).
            let exact = |u: f64| {
                match tool {
                    RasterTool::Knife { nose_radius } => {
                        ((1.0 - u * u).sqrt() + nose_radius).powi(2) - v * v
                    }
                    RasterTool::Ball { radius } => (1.0 + radius).powi(2) - v * v - u * u,
                }
                .sqrt()
                    - 1.0
            };
            for w in pass.windows(2) {
                let (du, dz) = (w[1][0] - w[0][0], w[1][2] - w[0][2]);
                let m = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][2] + w[1][2])];
                // Vertical gap times the cosine of the chord's slope:
                // the distance to the (locally straight) curve.
                let dev = (exact(m[0]) - m[1]) * du.abs() / du.hypot(dz);
                assert!(dev > -1e-12, "chord outside the curve by {dev:e}");
                worst = worst.max(dev);
            }
        }
        // The chords' share of the path's tolerance, and tight: the
        // sampling uses most of it.
        let share = tol * crate::plan::optimise::CHORD_SHARE;
        assert!(worst <= share * (1.0 + 1e-9), "{tool:?}: {worst:e}");
        assert!(worst > 0.5 * share, "{tool:?}: {worst:e}");
    }
}

/// Lin's model of the knife (his Fig. 5): the nose circle in the plane
/// of the path (y = `v`), touching the section at x = `t`; its centre is
/// the contact moved by the nose radius along the section's normal.
/// Returns (contact, centre).
fn lin_plane_contact(surface: &dyn SurfaceFn, v: f64, t: f64) -> ([f64; 3], [f64; 3]) {
    let o = surface.eval(t, v);
    let w = (1.0 + o[1] * o[1]).sqrt();
    (
        [t, v, o[0]],
        [t - LIN_NOSE * o[1] / w, v, o[0] + LIN_NOSE / w],
    )
}

/// The exact centre curve of Lin's in-plane model on the plane at y =
/// `v` at centre position x = `xc`: the contact whose centre is at xc,
/// found by bisection (the centre's x rises with the contact's x where
/// the nose fits the section).
fn knife_centre_at(surface: &dyn SurfaceFn, v: f64, xc: f64) -> ([f64; 3], [f64; 3]) {
    let at = |t: f64| {
        let (contact, centre) = lin_plane_contact(surface, v, t);
        ToolContact { contact, centre }
    };
    let (mut lo, mut hi) = (xc - LIN_NOSE, xc + LIN_NOSE);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if at(mid).centre[0] < xc {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c = at(0.5 * (lo + hi));
    (c.contact, c.centre)
}

/// Lin's hyperboloid job (R = 1 mm, k = −20): chord midpoints against
/// the exact centre curve, and no surface point ever inside the knife's
/// edge (the nose arc across the cut) at a planned centre, and inside it
/// by at most the chord tolerance along a chord.
#[test]
fn hyperboloid_chords_and_gouge() {
    let surf = convex(1.0, -20.0);
    let tol = 1e-5;
    let r = raster(Axis::X, 0.05, tol);
    let path = plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.8 }).unwrap();
    let mut worst_chord = 0.0f64;
    let mut worst_gouge = f64::NEG_INFINITY;
    let mut worst_chord_gouge = f64::NEG_INFINITY;
    for pass in path.passes.iter().step_by(4) {
        let v = pass[0][1];
        let clearance = |c: [f64; 3]| {
            (0..=400)
                .map(|i| {
                    let y = c[1] - LIN_NOSE + 2.0 * LIN_NOSE * i as f64 / 400.0;
                    let z = surf.eval(c[0], y)[0];
                    LIN_NOSE - (y - c[1]).hypot(z - c[2])
                })
                .fold(f64::NEG_INFINITY, f64::max)
        };
        for w in pass.windows(2) {
            worst_gouge = worst_gouge.max(clearance(w[0]));
            let m = [0.5 * (w[0][0] + w[1][0]), v, 0.5 * (w[0][2] + w[1][2])];
            worst_chord_gouge = worst_chord_gouge.max(clearance(m));
            let exact = tool_contact(&KNIFE, &surf, Axis::X, v, m[0])
                .unwrap()
                .centre;
            assert_eq!(exact[0], m[0]);
            let (du, dz) = (w[1][0] - w[0][0], w[1][2] - w[0][2]);
            // Vertical gap times cos of the chord's inclination: the
            // distance to the (locally straight) curve.
            worst_chord = worst_chord.max((exact[2] - m[2]).abs() * du.abs() / du.hypot(dz));
        }
    }
    assert!(worst_chord <= tol * (1.0 + 1e-6), "{worst_chord:e}");
    assert!(worst_gouge <= 1e-12, "gouge at a centre {worst_gouge:e}");
    assert!(
        worst_chord_gouge <= tol * (1.0 + 1e-6),
        "gouge along a chord {worst_chord_gouge:e}"
    );
}

#[test]
fn ball_is_gouge_free_at_its_centres() {
    let surf = convex(1.0, -20.0);
    let rho = 0.1;
    let r = raster(Axis::Y, 0.05, 1e-5);
    let path = plan_raster(
        &r,
        &RasterTool::Ball { radius: rho },
        &surf,
        &Domain::Circle { radius: 0.8 },
    )
    .unwrap();
    let mut worst = f64::NEG_INFINITY;
    for pass in path.passes.iter().step_by(5) {
        for c in pass.iter().step_by(7) {
            for i in 0..=40 {
                for j in 0..=40 {
                    let x = c[0] - rho + 2.0 * rho * i as f64 / 40.0;
                    let y = c[1] - rho + 2.0 * rho * j as f64 / 40.0;
                    let z = surf.eval(x, y)[0];
                    let d = ((x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2)).sqrt();
                    worst = worst.max(rho - d);
                }
            }
        }
    }
    assert!(worst <= 1e-12, "{worst:e}");
}

/// Lin's three convex jobs (seed 000, Figs 8 and 10) with the 85 µm
/// microshaper: oblate ellipsoid R = 3 mm k = 10, paraboloid R = 1 mm
/// k = −1, hyperboloid R = 1 mm k = −20; stepover 10 µm, chord
/// tolerance 10 nm, aperture radius 0.8 mm.
#[test]
fn lin_jobs_plan() {
    let r = raster(Axis::X, 0.01, 1e-5);
    let aperture = Domain::Circle { radius: 0.8 };
    for (radius, k, slope_deg) in [
        (1.0, -20.0, 12.436),
        (1.0, -1.0, 38.660),
        (3.0, 10.0, 29.745),
    ] {
        let path = plan_raster(&r, &KNIFE, &convex(radius, k), &aperture).unwrap();
        eprintln!(
            "R={radius} k={k}: {} passes, {} points, cut {:.3} mm, max slope along {:.3}°, across {:.3}°, safe z {:.4}",
            path.pass_count,
            path.point_count,
            path.cut_length,
            path.max_slope_along.value.to_degrees(),
            path.max_slope_across.value.to_degrees(),
            path.safe_z
        );
        // Planes at −0.8 + 0.01 k. Their contacts are taken a stepover
        // beyond the aperture, out to 0.81 mm (on a convex lens the
        // contacts of neighbouring planes lie closer than their planes).
        // The knife's contact on the plane at v lies ρ sin φ nearer the
        // axis, φ the slope across, so planes out to 0.81 mm +
        // ρ sin φ(0.81 mm) cut (φ at the reach's edge on the y axis,
        // where the contact is nearest the axis).
        let q = 0.81f64;
        let phi = (q / (radius * radius - (1.0 + k) * q * q).sqrt()).atan();
        let reach = q + LIN_NOSE * phi.sin();
        let planes = (-12..=172)
            .filter(|&j| (-0.8 + 0.01 * f64::from(j)).abs() < reach)
            .count();
        eprintln!("  {planes} planes reach {reach:.5} mm");
        assert_eq!(path.pass_count, planes);
        assert_eq!(path.passes.len(), planes);
        // A convex lens has no concave section.
        assert_eq!(path.min_concave_radius_along, None);
        // Steepest along the cut at the aperture edge on y ≈ 0:
        // atan(q/√(R² − (1+k) q²)) at q = 0.8.
        let want = (0.8 / (radius * radius - (1.0 + k) * 0.64f64).sqrt()).atan();
        assert!((want.to_degrees() - slope_deg).abs() < 1e-3);
        assert!(
            (path.max_slope_along.value - want).abs() < 1e-6,
            "{}",
            path.max_slope_along.value.to_degrees()
        );
        // The vertex centre is the highest: z = ρ above the vertex.
        assert!((path.safe_z - (LIN_NOSE + 0.5)).abs() < 1e-6);
    }
}

/// The conic root 1 − (1+k) c² r² vanishes at r = R/√(1+k) (0.9045 mm
/// for Lin's oblate ellipsoid R = 3 mm, k = 10): an aperture inside it
/// plans, one beyond it is undefined there.
#[test]
fn oblate_ellipsoid_aperture_is_limited_by_the_conic_root() {
    let surf = convex(3.0, 10.0);
    let limit = 3.0 / 11f64.sqrt();
    let r = raster(Axis::X, 0.01, 1e-5);
    let got = plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.9 });
    assert!(got.is_ok(), "{:?}", got.err());
    match plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.95 }) {
        Err(RasterError::Undefined { x, y }) => {
            let q = x.hypot(y);
            assert!(q >= limit && q <= 0.95 + 1e-12, "({x}, {y})");
        }
        other => panic!("{other:?}"),
    }
    // A path that runs from defined into undefined ground reports the
    // edge of definition itself.
    let strip = Domain::Rect {
        x: (-0.95, 0.95),
        y: (0.0, 0.005),
    };
    match plan_raster(&r, &KNIFE, &surf, &strip) {
        Err(RasterError::Undefined { x, y }) => {
            assert_eq!(y, 0.0);
            assert!((x.abs() - limit).abs() < 1e-9, "{x} vs {limit}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn zigzag_reverses_alternate_passes() {
    let surf = convex(1.0, -1.0);
    let aperture = Domain::Circle { radius: 0.5 };
    let mut r = raster(Axis::Y, 0.05, 1e-4);
    let one_way = plan_raster(&r, &KNIFE, &surf, &aperture).unwrap();
    r.zigzag = true;
    let zigzag = plan_raster(&r, &KNIFE, &surf, &aperture).unwrap();
    assert_eq!(one_way.pass_count, zigzag.pass_count);
    for (j, (a, b)) in one_way.passes.iter().zip(&zigzag.passes).enumerate() {
        assert!(a.windows(2).all(|w| w[1][1] > w[0][1]), "one-way runs +y");
        if j % 2 == 1 {
            let mut rev = a.clone();
            rev.reverse();
            assert_eq!(&rev, b);
        } else {
            assert_eq!(a, b);
        }
    }
    assert_eq!(one_way.cut_length, zigzag.cut_length);
}

#[test]
fn invalid_raster_parameters_give_errors() {
    let surf = convex(1.0, 0.0);
    let aperture = Domain::Circle { radius: 0.5 };
    let base = raster(Axis::X, 0.05, 1e-4);
    let bad = |r: Raster, name: &str| match plan_raster(&r, &KNIFE, &surf, &aperture) {
        Err(RasterError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
        other => panic!("{name}: {other:?}"),
    };
    for v in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        bad(
            Raster {
                stepover: v,
                ..base.clone()
            },
            "stepover",
        );
        bad(
            Raster {
                chord_tolerance: v,
                ..base.clone()
            },
            "chord tolerance",
        );
        bad(
            Raster {
                max_step: Some(v),
                ..base.clone()
            },
            "max step",
        );
    }
    bad(
        Raster {
            lin_angle: Some(4.0),
            ..base.clone()
        },
        "Lin step angle",
    );
    bad(
        Raster {
            retract: -1.0,
            ..base.clone()
        },
        "retract",
    );
}

#[test]
fn invalid_tools_and_apertures_give_errors() {
    let surf = convex(1.0, 0.0);
    let aperture = Domain::Circle { radius: 0.5 };
    let base = raster(Axis::X, 0.05, 1e-4);
    let err = |tool: RasterTool, ap: Domain| plan_raster(&base, &tool, &surf, &ap).unwrap_err();
    assert!(matches!(
        err(RasterTool::Knife { nose_radius: 0.0 }, aperture),
        RasterError::InvalidParameter {
            name: "nose radius",
            ..
        }
    ));
    assert!(matches!(
        err(RasterTool::Ball { radius: -1.0 }, aperture),
        RasterError::InvalidParameter {
            name: "ball radius",
            ..
        }
    ));
    assert!(matches!(
        err(KNIFE, Domain::Circle { radius: 0.0 }),
        RasterError::InvalidParameter { .. }
    ));
    assert!(matches!(
        err(
            KNIFE,
            Domain::Annulus {
                inner: 0.5,
                outer: 0.4
            }
        ),
        RasterError::InvalidParameter {
            name: "aperture inner radius",
            ..
        }
    ));
    assert!(matches!(
        err(
            KNIFE,
            Domain::Rect {
                x: (1.0, 0.0),
                y: (0.0, 1.0)
            }
        ),
        RasterError::InvalidParameter { .. }
    ));
}

#[test]
fn plans_beyond_reach_give_errors() {
    let surf = convex(1.0, 0.0);
    let aperture = Domain::Circle { radius: 0.5 };
    let base = raster(Axis::X, 0.05, 1e-4);
    assert!(matches!(
        plan_raster(
            &Raster {
                stepover: 1e-12,
                ..base.clone()
            },
            &KNIFE,
            &surf,
            &aperture
        ),
        Err(RasterError::TooManyPaths { .. })
    ));
    assert!(matches!(
        plan_raster(
            &Raster {
                chord_tolerance: 1e-30,
                ..base.clone()
            },
            &KNIFE,
            &surf,
            &aperture
        ),
        Err(RasterError::ToleranceUnreachable { .. })
    ));
    // The one plane of a tiny aperture only touches its edge (on a
    // surface level across the cut, the contact is on the plane), and
    // the surface has no continuation beyond the aperture to cut its rim
    // with (defined on the aperture only), so nothing is cut.
    assert_eq!(
        plan_raster(
            &base,
            &KNIFE,
            &Only {
                surface: Ramp { a: 0.1, b: 0.0 },
                radius: 0.001
            },
            &Domain::Circle { radius: 0.001 }
        )
        .unwrap_err(),
        RasterError::NothingToCut
    );
    // Where it has one, the plane at the edge cuts the rim: its contacts
    // run out to the aperture grown by a stepover.
    let rim = plan_raster(
        &base,
        &KNIFE,
        &Ramp { a: 0.1, b: 0.0 },
        &Domain::Circle { radius: 0.001 },
    )
    .unwrap();
    let reach = 0.001 + base.stepover;
    let half = (reach * reach - 0.001f64 * 0.001).sqrt();
    assert!((rim.passes[0][0][0] + half).abs() < 1e-12, "{rim:?}");
}

/// A concave sphere R = 1 mm: the cross-section at x = u, the knife
/// edge's, is a circle of radius √(1 − u²), down to 0.6 mm at the
/// aperture's edge (0.8 mm). A 0.7 mm knife does not fit there (it is
/// refused where it first meets a cross-section tighter than itself); a
/// 0.7 mm ball does (principal radius 1 mm); a 1.2 mm ball does not.
#[test]
fn tool_larger_than_the_hollow_is_refused() {
    let bowl = Conic {
        radius: 1.0,
        k: 0.0,
        s: 1.0,
    };
    let aperture = Domain::Circle { radius: 0.8 };
    let r = raster(Axis::X, 0.01, 1e-4);
    match plan_raster(
        &r,
        &RasterTool::Knife { nose_radius: 0.7 },
        &bowl,
        &aperture,
    ) {
        Err(RasterError::ToolTooLarge {
            tool_radius,
            min_radius,
            x,
            y,
        }) => {
            assert_eq!(tool_radius, 0.7);
            assert!(min_radius < 0.7 && min_radius > 0.6 - 1e-9, "{min_radius}");
            let want = (1.0 - x * x).sqrt();
            assert!((min_radius - want).abs() < 1e-9, "{min_radius} at x {x}");
            assert!(x.hypot(y) <= 0.8 + 1e-12, "({x}, {y})");
        }
        other => panic!("{other:?}"),
    }
    let r = raster(Axis::X, 0.05, 1e-4);
    assert!(plan_raster(&r, &RasterTool::Ball { radius: 0.7 }, &bowl, &aperture).is_ok());
    match plan_raster(&r, &RasterTool::Ball { radius: 1.2 }, &bowl, &aperture) {
        Err(RasterError::ToolTooLarge { min_radius, .. }) => {
            assert!((min_radius - 1.0).abs() < 1e-9, "{min_radius}")
        }
        other => panic!("{other:?}"),
    }
}

/// The pre-plan check finds what the planner finds first, with the same
/// figures: the tool too large for the hollow, and on a part it fits, the
/// planes' steepest slope, which the planned path only extends.
#[test]
fn the_pre_plan_check_agrees_with_the_planner() {
    let bowl = Conic {
        radius: 1.0,
        k: 0.0,
        s: 1.0,
    };
    let aperture = Domain::Circle { radius: 0.8 };
    let r = raster(Axis::X, 0.01, 1e-4);
    let knife = RasterTool::Knife { nose_radius: 0.7 };
    let checked = check_raster(&r, &knife, &bowl, &aperture);
    assert!(
        matches!(checked, Err(RasterError::ToolTooLarge { .. })),
        "{checked:?}"
    );
    assert_eq!(
        checked.err(),
        plan_raster(&r, &knife, &bowl, &aperture).err()
    );

    let lens = convex(1.0, -1.0);
    let scan = check_raster(&r, &KNIFE, &lens, &aperture).unwrap();
    let path = plan_raster(&r, &KNIFE, &lens, &aperture).unwrap();
    assert!(scan.max_slope_along.value <= path.max_slope_along.value);
    assert!(
        (scan.max_slope_along.value - path.max_slope_along.value).abs() < 1e-9,
        "the steepest slope lies at a span's end"
    );
    assert!(check_clearance(40f64.to_radians(), scan.max_slope_along).is_ok());
    match check_clearance(20f64.to_radians(), scan.max_slope_along) {
        Err(RasterError::ClearanceTooSmall { slope, x, y, .. }) => {
            assert_eq!(
                (slope, x, y),
                (
                    scan.max_slope_along.value,
                    scan.max_slope_along.x,
                    scan.max_slope_along.y
                )
            );
        }
        other => panic!("{other:?}"),
    }
}

/// The ball's contact for the centre `p` on its plane (along x): where the
/// normal through the centre meets the surface, by bisection on the
/// contact's x.
fn ball_contact_of(ball: &RasterTool, surf: &dyn SurfaceFn, p: [f64; 3]) -> [f64; 3] {
    let rho = ball.radius();
    let on = |t: f64| tool_contact(ball, surf, Axis::X, p[1], t).unwrap();
    let (mut lo, mut hi) = (p[0] - rho, p[0] + rho);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if on(mid).centre[0] < p[0] {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    on(0.5 * (lo + hi)).contact
}

/// Each pass starts and ends with the contact point exactly on the edge of
/// the rim's reach: the aperture (0.8 mm) grown by a stepover (0.05 mm) on
/// a convex lens, whose neighbouring planes' contacts lie closer together
/// than their planes, so every point of the rim lies between two planes'
/// contacts.
#[test]
fn passes_end_where_the_contact_reaches_a_stepover_beyond_the_edge() {
    let surf = convex(1.0, -20.0);
    let r = raster(Axis::X, 0.05, 1e-5);
    let aperture = Domain::Circle { radius: 0.8 };
    let path = plan_raster(&r, &KNIFE, &surf, &aperture).unwrap();
    for pass in &path.passes {
        for p in [pass[0], *pass.last().unwrap()] {
            // The knife's contact is at the centre's x.
            let c = tool_contact(&KNIFE, &surf, Axis::X, p[1], p[0]).unwrap();
            assert!(distance3(p, c.centre) < 1e-15);
            assert!(
                (c.contact[0].hypot(c.contact[1]) - 0.85).abs() < 1e-9,
                "{c:?}"
            );
        }
    }
    let ball = RasterTool::Ball { radius: 0.1 };
    let path = plan_raster(&r, &ball, &surf, &aperture).unwrap();
    for pass in &path.passes {
        for p in [pass[0], *pass.last().unwrap()] {
            let c = ball_contact_of(&ball, &surf, p);
            assert!((c[0].hypot(c[1]) - 0.85).abs() < 1e-9, "{c:?}");
        }
    }
}

/// In a bowl the contacts of neighbouring planes lie further apart than
/// their planes: on a concave sphere of radius R a ball of radius ρ has its
/// centre on the line from the sphere's centre through its contact, so the
/// contacts are the planes scaled by R/(R − ρ), here 2 (R = 1 mm, ρ =
/// 0.5 mm), and a stepover's reach would leave the last plane's contact
/// inside the rim. The passes run out to the aperture grown by the
/// contacts' spacing, 2 stepovers (0.8 + 0.1 mm); the figures stay the
/// aperture's own (the steepest slope along the cut is the edge's,
/// atan(0.8/0.6)).
#[test]
fn in_a_bowl_passes_reach_as_far_beyond_the_edge_as_the_contacts_spread() {
    let bowl = Conic {
        radius: 1.0,
        k: 0.0,
        s: 1.0,
    };
    let ball = RasterTool::Ball { radius: 0.5 };
    let r = raster(Axis::X, 0.05, 1e-5);
    let path = plan_raster(&r, &ball, &bowl, &Domain::Circle { radius: 0.8 }).unwrap();
    for pass in &path.passes {
        for p in [pass[0], *pass.last().unwrap()] {
            let c = ball_contact_of(&ball, &bowl, p);
            assert!((c[0].hypot(c[1]) - 0.9).abs() < 1e-9, "{c:?}");
        }
    }
    // The outermost planes: centres within 0.9 × (R − ρ)/R = 0.45 mm of
    // the axis, planes at −0.8 + 0.05 k; the one at 0.4 mm, which would
    // only graze the aperture's own edge (its contacts 0.8 mm out), cuts.
    let outer = path
        .passes
        .iter()
        .map(|p| p[0][1].abs())
        .fold(0.0, f64::max);
    assert!(outer > 0.4 - 1e-12 && outer < 0.45 + 1e-12, "{outer}");
    let want = (0.8f64 / 0.6).atan();
    assert!(
        (path.max_slope_along.value - want).abs() < 1e-9,
        "{} against {want}",
        path.max_slope_along.value
    );
    assert!(path.max_slope_along.x.hypot(path.max_slope_along.y) <= 0.8 + 1e-12);
}

/// The exact raise of the knife tip above S when the nose is centred
/// over S (the quantity of Lin's eq 4), from the exact centre curve.
fn exact_raise(surface: &dyn SurfaceFn, xs: f64) -> f64 {
    let (_, centre) = knife_centre_at(surface, 0.0, xs);
    centre[2] - LIN_NOSE - surface.eval(xs, 0.0)[0]
}

/// Eq 4 (for Lin's in-plane nose) is exact where the section is
/// straight (δ2 = 0, δ1 exact), and close on a curved one: on a circle
/// of signed radius ρ the exact raise is
/// ρ cos θ − r − sgn ρ √((ρ − r)² − ρ² sin² θ), which eq 4 matches to
/// first order in r/ρ. lensc's knife, its edge across the cut, needs no
/// raise where the cross-section is level: its tip is on S.
#[test]
fn eq4_against_the_exact_centre() {
    for (surf, xs) in [
        (convex(1.0, -20.0), 0.8),
        (convex(1.0, 0.0), 0.5),
        (convex(3.0, 10.0), -0.7),
    ] {
        let c = tool_contact(&KNIFE, &surf, Axis::X, 0.0, xs).unwrap();
        assert_eq!(c.centre[0], xs);
        let raise = c.centre[2] - LIN_NOSE - surf.eval(xs, 0.0)[0];
        assert!(raise.abs() < 1e-15, "{raise:e}");
    }
    // Straight: a ramp of slope 0.3 along x.
    let ramp = Ramp { a: -0.3, b: 0.0 };
    for xs in [-0.5, 0.0, 0.7] {
        let exact = exact_raise(&ramp, xs);
        let lin = lin_interference_offset(LIN_NOSE, f64::INFINITY, -0.3);
        assert!((exact - lin).abs() < 1e-15, "{exact} vs {lin}");
    }
    // Level: nothing to raise.
    assert_eq!(lin_interference_offset(LIN_NOSE, -1.0, 0.0), 0.0);
    // Curved: a convex and a concave sphere R = 1 mm (section at y = 0
    // is a circle of radius 1), r = 85 µm, at slopes θ up to 30°.
    let r = LIN_NOSE;
    for s in [-1.0f64, 1.0] {
        let sphere = Conic {
            radius: 1.0,
            k: 0.0,
            s,
        };
        for (deg, max_rel) in [(5.0, 7.4e-3), (12.43, 7.9e-3), (30.0, 1.23e-2)] {
            let theta = f64::to_radians(deg);
            let xs = theta.sin();
            let o = sphere.eval(xs, 0.0);
            let rho = section_radius(o[1], o[3]);
            assert!((rho - s).abs() < 1e-12);
            let closed = rho * theta.cos()
                - r
                - rho.signum() * ((rho - r).powi(2) - (rho * theta.sin()).powi(2)).sqrt();
            let exact = exact_raise(&sphere, xs);
            assert!((exact - closed).abs() < 1e-12, "{exact} vs {closed}");
            let lin = lin_interference_offset(r, rho, o[1]);
            let rel = (lin - exact) / exact;
            eprintln!(
                "eq 4, s={s} θ={deg}°: exact {:.4} nm, eq 4 {:.4} nm, differ {:.4} nm ({:.3e})",
                exact * 1e6,
                lin * 1e6,
                (lin - exact) * 1e6,
                rel
            );
            // Eq 4 is exact to first order in r/ρ; what remains is
            // about −(r/ρ)², growing with θ.
            assert!(rel < -0.9 * (r / rho).powi(2) && rel > -max_rel, "{rel}");
        }
    }
    // Lin's hyperboloid at its 0.8 mm edge, with the local ρ.
    let hyp = convex(1.0, -20.0);
    let o = hyp.eval(0.8, 0.0);
    let exact = exact_raise(&hyp, 0.8);
    let lin = lin_interference_offset(r, section_radius(o[1], o[3]), o[1]);
    eprintln!(
        "eq 4, k=-20 at 0.8 mm: exact {:.4} nm, eq 4 {:.4} nm, differ {:.3e} nm",
        exact * 1e6,
        lin * 1e6,
        (lin - exact) * 1e6
    );
    assert!(((lin - exact) / exact).abs() < 1e-3);
}

/// The exact counterpart of eqs 5–6: how far inside the edge the
/// contact must stop for the knife tip to stay at the edge's height.
fn exact_inset(surface: &dyn SurfaceFn, edge: f64) -> f64 {
    let z_edge = surface.eval(edge, 0.0)[0];
    let tip = |t: f64| lin_plane_contact(surface, 0.0, t).1[2] - LIN_NOSE;
    // The tip falls towards the edge of the dome (edge > 0).
    let (mut lo, mut hi) = (0.0, edge);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tip(mid) > z_edge {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    edge - 0.5 * (lo + hi)
}

/// Eqs 5–6 (for Lin's in-plane nose) are exact for a straight section;
/// on Lin's curved sections they differ from the exact inset. lensc's
/// knife, its edge across the cut, needs none: the pass ends with the
/// contact on the edge, the centre straight above it and the tip at the
/// edge's height.
#[test]
fn eqs5_6_against_the_exact_centre() {
    let ramp = Ramp { a: -0.3, b: 0.0 };
    let exact = exact_inset(&ramp, 0.5);
    let lin = lin_boundary_offset(LIN_NOSE, -0.3).abs();
    assert!((exact - lin).abs() < 1e-14, "{exact} vs {lin}");
    assert_eq!(lin_boundary_offset(LIN_NOSE, 0.0), 0.0);
    for (name, surf) in [
        ("sphere R=1", convex(1.0, 0.0)),
        ("k=-20", convex(1.0, -20.0)),
        ("k=-1", convex(1.0, -1.0)),
        ("R=3 k=10", convex(3.0, 10.0)),
    ] {
        let o = surf.eval(0.8, 0.0);
        let exact = exact_inset(&surf, 0.8);
        let lin = lin_boundary_offset(LIN_NOSE, o[1]).abs();
        let c = tool_contact(&KNIFE, &surf, Axis::X, 0.0, 0.8).unwrap();
        let theta = o[1].atan();
        assert_eq!(c.centre[0], 0.8);
        assert!((c.centre[2] - LIN_NOSE - o[0]).abs() < 1e-15);
        eprintln!(
            "eqs 5-6, {name} at 0.8 mm (θ {:.3}°): exact inset {:.4} µm, eq 6 {:.4} µm, \
             differ {:.4} µm",
            theta.to_degrees().abs(),
            exact * 1e3,
            lin * 1e3,
            (lin - exact) * 1e3,
        );
        // On a dome the surface falls faster than its tangent, so the
        // exact inset is shorter than the straight-line estimate.
        assert!(lin > exact && exact > 0.0);
    }
}

/// Eq 2 is the chord of a circle exactly; eq 3 takes its horizontal
/// projection with the slope at the step's start. With `lin_angle` set,
/// no planned step between contact points exceeds eq 2–3 at either end.
#[test]
fn lin_step_caps_the_planned_step() {
    let (rho, alpha) = (2.0, 0.1);
    let (p, q): (f64, f64) = (0.3, 0.3 + alpha);
    let chord = rho * (q.sin() - p.sin()).hypot(q.cos() - p.cos());
    assert!((lin_chord(rho, alpha) - chord).abs() < 1e-15);
    assert!((lin_step(rho, alpha, 0.0) - 2.0 * rho * 0.05f64.sin()).abs() < 1e-15);
    assert!((lin_step(-rho, alpha, 1.0) - lin_chord(rho, alpha) / 2f64.sqrt()).abs() < 1e-15);
    assert_eq!(lin_step(f64::INFINITY, alpha, 0.0), f64::INFINITY);

    // Knife on a convex sphere R = 1: the contact is where the radius
    // through the centre meets the section circle.
    let sphere = convex(1.0, 0.0);
    let alpha = 0.5f64.to_radians();
    let mut r = raster(Axis::X, 0.1, 1e-2);
    r.lin_angle = Some(alpha);
    let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
    let mut tightest = 0.0f64;
    for pass in &path.passes {
        let rs = (1.0 - pass[0][1].powi(2)).sqrt();
        let contact = |p: [f64; 3]| {
            let (dx, dz) = (p[0], p[2] + 1.0);
            let n = dx.hypot(dz);
            let (x, z) = (rs * dx / n, rs * dz / n - 1.0);
            (x, -x / (z + 1.0))
        };
        for w in pass.windows(2) {
            let ((x0, s0), (x1, s1)) = (contact(w[0]), contact(w[1]));
            let cap = lin_step(-rs, alpha, s0).min(lin_step(-rs, alpha, s1));
            assert!(
                (x1 - x0).abs() <= cap * (1.0 + 1e-12),
                "{} > {cap}",
                x1 - x0
            );
            tightest = tightest.max((x1 - x0).abs() / cap);
        }
    }
    assert!(tightest > 0.5, "{tightest}");
    // A fixed step cap holds too.
    let mut r = raster(Axis::X, 0.1, 1e-2);
    r.max_step = Some(0.003);
    let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
    assert!(
        path.passes
            .iter()
            .flat_map(|p| p.windows(2))
            .all(|w| distance3(w[0], w[1]) <= 0.003)
    );
}

/// The same paraboloid as an IR tape (z = −(x² + y²)/(2R), Lin's eq 8
/// with k = −1, s = −1) and in closed form plan the same path.
#[test]
fn ir_surface_plans_like_the_closed_form() {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let q2 = g.add(x2, y2);
    let k = g.constant_node(-0.5);
    let z = g.mul(k, q2);
    let f = Interpreter::new(&SurfaceTape::new(g, z));
    let r = raster(Axis::X, 0.05, 1e-5);
    let aperture = Domain::Circle { radius: 0.8 };
    let a = plan_raster(&r, &KNIFE, &f, &aperture).unwrap();
    let b = plan_raster(&r, &KNIFE, &convex(1.0, -1.0), &aperture).unwrap();
    assert_eq!(a.point_count, b.point_count);
    for (p, q) in a.passes.iter().flatten().zip(b.passes.iter().flatten()) {
        assert!(distance3(*p, *q) < 1e-13, "{p:?} vs {q:?}");
    }
}

/// Annulus apertures split the inner planes into two passes, each
/// ending on the inner and outer edges.
#[test]
fn annulus_splits_inner_planes() {
    let surf = convex(1.0, -1.0);
    let r = raster(Axis::X, 0.1, 1e-4);
    let ap = Domain::Annulus {
        inner: 0.25,
        outer: 0.8,
    };
    let path = plan_raster(&r, &KNIFE, &surf, &ap).unwrap();
    // Planes −0.8 … 0.8 (17): on the paraboloid z = −q²/2 the contact
    // lies ρ q/√(1 + q²) nearer the axis than its plane (0.747 mm for the
    // plane at 0.8, 0.843 mm for 0.9, outside). Of them −0.2 … 0.2 (5)
    // are split: the plane at 0.3 has its contacts at 0.276 mm, outside
    // the 0.25 mm hole.
    assert_eq!(path.pass_count, 22);
}

/// Seed 000 appendix eq A1 as printed gives dz/dq = s q (2Q² − (1+k) q²)/Q³
/// with Q = R + √(R² − (1+k) q²); the derivative of eq 8 is
/// s q / √(R² − (1+k) q²). They agree only for the paraboloid (k = −1),
/// which is why the planner uses the surface's exact derivatives.
#[test]
fn appendix_a1_as_printed() {
    let a1 = |radius: f64, k: f64, q: f64| {
        let big_q = radius + (radius * radius - (1.0 + k) * q * q).sqrt();
        -(2.0 * q * big_q - (1.0 + k) * q.powi(3) / big_q) / (big_q * big_q)
    };
    let exact = |radius: f64, k: f64, q: f64| convex(radius, k).eval(q, 0.0)[1];
    assert!((a1(1.0, -1.0, 0.8) - exact(1.0, -1.0, 0.8)).abs() < 1e-15);
    let (p, e) = (a1(1.0, -20.0, 0.8), exact(1.0, -20.0, 0.8));
    eprintln!("A1 at k=-20, q=0.8: printed {p}, exact {e}");
    assert!((p - e).abs() > 0.05);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(5_000))]

    /// The quick chord decision, from distances a few ulps off the exact
    /// ones, is the exact decision whenever it decides: over random probe
    /// distances (ties among them included) and limits at, near and far
    /// from the chord's peak.
    #[test]
    fn the_quick_chord_decision_is_the_exact_one(
        exact in proptest::collection::vec(
            proptest::prop_oneof![1e-9f64..1e-5, proptest::strategy::Just(4e-7)],
            PROBES - 1,
        ),
        ulps in proptest::collection::vec(-4i32..=4, PROBES - 1),
        at in proptest::prop_oneof![
            -1e-13f64..1e-13,
            -1e-8f64..1e-8,
            -0.5f64..0.5,
            proptest::strategy::Just(0.0),
        ],
    ) {
        let mut d = [0.0; PROBES + 1];
        let mut quick = [0.0; PROBES + 1];
        for i in 1..PROBES {
            d[i] = exact[i - 1];
            quick[i] = d[i] * (1.0 + ulps[i - 1] as f64 * f64::EPSILON);
        }
        let limit = chord_peak(&d) * (1.0 + at);
        if let Some(split) = clear_decision(&quick, limit) {
            proptest::prop_assert_eq!(split, chord_peak(&d) > limit);
        }
    }
}

/// Contacts solved side by side in one batch are the contacts solved one
/// at a time, to the last bit, refusals included (points beyond the
/// hyperboloid's domain, planes the tool cannot reach): the batch asks
/// for each solve's points as the solve alone would.
#[test]
fn contacts_solved_side_by_side_are_those_solved_alone() {
    // Defined out to 1/√11 ≈ 0.30 mm; a hollow of radius 0.1 mm.
    let oblate = convex(1.0, 10.0);
    let hollow = Conic {
        radius: 0.1,
        k: 0.0,
        s: 1.0,
    };
    let tools = [
        RasterTool::Ball { radius: 0.2 },
        RasterTool::Ball { radius: 0.05 },
        KNIFE,
    ];
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut solved, mut refused) = (0, 0);
    for (surface, reach) in [(&oblate as &dyn SurfaceFn, 0.35), (&hollow, 0.12)] {
        for along in [Axis::X, Axis::Y] {
            for tool in &tools {
                let cutter = Cutter::new(tool, surface, along);
                for _ in 0..200 {
                    let plane = reach * (2.0 * next() - 1.0);
                    let at: [(f64, f64); PROBES - 1] = std::array::from_fn(|_| {
                        let guess = if next() < 0.1 {
                            f64::NAN
                        } else {
                            plane + 0.02 * (next() - 0.5)
                        };
                        (reach * (2.0 * next() - 1.0), guess)
                    });
                    let together = cutter.contacts(plane, at);
                    for (&(t, guess), c) in at.iter().zip(&together) {
                        let alone = cutter.contact(plane, t, guess);
                        assert_eq!(
                            format!("{c:?}"),
                            format!("{alone:?}"),
                            "at t {t}, plane {plane}"
                        );
                        match c {
                            Ok(_) => solved += 1,
                            Err(_) => refused += 1,
                        }
                    }
                }
            }
        }
    }
    // Both outcomes are exercised.
    assert!(
        solved > 1000 && refused > 1000,
        "{solved} solved, {refused} refused"
    );
}

/// Counts the points a planner asks a surface for.
struct Counting<'a> {
    inner: &'a dyn SurfaceFn,
    points: std::cell::Cell<usize>,
}

impl SurfaceFn for Counting<'_> {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        self.points.set(self.points.get() + xs.len());
        self.inner.eval_batch(xs, ys, out);
    }
}

/// A split chord's halves taking their parent's probe contacts (where
/// asked for at the same t and guess) sample the same contacts, to the
/// last bit, and see the same summary as solving every probe; and they
/// do take some (fewer surface evaluations).
#[test]
fn halves_reusing_their_parents_probes_sample_what_solving_every_probe_samples() {
    let surfaces = [
        convex(3.0, 10.0),
        convex(1.0, -1.0),
        convex(1.0, -20.0),
        Conic {
            radius: 4.0,
            k: 0.0,
            s: 1.0,
        },
    ];
    let tools = [RasterTool::Ball { radius: 0.2 }, KNIFE];
    let (mut with, mut without) = (0, 0);
    for surface in &surfaces {
        for along in [Axis::X, Axis::Y] {
            for tool in &tools {
                for lin_angle in [None, Some(5f64.to_radians())] {
                    let r = Raster {
                        along,
                        zigzag: false,
                        stepover: 0.01,
                        chord_tolerance: 2e-7,
                        max_step: None,
                        lin_angle,
                        retract: 0.5,
                        chords: ChordPlacement::OnPath,
                    };
                    for plane in [-0.31, 0.0, 0.17] {
                        let runs = [true, false].map(|reuse| {
                            let counting = Counting {
                                inner: surface,
                                points: std::cell::Cell::new(0),
                            };
                            let mut cutter = Cutter::new(tool, &counting, along);
                            cutter.reuse_probes = reuse;
                            let mut summary = Summary::new(along);
                            let a = cutter.contact(plane, -0.35, plane).expect("a contact");
                            let b = cutter.contact(plane, 0.35, plane).expect("a contact");
                            let mut budget = MAX_POINTS;
                            let pts = cutter
                                .sample(&r, plane, a, b, &mut budget, &mut summary)
                                .expect("samples");
                            let bits: Vec<[u64; 4]> = pts
                                .iter()
                                .map(|c| [c.u, c.v, c.c[0], c.c[1]].map(f64::to_bits))
                                .collect();
                            let seen = format!(
                                "{:?} {:?} {:?} {:?}",
                                summary.slope_along,
                                summary.slope_across,
                                summary.concave_along,
                                summary.tool_limit
                            );
                            (bits, seen, counting.points.get())
                        });
                        let [(bits, seen, n), (bits_all, seen_all, n_all)] = &runs;
                        assert!(bits.len() > 2, "the pass is split");
                        assert_eq!(bits, bits_all, "plane {plane}, {along:?}, {tool:?}");
                        assert_eq!(seen, seen_all, "plane {plane}, {along:?}, {tool:?}");
                        with += *n;
                        without += *n_all;
                    }
                }
            }
        }
    }
    assert!(
        (with as f64) < 0.9 * without as f64,
        "{with} evaluations reusing probes, {without} solving every one"
    );
}

/// The pre-plan check's planes on a fine raster: as many as it scans at
/// most, evenly spread, in order, with the range's ends and the plane at
/// the aperture's far edge among them; a coarse raster's every plane.
#[test]
fn the_check_scans_a_fine_raster_on_planes_spread_over_it() {
    assert_eq!(sampled(-3, 10, 9, 1024), (-3..=10).collect::<Vec<_>>());
    let ks = sampled(-250, 125_250, 125_000, CHECK_PLANES);
    assert!(ks.len() <= CHECK_PLANES + 1, "{}", ks.len());
    assert_eq!((ks[0], ks[ks.len() - 1]), (-250, 125_250));
    assert!(ks.contains(&125_000));
    assert!(ks.windows(2).all(|w| w[0] < w[1] && w[1] - w[0] <= 123));
}
