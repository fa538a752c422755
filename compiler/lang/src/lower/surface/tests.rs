//! The surface lowering against closed forms and published tables.

use super::*;
use lensc_runtime::surface::ir::{Interpreter, SurfaceFn};
use lensc_runtime::surface::{RotationalSurface, Sense};

/// The IR sag (in r² form, differentiated symbolically) against the
/// runtime's closed-form profile (differentiated by hand), along x and,
/// by symmetry, along y.
#[test]
fn ir_sag_matches_closed_form_profile() {
    let terms = vec![(3, 2e-4), (4, 1.5e-4), (6, -3e-6), (8, 2e-8), (16, 1e-14)];
    for (radius, k, sense) in [
        (22.405, 43.098, Sense::Convex),
        (4.254, -3.359, Sense::Concave),
        (8.5, -0.62, Sense::Convex),
        (5.0, 0.0, Sense::Concave),
    ] {
        let closed = RotationalSurface {
            radius,
            conic: k,
            sense,
            terms: terms.clone(),
            aperture_radius: 1.5,
        };
        let mut g = Graph::new();
        let z = rotational_sag(&mut g, radius, k, &terms, sense.sign());
        let f = Interpreter::new(&SurfaceTape::new(g, z));
        for r in [0.05, 0.4, 0.9, 1.5] {
            let p = closed.eval(r);
            let ox = f.eval(r, 0.0);
            let oy = f.eval(0.0, r);
            let tol = |a: f64| 1e-13 * (1.0 + a.abs());
            assert!(
                (ox[0] - p.z).abs() <= tol(p.z),
                "z R={radius} r={r}: {} vs {}",
                ox[0],
                p.z
            );
            assert!(
                (ox[1] - p.dz).abs() <= tol(p.dz),
                "dz/dx R={radius} r={r}: {} vs {}",
                ox[1],
                p.dz
            );
            assert!(
                (ox[3] - p.d2z).abs() <= tol(p.d2z),
                "d2z/dx2 R={radius} r={r}: {} vs {}",
                ox[3],
                p.d2z
            );
            assert!(
                (oy[0] - p.z).abs() <= tol(p.z)
                    && (oy[2] - p.dz).abs() <= tol(p.dz)
                    && (oy[5] - p.d2z).abs() <= tol(p.d2z)
            );
            assert!(
                ox[2].abs() < 1e-15 && ox[4].abs() < 1e-15,
                "no slope across the section"
            );
        }
    }
}

/// A sphere's sag against R − sqrt(R² − r²) in 2-D, off the axes
/// (written r²/(R + sqrt(R² − r²)) to avoid cancellation).
#[test]
fn sphere_sag_off_axis() {
    let mut g = Graph::new();
    let z = rotational_sag(&mut g, 20.0, 0.0, &[], 1.0);
    let f = Interpreter::new(&SurfaceTape::new(g, z));
    for (x, y) in [(0.3, 0.4), (-0.6, 0.8), (0.85, -0.1)] {
        let r2 = x * x + y * y;
        let want = r2 / (20.0 + (400.0f64 - r2).sqrt());
        let got = f.eval(x, y)[0];
        assert!((got - want).abs() <= 4e-16 * want, "{got} vs {want}");
    }
}

/// Checks `src` and lowers its surface `name`; evaluates at (x, y).
fn eval_surface(src: &str, name: &str, x: f64, y: f64) -> [f64; 6] {
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let o = c.checked.declarations.get(name).expect("surface");
    let l = lower_surface(o).expect("lowers");
    Interpreter::new(&l.tape).eval(x, y)
}

/// The surface `name` of a checked file, read.
fn read_surface(c: &crate::Checked, name: &str) -> crate::schema::Surface {
    let o = c.checked.declarations.get(name).expect("surface");
    crate::schema::Surface::read(o).expect("reads")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-14 * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn zernike_indices_follow_the_tables() {
    // Fringe: Z1 piston, Z4 defocus, Z5/Z6 astigmatism, Z9 spherical,
    // Z10 trefoil, Z16 5th-order spherical, Z36 (10,0), Z37 (12,0).
    assert_eq!(zernike_fringe(1), Some((0, 0)));
    assert_eq!(zernike_fringe(2), Some((1, 1)));
    assert_eq!(zernike_fringe(3), Some((1, -1)));
    assert_eq!(zernike_fringe(4), Some((2, 0)));
    assert_eq!(zernike_fringe(6), Some((2, -2)));
    assert_eq!(zernike_fringe(9), Some((4, 0)));
    assert_eq!(zernike_fringe(10), Some((3, 3)));
    assert_eq!(zernike_fringe(16), Some((6, 0)));
    assert_eq!(zernike_fringe(36), Some((10, 0)));
    assert_eq!(zernike_fringe(37), Some((12, 0)));
    assert_eq!(zernike_fringe(38), None);
    // ANSI Z80.28: j = (n(n+2) + m)/2.
    for n in 0..12u32 {
        for m in (-(n as i32)..=n as i32).step_by(2) {
            let j = ((n * (n + 2)) as i32 + m) / 2;
            assert_eq!(zernike_ansi(j as u32), (n, m), "j={j}");
        }
    }
}

#[test]
fn zernike_terms_match_their_polynomials() {
    let base = "surface w = zernike { sense: concave, norm_radius: 2 mm, ordering: ORD, aperture: circle(radius: 2 mm), TERM: 1 um }";
    let at = |ord: &str, term: &str, x: f64, y: f64| {
        eval_surface(&base.replace("ORD", ord).replace("TERM", term), "w", x, y)[0]
    };
    let (x, y): (f64, f64) = (0.7, -1.1);
    let (rho, th) = ((x * x + y * y).sqrt() / 2.0, f64::atan2(y, x));
    let um = 1e-3;
    // Fringe Z9 = 6ρ⁴ − 6ρ² + 1; Z8 = (3ρ³ − 2ρ) sin θ; Z10 = ρ³ cos 3θ.
    assert!(close(
        at("fringe", "Z9", x, y),
        um * (6.0 * rho.powi(4) - 6.0 * rho * rho + 1.0)
    ));
    assert!(close(
        at("fringe", "Z8", x, y),
        um * (3.0 * rho.powi(3) - 2.0 * rho) * th.sin()
    ));
    assert!(close(
        at("fringe", "Z10", x, y),
        um * rho.powi(3) * (3.0 * th).cos()
    ));
    // ANSI j = 12 is (4, 0) normalised by sqrt(5); j = 3 is (2, −2) by sqrt(6).
    assert!(close(
        at("ansi", "Z12", x, y),
        um * 5f64.sqrt() * (6.0 * rho.powi(4) - 6.0 * rho * rho + 1.0)
    ));
    assert!(close(
        at("ansi", "Z3", x, y),
        um * 6f64.sqrt() * rho * rho * (2.0 * th).sin()
    ));
}

#[test]
fn cylinder_toroid_biconic_ellipsoid_and_xy_polynomial() {
    let (x, y) = (0.3, -0.45);
    // A cylinder along y varies only with x.
    let cyl = eval_surface(
        "surface c = cylinder { radius: 2 mm, axis: y, sense: concave, aperture: circle(radius: 1 mm) }",
        "c",
        x,
        y,
    );
    assert!(close(cyl[0], x * x / (2.0 + (4.0 - x * x).sqrt())) && cyl[2] == 0.0 && cyl[5] == 0.0);
    // A biconic with equal radii and conics is the conic of revolution.
    let bic = eval_surface(
        "surface b = biconic { radius_x: 3 mm, radius_y: 3 mm, conic_x: -0.5, conic_y: -0.5, sense: convex, aperture: circle(radius: 1 mm) }",
        "b",
        x,
        y,
    );
    let con = eval_surface(
        "surface b = conic { radius: 3 mm, conic: -0.5, sense: convex, aperture: circle(radius: 1 mm) }",
        "b",
        x,
        y,
    );
    for k in 0..6 {
        assert!(
            close(bic[k], con[k]),
            "output {k}: {} vs {}",
            bic[k],
            con[k]
        );
    }
    // A toroid whose rotation radius equals its profile radius is a sphere.
    let tor = eval_surface(
        "surface t = toroid { radius: 4 mm, rotation_radius: 4 mm, sense: concave, aperture: circle(radius: 1 mm) }",
        "t",
        x,
        y,
    );
    let sph = eval_surface(
        "surface t = sphere { radius: 4 mm, sense: concave, aperture: circle(radius: 1 mm) }",
        "t",
        x,
        y,
    );
    for k in 0..6 {
        assert!(
            close(tor[k], sph[k]),
            "output {k}: {} vs {}",
            tor[k],
            sph[k]
        );
    }
    // At x = 0 a toroid is its y–z profile; along x a circle of the rotation radius.
    let tor = eval_surface(
        "surface t = toroid { radius: 4 mm, rotation_radius: 10 mm, sense: concave, aperture: circle(radius: 1 mm) }",
        "t",
        0.0,
        y,
    );
    assert!(close(tor[0], y * y / (4.0 + (16.0 - y * y).sqrt())));
    let tor = eval_surface(
        "surface t = toroid { radius: 4 mm, rotation_radius: 10 mm, sense: concave, aperture: circle(radius: 1 mm) }",
        "t",
        x,
        0.0,
    );
    assert!(close(tor[0], x * x / (10.0 + (100.0 - x * x).sqrt())));
    // Seed 002's lenslet: a = b = 0.505 mm, c = 1.01 mm, a dimple.
    let e = eval_surface(
        "surface e = ellipsoid { a: 0.505 mm, b: 0.505 mm, c: 1.01 mm, sense: concave, aperture: circle(diameter: 0.1 mm) }",
        "e",
        0.03,
        0.04,
    );
    assert!(close(
        e[0],
        1.01 * (1.0 - (1.0f64 - 0.0025 / (0.505 * 0.505)).sqrt())
    ));
    // XY polynomial on a plane: 0.01 x²y − 0.002 y³ (coefficients in mm^-2).
    let p = eval_surface(
        "surface p = xy_polynomial { sense: concave, aperture: circle(radius: 1 mm), X2Y1: 0.01 mm^-2, X0Y3: -0.002 mm^-2 }",
        "p",
        x,
        y,
    );
    assert!(close(p[0], 0.01 * x * x * y - 0.002 * y * y * y));
    assert!(close(p[4], 0.02 * x));
}

#[test]
fn optical_sign_convention_matches_sense() {
    // Kim 2008's concave R = −4.254 mm, k = −3.359 in the optical
    // convention is the same surface as |R| with `sense: concave`; a
    // positive optical R is convex. Coefficients follow the sag's sign.
    let (x, y) = (0.4, 0.9);
    let opt = eval_surface(
        "surface s = asphere { radius: -4.254 mm, conic: -3.359, convention: optical, A4: 1e-3 mm^-3, aperture: circle(radius: 1.5 mm) }",
        "s",
        x,
        y,
    );
    let sen = eval_surface(
        "surface s = asphere { radius: 4.254 mm, conic: -3.359, sense: concave, A4: -1e-3 mm^-3, aperture: circle(radius: 1.5 mm) }",
        "s",
        x,
        y,
    );
    for k in 0..6 {
        assert!(
            close(opt[k], sen[k]),
            "output {k}: {} vs {}",
            opt[k],
            sen[k]
        );
    }
    let opt = eval_surface(
        "surface s = conic { radius: 22.405 mm, conic: 43.098, convention: optical, aperture: circle(radius: 1.6 mm) }",
        "s",
        x,
        y,
    );
    let sen = eval_surface(
        "surface s = conic { radius: 22.405 mm, conic: 43.098, sense: convex, aperture: circle(radius: 1.6 mm) }",
        "s",
        x,
        y,
    );
    assert!(close(opt[0], sen[0]) && opt[0] < 0.0);
}

#[test]
fn off_axis_section_and_wrap() {
    // An off-axis section of a paraboloid z = r²/(2R) centred at (3, 0):
    // z(x, y) = ((x+3)² + y² − 9)/(2R); with the tilt removed, x²+y² over 2R.
    let src = "surface p = conic { radius: 10 mm, conic: -1, sense: concave, aperture: circle(radius: 5 mm) }
surface s = off_axis(p, x: 3 mm, y: 0 mm, aperture: circle(radius: 1 mm))
surface t = off_axis(p, x: 3 mm, y: 0 mm, tilt: remove, aperture: circle(radius: 1 mm))";
    let (x, y) = (0.4, -0.7);
    let s = eval_surface(src, "s", x, y);
    assert!(
        close(s[0], ((x + 3.0) * (x + 3.0) + y * y - 9.0) / 20.0) && close(s[1], (x + 3.0) / 10.0)
    );
    // With the tilt removed: the section turned rigidly, level at its
    // centre (`tilt_removed_is_the_exact_turned_section` checks the turn).
    let t = eval_surface(src, "t", 0.0, 0.0);
    assert!(
        t[0].abs() < 1e-15 && t[1].abs() < 1e-15 && t[2].abs() < 1e-15,
        "{t:?}"
    );
    // A wrapped design evaluates as the flat design.
    let w = eval_surface(
        "surface f = freeform { z(x, y) = 0.02 mm * sin(5 rad/mm * x), domain: rect(x: 0 mm .. 6 mm, y: 0 mm .. 18.84955592153876 mm) }
surface w = wrap(f, onto: roller(radius: 3 mm))",
        "w",
        0.3,
        1.0,
    );
    assert!(close(w[0], 0.02 * 1.5f64.sin()));
}

/// sag of a sphere of radius R at r: r²/(R + sqrt(R² − r²)).
fn sphere_sag(radius: f64, r: f64) -> f64 {
    r * r / (radius + (radius * radius - r * r).sqrt())
}

#[test]
fn grid_places_clips_and_lands() {
    let src =
        "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.3 mm) }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 2)";
    let rim = sphere_sag(2.0, 0.3);
    // Centres at (±0.5, ±0.5); the rim sits on the land, z = 0.
    assert!(close(eval_surface(src, "a", 0.5, 0.5)[0], -rim));
    assert!(close(eval_surface(src, "a", -0.5, 0.5)[0], -rim));
    assert!(close(
        eval_surface(src, "a", 0.6, 0.5)[0],
        sphere_sag(2.0, 0.1) - rim
    ));
    assert_eq!(
        eval_surface(src, "a", 0.0, 0.0)[0],
        0.0,
        "land between the lenslets"
    );
    assert_eq!(
        eval_surface(src, "a", 0.5, 0.85)[0],
        0.0,
        "outside the aperture"
    );
}

#[test]
fn overlapping_lenslets_keep_the_deepest_cut() {
    // Convex bumps 1 mm apart whose apertures (0.8 mm) overlap: between
    // them the lower of the two profiles is what is left.
    let src = "surface l = sphere { radius: 2 mm, sense: convex, aperture: circle(radius: 0.8 mm) }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 1)";
    let rim = sphere_sag(2.0, 0.8);
    let near = rim - sphere_sag(2.0, 0.4);
    let far = rim - sphere_sag(2.0, 0.6);
    let z = eval_surface(src, "a", 0.1, 0.0)[0];
    assert!(
        close(z, near.min(far)) && far < near,
        "{z} vs {near} / {far}"
    );
    // Concave dimples: the nearer (deeper) one wins.
    let src = src.replace("convex", "concave");
    let z = eval_surface(&src, "a", 0.1, 0.0)[0];
    assert!(close(
        z,
        (sphere_sag(2.0, 0.4) - rim).min(sphere_sag(2.0, 0.6) - rim)
    ));
}

#[test]
fn hex_rows_alternate_by_half_a_pitch() {
    let src =
        "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.2 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 3, count_y: 2)";
    let rim = sphere_sag(2.0, 0.2);
    let row = 3f64.sqrt() / 2.0;
    // Rows at y = ∓row/2; row 0 shifted by −1/4, row 1 by +1/4.
    for (x, y) in [
        (-1.25, -row / 2.0),
        (-0.25, -row / 2.0),
        (0.75, -row / 2.0),
        (-0.75, row / 2.0),
        (0.25, row / 2.0),
        (1.25, row / 2.0),
    ] {
        assert!(
            close(eval_surface(src, "h", x, y)[0], -rim),
            "no lenslet centre at ({x}, {y})"
        );
    }
    assert_eq!(eval_surface(src, "h", 0.25, -row / 2.0)[0], 0.0);
}

#[test]
fn a_hex_grid_s_centres_are_its_lenslets_deepest_points() {
    // The per-lenslet figures of a simulation go by these centres: before
    // issue #29 a hex grid had none (`None`), so its lenslets went
    // unreported and ungated.
    let src =
        "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.2 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 3, count_y: 3)";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let o = c.checked.declarations.get("h").expect("surface");
    let centres = array_centres(o).expect("a hex grid's centres");
    assert_eq!(centres.len(), 9);
    let rim = sphere_sag(2.0, 0.2);
    let row = 3f64.sqrt() / 2.0;
    // The middle row (odd) is shifted by +1/4 pitch: no lenslet on the axis.
    assert!(centres.contains(&(0.25, 0.0)) && centres.contains(&(-1.25, -row)));
    for &(x, y) in &centres {
        assert!(
            close(eval_surface(src, "h", x, y)[0], -rim),
            "no lenslet centre at ({x}, {y})"
        );
    }
}

#[test]
fn a_hex_grid_names_its_lenslet_centres() {
    // The simulation judges an array lenslet by lenslet, and the planner
    // samples only over them: a hex grid without its centres was judged
    // over its land, where a settled spiral holds the tool above it
    // (issue #29: 10.9 um "residual" over the land of a 5 x 5 hex array).
    let src =
        "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.2 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 3, count_y: 2)";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let o = c.checked.declarations.get("h").expect("surface");
    let centres = array_centres(o).expect("a hex grid has centres");
    assert_eq!(centres.len(), 6);
    let rim = sphere_sag(2.0, 0.2);
    for &(x, y) in &centres {
        assert!(
            close(eval_surface(src, "h", x, y)[0], -rim),
            "no lenslet centre at ({x}, {y})"
        );
    }
    let row = 3f64.sqrt() / 2.0;
    assert!(close(centres[0].0, -1.25) && close(centres[0].1, -row / 2.0));
    assert!(close(centres[5].0, 1.25) && close(centres[5].1, row / 2.0));
}

#[test]
fn a_settled_trajectory_has_finite_slopes_wherever_a_spiral_goes() {
    // Issue 15's 5 × 5 hex array (R 3 mm): at its edges the cell indices
    // clamp, and a neighbour 3.02 mm off was continued past its sphere's
    // radius (NaN). The minimum's value skipped it, its slopes did not:
    // the planner lost the nose radius there (102,427 m/s² at r = 3.49
    // mm, outside every lenslet).
    let src =
        "surface l = sphere { radius: 3 mm, sense: concave, aperture: circle(diameter: 0.9 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 5, count_y: 5)";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let o = c.checked.declarations.get("h").expect("surface");
    let settle = 0.017694;
    let f = Interpreter::new(&lower_trajectory(o, settle).expect("lowers").tape);
    let n = 281;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                -3.5 + 7.0 * i as f64 / (n - 1) as f64,
                -3.5 + 7.0 * j as f64 / (n - 1) as f64,
            );
            let out = f.eval(x, y);
            assert!(out.iter().all(|v| v.is_finite()), "({x}, {y}): {out:?}");
            assert!(out[0] <= settle, "({x}, {y}) above the plateau");
        }
    }
    // The point the spiral met: on the plateau, level.
    let out = f.eval(3.473, 0.4332);
    assert_eq!(out[0], settle);
    assert_eq!(out[1..3], [0.0, 0.0]);
}

#[test]
fn qbfs_is_the_sphere_plus_the_published_departure() {
    // Best-fit sphere R = 25 mm, ρ_max = 4 mm, a_0 … a_3 in µm.
    let src = "surface q = qbfs { radius: 25 mm, sense: concave, norm_radius: 4 mm, aperture: circle(radius: 4 mm), Q0: 2 um, Q1: -1 um, Q2: 0.5 um, Q3: 0.25 um }";
    let (x, y): (f64, f64) = (1.3, -2.1);
    let rho2 = x * x + y * y;
    let u2 = rho2 / 16.0;
    let q = [
        1.0,
        (13.0 - 16.0 * u2) / 19f64.sqrt(),
        (2.0f64 / 95.0).sqrt() * (29.0 - 4.0 * u2 * (25.0 - 19.0 * u2)),
        (2.0f64 / 2545.0).sqrt() * (207.0 - 4.0 * u2 * (315.0 - u2 * (577.0 - 320.0 * u2))),
    ];
    let a = [2e-3, -1e-3, 0.5e-3, 0.25e-3];
    let c = 1.0 / 25.0;
    let sum: f64 = a.iter().zip(q).map(|(a, q)| a * q).sum();
    let want = c * rho2 / (1.0 + (1.0 - c * c * rho2).sqrt())
        + u2 * (1.0 - u2) / (1.0 - c * c * rho2).sqrt() * sum;
    let got = eval_surface(src, "q", x, y)[0];
    assert!((got - want).abs() < 1e-15, "{got} vs {want}");
    // At the edge (u = 1) the departure vanishes: the best-fit sphere.
    let edge = eval_surface(src, "q", 4.0, 0.0)[0];
    assert!((edge - c * 16.0 / (1.0 + (1.0f64 - c * c * 16.0).sqrt())).abs() < 1e-15);
}

#[test]
fn qcon_is_the_conic_plus_the_published_departure() {
    // Conic R = 12 mm, k = −0.8, ρ_max = 3 mm; Forbes 2007's closed forms
    // Q_0 = 1, Q_1 = −(5 − 6x), Q_2 = 15 − 14x(3 − 2x).
    let src = "surface q = qcon { radius: 12 mm, conic: -0.8, sense: convex, norm_radius: 3 mm, aperture: circle(radius: 3 mm), Q0: 1.5 um, Q1: -0.4 um, Q2: 0.2 um }
surface l = qcon { radius: 12 mm, conic: -0.8, sense: convex, norm_radius: 0.4 mm, aperture: circle(radius: 0.4 mm), Q1: 1 um }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 2)";
    let (x, y): (f64, f64) = (0.9, -2.2);
    let rho2 = x * x + y * y;
    let u2 = rho2 / 9.0;
    let (c, k) = (1.0 / 12.0, -0.8);
    let q = [1.0, -(5.0 - 6.0 * u2), 15.0 - 14.0 * u2 * (3.0 - 2.0 * u2)];
    let a = [1.5e-3, -0.4e-3, 0.2e-3];
    let sum: f64 = a.iter().zip(q).map(|(a, q)| a * q).sum();
    let sag = c * rho2 / (1.0 + (1.0 - (1.0 + k) * c * c * rho2).sqrt()) + u2 * u2 * sum;
    let got = eval_surface(src, "q", x, y)[0];
    assert!((got + sag).abs() < 1e-15, "{got} vs {}", -sag);
    // In an array the lenslet is the same surface about its centre, its
    // rim (ρ = 0.4 mm) at the land.
    let lens = |r2: f64| {
        let u2 = r2 / 0.16;
        c * r2 / (1.0 + (1.0 - (1.0 + k) * c * c * r2).sqrt()) + u2 * u2 * 1e-3 * -(5.0 - 6.0 * u2)
    };
    let (dx, dy) = (0.1, -0.25);
    let want = lens(0.16) - lens(dx * dx + dy * dy);
    let got = eval_surface(src, "a", 0.5 + dx, 0.5 + dy)[0];
    assert!(close(got, want), "{got} vs {want}");
}

#[test]
fn tilted_sphere_is_the_sphere_with_its_centre_turned() {
    // A concave sphere R = 5 mm (centre (0, 0, 5)) turned 10° about y has
    // its centre at (5 sin θ, 0, 5 cos θ); its lower cap is the height.
    let src = "surface s = sphere { radius: 5 mm, sense: concave, aperture: circle(radius: 2 mm) }
surface t = tilt(s, about: y, angle: 10 deg, aperture: circle(radius: 1.5 mm))
surface u = tilt(s, about: x, angle: -7 deg, aperture: circle(radius: 1.5 mm))";
    let th = 10f64.to_radians();
    let (xc, zc) = (5.0 * th.sin(), 5.0 * th.cos());
    for (x, y) in [(0.0, 0.0), (0.7, -0.4), (-1.1, 0.9)] {
        let o = eval_surface(src, "t", x, y);
        let d = (25.0 - (x - xc) * (x - xc) - y * y).sqrt();
        assert!(
            close(o[0], zc - d),
            "z at ({x}, {y}): {} vs {}",
            o[0],
            zc - d
        );
        assert!(
            close(o[1], (x - xc) / d),
            "dz/dx at ({x}, {y}): {} vs {}",
            o[1],
            (x - xc) / d
        );
        assert!(close(o[2], y / d), "dz/dy at ({x}, {y})");
    }
    // About x, right-handed: the centre (0, 0, 5) goes to (0, −5 sin φ, 5 cos φ).
    let ph = (-7f64).to_radians();
    let (yc, zc) = (-5.0 * ph.sin(), 5.0 * ph.cos());
    let (x, y) = (0.3, 0.8);
    let d = (25.0 - x * x - (y - yc) * (y - yc)).sqrt();
    assert!(close(eval_surface(src, "u", x, y)[0], zc - d));
}

/// Seed 002's grid of overlapping concave ellipsoids (each aperture
/// reaches into eight neighbours) evaluated at the point's own cell alone
/// against every cell that may reach it: the same height, bit for bit,
/// except within rounding of the ridges where two dimples are equally
/// deep; slopes and curvatures the same up to the rounding the reference
/// adds where it folds a losing neighbour into its minimum's derivative;
/// and the flat array's selected slopes bit for bit. A convex lenslet
/// keeps every candidate (the farther bump is the lower there).
#[test]
fn a_grid_of_dimples_cuts_at_its_own_cell_alone() {
    use super::arrays::{Cells, array_height_settled, array_outputs_of};
    let src = "surface dimple = ellipsoid { a: 0.505 mm, b: 0.505 mm, c: 1.01 mm, sense: concave, aperture: circle(radius: 0.12 mm) }
surface microlenses = grid(dimple, pitch_x: 0.1 mm, pitch_y: 0.19634954084936207 mm, count_x: 60, count_y: 96)";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let crate::schema::Surface::Array(o) = &read_surface(&c, "microlenses") else {
        panic!("an array")
    };
    let tapes = |cells: Cells| {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let z = array_height_settled(&mut g, o, x, y, None, cells).expect("lowers");
        let height = SurfaceTape::new(g, z);
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let outputs = array_outputs_of(&mut g, o, (x, y), cells).expect("lowers");
        (height, SurfaceTape::with_outputs(g, outputs))
    };
    let (own, own_flat) = tapes(Cells::NearestWhereItWins);
    let (every, every_flat) = tapes(Cells::Reaching);
    assert!(
        own.live_nodes().len() * 4 < every.live_nodes().len(),
        "one lenslet, not nine: {} vs {} nodes",
        own.live_nodes().len(),
        every.live_nodes().len()
    );
    let (own, every) = (Interpreter::new(&own), Interpreter::new(&every));
    let (own_flat, every_flat) = (Interpreter::new(&own_flat), Interpreter::new(&every_flat));
    let (px, py) = (0.1, 0.19634954084936207);
    // Three cells each way around an inner one and the grid's corner, at
    // 1 µm steps, on the ridges and a few ulps either side of them.
    let mut xs: Vec<f64> = (-150..=150).map(|i| 0.001 * f64::from(i)).collect();
    let mut ys: Vec<f64> = (-150..=150).map(|i| py / 100.0 * f64::from(i)).collect();
    for k in -2..=2 {
        // Both counts are even: the cells' edges are whole pitches.
        let (ex, ey) = (f64::from(k) * px, f64::from(k) * py);
        for (v, list) in [(ex, &mut xs), (ey, &mut ys)] {
            let mut t = v;
            for _ in 0..4 {
                t = t.next_down();
            }
            for _ in 0..9 {
                list.push(t);
                t = t.next_up();
            }
        }
    }
    let corner = (30.0 * px, 48.0 * py);
    xs.extend((0..40).map(|i| corner.0 - 0.15 + 0.01 * f64::from(i)));
    ys.extend((0..40).map(|i| corner.1 - 0.3 + 0.02 * f64::from(i)));
    let on_ridge = |t: f64, p: f64| {
        let f = (t / p).rem_euclid(1.0);
        f.min(1.0 - f) < 1e-9
    };
    let (mut compared, mut ridges) = (0, 0);
    for &x in &xs {
        for &y in &ys {
            let (a, b) = (own.eval(x, y), every.eval(x, y));
            let (fa, fb) = (own_flat.eval(x, y), every_flat.eval(x, y));
            if on_ridge(x, px) || on_ridge(y, py) {
                ridges += 1;
                assert!((a[0] - b[0]).abs() <= 1e-15, "z at ridge ({x}, {y})");
                continue;
            }
            compared += 1;
            assert_eq!(a[0].to_bits(), b[0].to_bits(), "z at ({x}, {y})");
            assert_eq!(fa, fb, "flat array's outputs at ({x}, {y})");
            for k in 1..6 {
                let tol = 1e-13 * (1.0 + b[k].abs());
                assert!(
                    (a[k] - b[k]).abs() <= tol,
                    "output {k} at ({x}, {y}): {} vs {}",
                    a[k],
                    b[k]
                );
            }
        }
    }
    assert!(compared > 100_000 && ridges > 1000, "{compared} {ridges}");

    // Convex bumps: the own cell's is the higher one, so all are kept.
    let convex = src.replace("concave", "convex");
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", convex.as_bytes());
    let crate::schema::Surface::Array(o) = &read_surface(&c, "microlenses") else {
        panic!("an array")
    };
    let nodes = |cells: Cells| {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let z = array_height_settled(&mut g, o, x, y, None, cells).expect("lowers");
        SurfaceTape::new(g, z).live_nodes().len()
    };
    assert_eq!(nodes(Cells::NearestWhereItWins), nodes(Cells::Reaching));
}

#[test]
fn tilted_curvatures_are_the_turned_sphere_s() {
    // The tilted sphere of `tilted_sphere_is_the_sphere_with_its_centre_turned`:
    // z = z_c − d, d = √(25 − u² − v²) with (u, v) the point less the
    // turned centre, so z_uu = 1/d + u²/d³, z_uv = u v/d³, z_vv = 1/d + v²/d³
    // — the closed-form curvatures of a tilted surface of its own.
    let src = "surface s = sphere { radius: 5 mm, sense: concave, aperture: circle(radius: 2 mm) }
surface t = tilt(s, about: y, angle: 10 deg, aperture: circle(radius: 1.5 mm))
surface u = tilt(s, about: x, angle: -7 deg, aperture: circle(radius: 1.5 mm))";
    let th = 10f64.to_radians();
    let ph = (-7f64).to_radians();
    // (surface, centre (x, y, z) after the turn)
    let cases = [
        ("t", (5.0 * th.sin(), 0.0, 5.0 * th.cos())),
        ("u", (0.0, -5.0 * ph.sin(), 5.0 * ph.cos())),
    ];
    for (name, (xc, yc, zc)) in cases {
        for (x, y) in [(0.0, 0.0), (0.7, -0.4), (-1.1, 0.9), (1.2, 0.6)] {
            let (u, v) = (x - xc, y - yc);
            let d = (25.0 - u * u - v * v).sqrt();
            let d3 = d * d * d;
            let want = [
                zc - d,
                u / d,
                v / d,
                1.0 / d + u * u / d3,
                u * v / d3,
                1.0 / d + v * v / d3,
            ];
            let got = eval_surface(src, name, x, y);
            for k in 0..6 {
                assert!(
                    close(got[k], want[k]),
                    "{name} output {k} at ({x}, {y}): {} vs {}",
                    got[k],
                    want[k]
                );
            }
        }
    }
}

#[test]
fn tilted_derivatives_agree_with_those_through_the_newton_steps() {
    // The closed forms against the graph's derivatives of the six Newton
    // steps (how a tilt inside another surface is differentiated), for an
    // asphere with an odd term, turned either way: the same values to
    // within rounding.
    let src = "surface p = asphere { radius: 9 mm, conic: -0.6, sense: concave, aperture: circle(radius: 3 mm), A4: 1e-4 mm^-3, A3: -2e-4 mm^-2 }
surface ty = tilt(p, about: y, angle: 12 deg, aperture: circle(radius: 1.5 mm))
surface tx = tilt(p, about: x, angle: -8 deg, aperture: circle(radius: 1.5 mm))";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    for name in ["ty", "tx"] {
        let o = c.checked.declarations.get(name).expect("surface");
        let closed = Interpreter::new(&lower_surface(o).expect("lowers").tape);
        let crate::schema::Surface::Tilt(t) = &read_surface(&c, name) else {
            panic!("a tilt")
        };
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let z = derived::tilted_height(&mut g, t, x, y).expect("lowers");
        let through = SurfaceTape::new(g, z);
        let steps = Interpreter::new(&through);
        assert!(
            closed_nodes(o) * 4 < through.live_nodes().len(),
            "{name}: the closed forms are the smaller tape"
        );
        // (Away from the parent's vertex, where the A3 term's curvature is
        // not defined.)
        for (x, y) in [
            (0.2, 0.1),
            (0.9, -0.3),
            (-1.2, 0.8),
            (0.4, 1.4),
            (-1.0, -1.0),
        ] {
            same_z_close_derivatives(name, (x, y), closed.eval(x, y), steps.eval(x, y));
        }
    }
}

#[test]
fn a_tilt_s_newton_steps_are_one_loop_with_the_bits_of_the_steps_written_out() {
    // A tilted surface of its own holds its six Newton steps as one loop
    // (`Node::Repeat`, the body once), and all six outputs are bit for bit
    // those of the steps written out; with no turn there is no loop (the
    // steps written out fold to p = P, which a loop's body could not).
    let src = "surface p = asphere { radius: 9 mm, conic: -0.6, sense: concave, aperture: circle(radius: 3 mm), A4: 1e-4 mm^-3, A3: -2e-4 mm^-2 }
surface ty = tilt(p, about: y, angle: 12 deg, aperture: circle(radius: 1.5 mm))
surface tx = tilt(p, about: x, angle: -8 deg, aperture: circle(radius: 1.5 mm))
surface t0 = tilt(p, about: y, angle: 0 deg, aperture: circle(radius: 1.5 mm))";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    for (name, loops) in [("ty", 1), ("tx", 1), ("t0", 0)] {
        let o = c.checked.declarations.get(name).expect("surface");
        let looped = lower_surface(o).expect("lowers").tape;
        let repeats = looped
            .live_nodes()
            .into_iter()
            .filter(|&i| {
                matches!(
                    looped.graph.node(i),
                    lensc_runtime::surface::ir::Node::Repeat { .. }
                )
            })
            .count();
        assert_eq!(repeats, loops, "{name}: loops in the tape");
        let crate::schema::Surface::Tilt(t) = &read_surface(&c, name) else {
            panic!("a tilt")
        };
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let outputs = derived::tilted_outputs_with(&mut g, t, x, y, derived::Steps::WrittenOut)
            .expect("lowers");
        let written = SurfaceTape::with_outputs(g, outputs);
        if loops == 1 {
            assert!(
                looped.live_nodes().len() * 3 < written.live_nodes().len() * 2,
                "{name}: the body is written once"
            );
        }
        let (a, b) = (Interpreter::new(&looped), Interpreter::new(&written));
        for i in 0..=20 {
            for j in 0..=20 {
                let (px, py) = (-1.5 + 0.15 * f64::from(i), -1.5 + 0.15 * f64::from(j));
                let (oa, ob) = (a.eval(px, py), b.eval(px, py));
                for k in 0..6 {
                    assert_eq!(
                        oa[k].to_bits(),
                        ob[k].to_bits(),
                        "{name} output {k} at ({px}, {py}): {} looped, {} written out",
                        oa[k],
                        ob[k]
                    );
                }
            }
        }
    }
}

/// Closed-form outputs `a` against the graph's `b` at `at`: z bit for bit
/// (the same nodes), the slopes and curvatures within 1e-13 relative.
fn same_z_close_derivatives(name: &str, at: (f64, f64), a: [f64; 6], b: [f64; 6]) {
    assert_eq!(
        a[0].to_bits(),
        b[0].to_bits(),
        "{name}: z is the same nodes"
    );
    for k in 1..6 {
        assert!(
            (a[k] - b[k]).abs() <= 1e-13 * (1.0 + b[k].abs()),
            "{name} output {k} at {at:?}: {} vs {}",
            a[k],
            b[k]
        );
    }
}

/// The live nodes of a surface's lowered tape.
fn closed_nodes(o: &crate::value::Object) -> usize {
    lower_surface(o).expect("lowers").tape.live_nodes().len()
}

#[test]
fn revolved_derivatives_agree_with_the_graph_s() {
    // A revolved array of cylinders (seed 004's rings, three of them) and
    // a revolved cylinder: the closed forms against the graph's
    // derivatives of the height through u = start + r.
    let src = "surface cyl = cylinder { radius: 0.788 mm, axis: y, sense: convex, aperture: rect(x: -0.267 mm .. 0.267 mm, y: -1 mm .. 1 mm) }
surface row = linear_array(cyl, pitch: 0.554 mm, count: 3, axis: x)
surface rings = revolve(row, start: -0.831 mm, aperture: circle(radius: 1.662 mm))
surface dome = revolve(cyl, start: 0 mm, aperture: circle(radius: 0.25 mm))
surface tip = revolve(cyl, start: 0.1 mm, aperture: circle(radius: 0.15 mm))";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags());
    let decl = |name: &str| c.checked.declarations.get(name).expect("surface");
    let closed = |name: &str| Interpreter::new(&lower_surface(decl(name)).expect("lowers").tape);
    let through = |name: &str| {
        let crate::schema::Surface::Revolve(r) = &read_surface(&c, name) else {
            panic!("a revolved profile")
        };
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let z = derived::revolve_height(&mut g, r, x, y).expect("lowers");
        SurfaceTape::new(g, z)
    };
    for name in ["rings", "dome", "tip"] {
        let (a, b) = (closed(name), Interpreter::new(&through(name)));
        assert!(
            closed_nodes(decl(name)) < through(name).live_nodes().len(),
            "{name}: the closed forms are the smaller tape"
        );
        let pts = [
            (0.2, 0.1),
            (0.13, -0.05),
            (-0.07, 0.11),
            (0.9, -0.6),
            (-1.1, 0.4),
        ];
        for (x, y) in pts
            .into_iter()
            .filter(|&(x, y)| name == "rings" || x * x + y * y < 0.02)
        {
            same_z_close_derivatives(name, (x, y), a.eval(x, y), b.eval(x, y));
        }
    }
    // On the axis: the rings start on the land (all derivatives 0, as the
    // graph's selects give); the dome is level there (slopes 0, both
    // curvatures the profile's); the tip is a cone's (no slope: NaN).
    assert_eq!(closed("rings").eval(0.0, 0.0), [0.0; 6]);
    let profile = closed("cyl").eval(0.0, 0.0);
    let dome = closed("dome").eval(0.0, 0.0);
    assert_eq!(dome, [profile[0], 0.0, 0.0, profile[3], 0.0, profile[3]]);
    assert!(profile[3] != 0.0);
    let tip = closed("tip").eval(0.0, 0.0);
    assert!(
        tip[0].is_finite() && tip[1..].iter().all(|v| v.is_nan()),
        "{tip:?}"
    );
}

/// A declaration that did not check (its aperture refused) is refused
/// with what it lacks, as E0121 words it: its parameters are read once,
/// and nothing unwraps them.
#[test]
fn a_surface_that_did_not_check_is_refused_with_what_it_lacks() {
    let src = "surface s = sphere { radius: 5 mm, sense: convex, aperture: circle(diameter: 2 mm, radius: 1 mm) }";
    let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
    assert!(c.has_errors());
    let o = c.checked.declarations.get("s").expect("declared");
    assert_eq!(
        lower_surface(o).err(),
        Some(LowerError::Missing(
            "`sphere` is missing `aperture`".to_string()
        ))
    );
    assert_eq!(crate::domain::surface_domain(o), None);
}

/// `off_axis(…, tilt: remove)` is the level section turned rigidly (about
/// y by atan(s_x), then about x by −atan(s_y / sqrt(1 + s_x²))): every
/// point of it, turned back by the transposed rotation, lies on the level
/// section, and its slope at the centre is zero. At 14° (a paraboloid of
/// R = 48.13 mm sectioned 12 mm off axis) the small-angle shear it
/// replaces, z − s_x x, is tens of µm off it at the section's edge: on
/// main this test fails there.
#[test]
fn tilt_removed_is_the_exact_turned_section() {
    let r = 12.0 / 14f64.to_radians().tan();
    for (x0, y0) in [(12.0, 0.0), (5.0, -7.0)] {
        let src = format!(
            "surface p = conic {{ radius: {r} mm, conic: -1, sense: concave, aperture: circle(radius: 30 mm) }}
surface t = off_axis(p, x: {x0} mm, y: {y0} mm, tilt: remove, aperture: circle(radius: 12 mm))"
        );
        let parent = |x: f64, y: f64| (x * x + y * y) / (2.0 * r);
        let level = |u: f64, v: f64| parent(u + x0, v + y0) - parent(x0, y0);
        let (sx, sy) = (x0 / r, y0 / r);
        let a = sx.atan();
        let b = -(sy / sx.hypot(1.0)).atan();
        // M = Rx(b) · Ry(a), rows; its transpose turns a point back.
        let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
        let m = [
            [ca, 0.0, sa],
            [-sb * -sa, cb, -sb * ca],
            [-cb * sa, sb, cb * ca],
        ];
        let centre = eval_surface(&src, "t", 0.0, 0.0);
        assert!(
            centre[1].abs() < 1e-12 && centre[2].abs() < 1e-12,
            "{centre:?}"
        );
        for (x, y) in [(11.0, 0.0), (-11.0, 2.0), (3.0, -8.0), (0.0, 11.5)] {
            let z = eval_surface(&src, "t", x, y)[0];
            let back = |i: usize| m[0][i] * x + m[1][i] * y + m[2][i] * z;
            let (u, v, w) = (back(0), back(1), back(2));
            assert!(
                (w - level(u, v)).abs() < 1e-11,
                "({x0}, {y0}) at ({x}, {y}): {w} vs {}",
                level(u, v)
            );
            if y0 == 0.0 && x == 11.0 {
                let shear = level(x, y) - sx * x;
                assert!((z - shear).abs() > 10e-3, "{z} vs the shear {shear}");
            }
        }
    }
}
