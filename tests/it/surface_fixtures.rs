//! Sag fixtures for every surface kind (issue #3): each surface is written
//! as `.lens` text, checked and lowered by `lensc_build::driver`, evaluated by both
//! backends (the interpreter and the JIT, which must agree by the runtime's
//! conformance check, `surface::conformance::against_reference`), and
//! compared with values whose source is written beside them:
//!
//! 1. closed forms written out here from the literature, never by calling
//!    lensc code;
//! 2. optiland 0.6.3, an independent optical-design code, through
//!    `tests/fixtures/optiland_sag.py` (its printed values are pasted at the
//!    end of this file: the CI does not run Python);
//! 3. numbers the seed papers publish, with their citation, kept apart from
//!    what is computed from them.
//!
//! Agreement with closed forms and optiland: 1e-12 mm, or 1e-12 relative
//! where a value exceeds 1 (slopes likewise). Paper numbers are held to the
//! digits the paper prints.
//!
//! ## Conventions, lensc ↔ optiland
//!
//! optiland (like Zemax and Code V) measures sag along the light, +z into the
//! glass, with a signed radius (R > 0: centre of curvature at +z). lensc's
//! +z points out of the material towards the tool (docs/language/sign-rule.md):
//!
//! - `convention: optical` with optiland's signed radii and coefficients:
//!   z_lensc(x, y) = −z_optiland(x, y), and both slopes change sign (x and y
//!   are kept as they are).
//! - `sense` with |R|: the same numbers as optiland with R_optiland = s·|R|
//!   and every coefficient times s (s = +1 concave, −1 convex):
//!   z_lensc(x, y) = z_optiland(x, y).
//! - Powers: optiland's `EvenAsphere.coefficients[i]` is lensc's `A{2i+2}`,
//!   `OddAsphere.coefficients[i]` is `A{i+1}`, `ToroidalGeometry.coeffs_poly_y[i]`
//!   is the toroid's `A{2i+2}`, `PolynomialGeometry.coefficients[i][j]` is
//!   `X{i}Y{j}`; each carries the unit mm^(1−power).
//! - Zernike: optiland's `norm_radius` is lensc's `norm_radius`; `"fringe"`
//!   numbers from 1 like lensc's `ordering: fringe` and is unnormalised;
//!   `"standard"` numbers from 0 (ANSI Z80.28 / OSA) with the normalisation
//!   sqrt(2(n+1)/(1+δ_m0)), like lensc's `ordering: ansi`. Past Z36 the two
//!   fringe schemes part: optiland extends the index formula
//!   j = (1 + (n+|m|)/2)² − 2|m| + (1 − sgn m)/2, so its Z37 is (n, m) =
//!   (6, 6); lensc's Z37 is the 37-term set's 12th-order spherical (12, 0)
//!   (Zemax, Code V), checked here against its polynomial instead.
//! - Forbes: optiland's `ForbesQNormalSlopeGeometry` with `conic = 0` is
//!   Forbes 2007's Q-bfs (its conic factor sqrt((1 − kc²ρ²)/(1 − (1+k)c²ρ²))
//!   is then 1/sqrt(1 − c²ρ²)); `norm_radius` is ρ_max. optiland 0.6.3 has
//!   no Q-con: lensc's `qcon` is checked against Forbes's closed forms and
//!   the Jacobi polynomials.
//! - Biconic: optiland's `BiconicGeometry` is a different surface from
//!   lensc's (which is Zemax's): optiland adds two conic sections,
//!   z = c_x x²/(1 + sqrt(1 − (1+k_x)c_x²x²)) + c_y y²/(1 + sqrt(1 − (1+k_y)c_y²y²)),
//!   Zemax has one square root, (c_x x² + c_y y²)/(1 + sqrt(1 − (1+k_x)c_x²x²
//!   − (1+k_y)c_y²y²)). They agree on the x and y axes, where lensc is
//!   compared with optiland; elsewhere lensc is compared with Zemax's formula
//!   and optiland's values with the sum of sections.
//! - Toroid: both sweep a y–z profile about an axis parallel to y (Zemax's
//!   "Toroidal" surface), z = R − sgn(R) sqrt((R − z_y)² − x²). optiland
//!   signs the rotation radius on its own; lensc's `rotation_radius` is a
//!   magnitude on the profile's side (no saddle toroids).

use lensc_build::driver;
use lensc_lang::loader::RealFs;
use lensc_runtime::surface::conformance::against_reference;
use lensc_runtime::surface::ir::Interpreter;
use lensc_runtime::surface::jit::JitSurface;

/// Agreement with a reference: 1e-12 (mm, or dimensionless slope), relative
/// above 1.
const TOL: f64 = 1e-12;

/// A declared surface, lowered, with both backends.
struct Surface {
    label: String,
    interp: Interpreter,
    jit: JitSurface,
}

/// Checks `src`, lowers its surface `name` and compiles it.
fn surface(src: &str, name: &str) -> Surface {
    let c = driver::check_text(&RealFs, "fixture.lens", src.as_bytes());
    assert!(!c.has_errors(), "{src}\n{:?}", c.diags());
    let l = driver::declared_surface(&c, name).unwrap_or_else(|e| panic!("{e}\n{src}"));
    let jit = JitSurface::compile(&l.tape).unwrap_or_else(|e| panic!("{name}: {e}"));
    Surface {
        label: format!("`{name}` of\n{src}\n"),
        interp: Interpreter::new(&l.tape),
        jit,
    }
}

impl Surface {
    /// The six outputs (z, z_x, z_y, z_xx, z_xy, z_yy) at each point, from
    /// the interpreter, after checking the JIT gives the same.
    fn at(&self, pts: &[(f64, f64)]) -> Vec<[f64; 6]> {
        let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let a = against_reference(&self.interp, &self.jit, &xs, &ys)
            .unwrap_or_else(|e| panic!("{}: {e}", self.label));
        for (k, u) in a.iter().enumerate() {
            assert!(
                u.is_finite(),
                "{}: output {} at {:?}: {u:e}",
                self.label,
                k % 6,
                pts[k / 6]
            );
        }
        a.chunks(6)
            .map(|c| c.try_into().expect("six outputs"))
            .collect()
    }

    /// z, z_x and z_y at each point against `want(x, y)` = (z, z_x, z_y);
    /// a `None` slope is not compared.
    fn expect(&self, pts: &[(f64, f64)], want: impl Fn(f64, f64) -> Want, source: &str) {
        for (o, &(x, y)) in self.at(pts).iter().zip(pts) {
            let w = want(x, y);
            expect(&self.label, source, "z", (x, y), o[0], w.z);
            if let Some(zx) = w.zx {
                expect(&self.label, source, "dz/dx", (x, y), o[1], zx);
            }
            if let Some(zy) = w.zy {
                expect(&self.label, source, "dz/dy", (x, y), o[2], zy);
            }
        }
    }
}

/// A reference value: the height and, where the source gives them, slopes.
struct Want {
    z: f64,
    zx: Option<f64>,
    zy: Option<f64>,
}

fn z_only(z: f64) -> Want {
    Want {
        z,
        zx: None,
        zy: None,
    }
}

fn z_slopes(z: f64, zx: f64, zy: f64) -> Want {
    Want {
        z,
        zx: Some(zx),
        zy: Some(zy),
    }
}

fn expect(label: &str, source: &str, what: &str, at: (f64, f64), got: f64, want: f64) {
    assert!(
        (got - want).abs() <= TOL * want.abs().max(1.0),
        "{label}{what} at {at:?}: lensc {got:.17e}, {source} {want:.17e} (differ by {:e})",
        (got - want).abs()
    );
}

// ---------------------------------------------------------------------------
// Closed forms, from the literature.
// ---------------------------------------------------------------------------

/// The conic section's sag at r² = s: c s / (1 + sqrt(1 − (1+k) c² s)),
/// c = 1/R (ISO 10110-12's aspheric equation without its polynomial; the
/// "standard" surface of Zemax OpticStudio and Code V).
fn conic_sag(c: f64, k: f64, s: f64) -> f64 {
    c * s / (1.0 + (1.0 - (1.0 + k) * c * c * s).sqrt())
}

/// Its derivative along the radius: c r / sqrt(1 − (1+k) c² r²).
fn conic_slope(c: f64, k: f64, r: f64) -> f64 {
    c * r / (1.0 - (1.0 + k) * c * c * r * r).sqrt()
}

/// The rotationally symmetric asphere of ISO 10110-12 and Kim 2008 eq. 1,
/// z = conic + Σ A_j |r|^j, with slopes (x, y) · z'(r)/r; `sign` multiplies all.
fn asphere(sign: f64, c: f64, k: f64, terms: &[(i32, f64)], x: f64, y: f64) -> Want {
    let r = x.hypot(y);
    let z = conic_sag(c, k, r * r) + terms.iter().map(|&(j, a)| a * r.powi(j)).sum::<f64>();
    let dr = conic_slope(c, k, r)
        + terms
            .iter()
            .map(|&(j, a)| f64::from(j) * a * r.powi(j - 1))
            .sum::<f64>();
    // at the vertex the slope is 0 (without an A1 cone)
    let (ux, uy) = if r == 0.0 { (0.0, 0.0) } else { (x / r, y / r) };
    z_slopes(sign * z, sign * dr * ux, sign * dr * uy)
}

/// Points inside a 1.5 mm aperture, off the axes, in every quadrant.
const P15: [(f64, f64); 6] = [
    (0.3, 0.4),
    (-0.7, 0.55),
    (1.05, -0.62),
    (-0.21, -1.33),
    (1.2, 0.8),
    (-0.9, -0.9),
];

#[test]
fn plane_is_flat() {
    let s = surface(
        "surface p = plane { aperture: rect(x: -2 mm .. 2 mm, y: -1 mm .. 3 mm) }",
        "p",
    );
    s.expect(&P15, |_, _| z_slopes(0.0, 0.0, 0.0), "z = 0");
}

#[test]
fn sphere_and_conic_are_the_conic_sections() {
    // The sphere in its school form R − sqrt(R² − r²) (a different algebra
    // from the sag equation lensc lowers), signed by the sense.
    for (sense, s) in [("concave", 1.0), ("convex", -1.0)] {
        let src = format!(
            "surface s = sphere {{ radius: 8.5 mm, sense: {sense}, aperture: circle(radius: 1.5 mm) }}"
        );
        surface(&src, "s").expect(
            &P15,
            |x, y| {
                let d = (8.5f64 * 8.5 - x * x - y * y).sqrt();
                z_slopes(s * (8.5 - d), s * x / d, s * y / d)
            },
            "sphere R − sqrt(R² − r²)",
        );
    }
    // A paraboloid (k = −1) is r²/(2R) exactly.
    surface(
        "surface p = conic { radius: 20 mm, conic: -1, sense: concave, aperture: circle(radius: 1.5 mm) }",
        "p",
    )
    .expect(
        &P15,
        |x, y| z_slopes((x * x + y * y) / 40.0, x / 20.0, y / 20.0),
        "paraboloid r²/(2R)",
    );
    // Every conic satisfies its section's equation r² − 2Rz + (1+k)z² = 0
    // (the conic section about its vertex): z = (R − sqrt(R² − (1+k) r²))/(1+k)
    // for k ≠ −1 (the nearer root), a hyperboloid, an oblate and a prolate
    // ellipsoid.
    for k in [-2.5f64, 0.6, -0.4, 43.098] {
        let src = format!(
            "surface c = conic {{ radius: 22.405 mm, conic: {k}, sense: concave, aperture: circle(radius: 1.5 mm) }}"
        );
        surface(&src, "c").expect(
            &P15,
            |x, y| {
                let (r2, big_r) = (x * x + y * y, 22.405f64);
                let z = (big_r - (big_r * big_r - (1.0 + k) * r2).sqrt()) / (1.0 + k);
                // implicit differentiation: dz/dx = x / (R − (1+k) z)
                let den = big_r - (1.0 + k) * z;
                z_slopes(z, x / den, y / den)
            },
            "root of r² − 2Rz + (1+k)z² = 0",
        );
    }
}

#[test]
fn asphere_even_and_odd_terms() {
    // Even and odd powers together, as Kim 2008 eq. 1 writes them
    // (Σ A_j |x|^j from j = 1), convex and concave.
    let terms = [
        (1, 2e-4),
        (2, 3e-3),
        (3, -4e-4),
        (4, 1.5e-3),
        (5, -2e-5),
        (6, 3e-6),
        (8, -4e-7),
        (10, 2e-8),
    ];
    let coeffs = "A1: 2e-4, A2: 3e-3 mm^-1, A3: -4e-4 mm^-2, A4: 1.5e-3 mm^-3, A5: -2e-5 mm^-4, A6: 3e-6 mm^-5, A8: -4e-7 mm^-7, A10: 2e-8 mm^-9";
    for (sense, s) in [("convex", -1.0), ("concave", 1.0)] {
        let src = format!(
            "surface a = asphere {{ radius: 4.254 mm, conic: -3.359, sense: {sense}, aperture: circle(radius: 1.5 mm), {coeffs} }}"
        );
        surface(&src, "a").expect(
            &P15,
            |x, y| asphere(s, 1.0 / 4.254, -3.359, &terms, x, y),
            "conic + Σ A_j |r|^j (Kim 2008 eq. 1)",
        );
    }
    // The optical convention: the designer's signed R and coefficients,
    // the whole sag negated (docs/language/sign-rule.md).
    let src = format!(
        "surface a = asphere {{ radius: -4.254 mm, conic: -3.359, convention: optical, aperture: circle(radius: 1.5 mm), {coeffs} }}"
    );
    surface(&src, "a").expect(
        &P15,
        |x, y| asphere(-1.0, -1.0 / 4.254, -3.359, &terms, x, y),
        "−(designer's sag)",
    );
}

#[test]
fn cylinder_and_acylinder_are_extruded_profiles() {
    // A circle across the axis: R − sqrt(R² − u²), u the coordinate across.
    for (axis, across_x) in [("y", true), ("x", false)] {
        let src = format!(
            "surface c = cylinder {{ radius: 6 mm, axis: {axis}, sense: convex, aperture: circle(radius: 1.5 mm) }}"
        );
        surface(&src, "c").expect(
            &P15,
            |x, y| {
                let u = if across_x { x } else { y };
                let d = (36.0 - u * u).sqrt();
                let slope = -u / d;
                if across_x {
                    z_slopes(-(6.0 - d), slope, 0.0)
                } else {
                    z_slopes(-(6.0 - d), 0.0, slope)
                }
            },
            "circle R − sqrt(R² − u²)",
        );
    }
    // An aspheric profile across x (extruded along y), odd and even terms.
    let terms = [(3, 5e-4), (4, -2e-3), (6, 1e-4)];
    surface(
        "surface c = acylinder { radius: 3 mm, conic: -0.7, axis: y, sense: concave, aperture: circle(radius: 1.5 mm), A3: 5e-4 mm^-2, A4: -2e-3 mm^-3, A6: 1e-4 mm^-5 }",
        "c",
    )
    .expect(
        &P15,
        |x, _| {
            let u = x.abs();
            let w = asphere(1.0, 1.0 / 3.0, -0.7, &terms, u, 0.0);
            z_slopes(w.z, w.zx.expect("slope") * x.signum(), 0.0)
        },
        "conic + Σ A_j |u|^j across the axis",
    );
}

/// Zemax's biconic (OpticStudio manual, "Biconic"): one square root.
fn zemax_biconic(cx: f64, cy: f64, kx: f64, ky: f64, x: f64, y: f64) -> Want {
    let q = 1.0 - (1.0 + kx) * cx * cx * x * x - (1.0 + ky) * cy * cy * y * y;
    let root = q.sqrt();
    let num = cx * x * x + cy * y * y;
    let den = 1.0 + root;
    let z = num / den;
    // d/dx: (2 cx x · den − num · d(root)/dx) / den², d(root)/dx = −(1+kx) cx² x / root
    let droot_x = -(1.0 + kx) * cx * cx * x / root;
    let droot_y = -(1.0 + ky) * cy * cy * y / root;
    let zx = (2.0 * cx * x * den - num * droot_x) / (den * den);
    let zy = (2.0 * cy * y * den - num * droot_y) / (den * den);
    z_slopes(z, zx, zy)
}

#[test]
fn biconic_is_zemaxs() {
    surface(
        "surface b = biconic { radius_x: 6 mm, radius_y: 9 mm, conic_x: -0.5, conic_y: 1.2, sense: concave, aperture: circle(radius: 1.5 mm) }",
        "b",
    )
    .expect(
        &P15,
        |x, y| zemax_biconic(1.0 / 6.0, 1.0 / 9.0, -0.5, 1.2, x, y),
        "Zemax biconic",
    );
    // A saddle, in the optical convention (signed radii), negated.
    surface(
        "surface b = biconic { radius_x: 6 mm, radius_y: -9 mm, conic_x: -0.5, conic_y: 1.2, convention: optical, aperture: circle(radius: 1.5 mm) }",
        "b",
    )
    .expect(
        &P15,
        |x, y| {
            let w = zemax_biconic(1.0 / 6.0, -1.0 / 9.0, -0.5, 1.2, x, y);
            z_slopes(-w.z, -w.zx.expect("zx"), -w.zy.expect("zy"))
        },
        "−(Zemax biconic)",
    );
}

/// Zemax's toroid: the y–z profile z_y (conic + Σ A_j |y|^j) swept about an
/// axis parallel to y at R: z = R − sgn(R) sqrt((R − z_y)² − x²).
fn toroid(rr: f64, c: f64, k: f64, terms: &[(i32, f64)], x: f64, y: f64) -> Want {
    let p = asphere(1.0, c, k, terms, y.abs(), 0.0);
    let (zy, dzy) = (p.z, p.zx.expect("slope") * y.signum());
    let d = ((rr - zy).powi(2) - x * x).sqrt();
    let z = rr - rr.signum() * d;
    z_slopes(z, rr.signum() * x / d, rr.signum() * (rr - zy) * dzy / d)
}

#[test]
fn toroid_is_a_swept_profile() {
    let terms = [(4, 4e-4), (6, -1e-5)];
    surface(
        "surface t = toroid { radius: 5 mm, conic: -0.6, rotation_radius: 15 mm, sense: concave, aperture: circle(radius: 1.5 mm), A4: 4e-4 mm^-3, A6: -1e-5 mm^-5 }",
        "t",
    )
    .expect(
        &P15,
        |x, y| toroid(15.0, 0.2, -0.6, &terms, x, y),
        "Zemax toroid",
    );
    // Every point lies on the circle of radius R − z_y(y) about the axis:
    // x² + (z − R)² = (R − z_y)², for a convex one too.
    let t = surface(
        "surface t = toroid { radius: 7.5 mm, rotation_radius: 4 mm, sense: convex, aperture: circle(radius: 1.5 mm) }",
        "t",
    );
    for (o, &(x, y)) in t.at(&P15).iter().zip(&P15) {
        // convex: the mirror image of the concave toroid below z = 0
        let z = -o[0];
        let zy = conic_sag(1.0 / 7.5, 0.0, y * y);
        let lhs = x * x + (z - 4.0).powi(2);
        expect(
            &t.label,
            "x² + (z − R)² = (R − z_y)²",
            "z",
            (x, y),
            lhs,
            (4.0 - zy).powi(2),
        );
    }
}

#[test]
fn ellipsoid_cap() {
    // The ellipsoid x²/a² + y²/b² + (z − c)²/c² = 1 through the vertex:
    // z = c (1 − sqrt(1 − x²/a² − y²/b²)) (Liu et al., seed 002, eq. 11, the
    // microlens, moved to its vertex); convex is its mirror image.
    for (sense, s) in [("concave", 1.0), ("convex", -1.0)] {
        let src = format!(
            "surface e = ellipsoid {{ a: 2.5 mm, b: 1.8 mm, c: 3.2 mm, sense: {sense}, aperture: circle(radius: 1.5 mm) }}"
        );
        surface(&src, "e").expect(
            &P15,
            |x, y| {
                let (a, b, c) = (2.5f64, 1.8f64, 3.2f64);
                let q = (1.0 - x * x / (a * a) - y * y / (b * b)).sqrt();
                z_slopes(
                    s * c * (1.0 - q),
                    s * c * x / (a * a * q),
                    s * c * y / (b * b * q),
                )
            },
            "ellipsoid cap",
        );
    }
}

#[test]
fn xy_polynomial_on_a_conic_and_on_a_plane() {
    // Σ C_ij x^i y^j (Zemax "Extended polynomial" / optiland "Polynomial XY").
    let terms = [
        (1, 0, 1e-3),
        (0, 2, 3e-3),
        (2, 0, -2e-3),
        (1, 1, 1.5e-3),
        (2, 1, 4e-4),
        (0, 3, -2e-4),
        (3, 1, 5e-5),
        (1, 3, -3e-5),
        (5, 2, 1e-6),
    ];
    let poly = |x: f64, y: f64| {
        let mut p = (0.0, 0.0, 0.0);
        for &(i, j, a) in &terms {
            let (xi, yj) = (x.powi(i), y.powi(j));
            p.0 += a * xi * yj;
            if i > 0 {
                p.1 += a * f64::from(i) * x.powi(i - 1) * yj;
            }
            if j > 0 {
                p.2 += a * f64::from(j) * xi * y.powi(j - 1);
            }
        }
        p
    };
    let coeffs = "X1Y0: 1e-3, X0Y2: 3e-3 mm^-1, X2Y0: -2e-3 mm^-1, X1Y1: 1.5e-3 mm^-1, X2Y1: 4e-4 mm^-2, X0Y3: -2e-4 mm^-2, X3Y1: 5e-5 mm^-3, X1Y3: -3e-5 mm^-3, X5Y2: 1e-6 mm^-6";
    let src = format!(
        "surface p = xy_polynomial {{ radius: 20 mm, conic: -1, sense: convex, aperture: circle(radius: 1.5 mm), {coeffs} }}"
    );
    surface(&src, "p").expect(
        &P15,
        |x, y| {
            let p = poly(x, y);
            z_slopes(
                -((x * x + y * y) / 40.0 + p.0),
                -(x / 20.0 + p.1),
                -(y / 20.0 + p.2),
            )
        },
        "−(r²/(2R) + Σ C_ij x^i y^j)",
    );
    let src = format!(
        "surface p = xy_polynomial {{ sense: concave, aperture: circle(radius: 1.5 mm), {coeffs} }}"
    );
    surface(&src, "p").expect(
        &P15,
        |x, y| {
            let p = poly(x, y);
            z_slopes(p.0, p.1, p.2)
        },
        "Σ C_ij x^i y^j",
    );
}

/// The 37-term fringe (University of Arizona) Zernike set, as tabulated by
/// Wyant & Creath, "Basic wavefront aberration theory for optical
/// metrology" (Applied Optics and Optical Engineering XI, 1992), and the
/// Zemax OpticStudio manual ("Fringe Zernike Sag"): (radial polynomial in
/// ρ, m), m > 0 cos mθ, m < 0 sin |m|θ.
fn fringe_table(j: usize, rho: f64) -> (f64, i32) {
    let p = |c: &[f64]| c.iter().fold(0.0, |acc, &a| acc * rho + a);
    let r = rho;
    match j {
        1 => (1.0, 0),
        2 => (r, 1),
        3 => (r, -1),
        4 => (2.0 * r * r - 1.0, 0),
        5 => (r * r, 2),
        6 => (r * r, -2),
        7 => (p(&[3.0, 0.0, -2.0, 0.0]), 1),
        8 => (p(&[3.0, 0.0, -2.0, 0.0]), -1),
        9 => (p(&[6.0, 0.0, -6.0, 0.0, 1.0]), 0),
        10 => (r.powi(3), 3),
        11 => (r.powi(3), -3),
        12 => (p(&[4.0, 0.0, -3.0, 0.0, 0.0]), 2),
        13 => (p(&[4.0, 0.0, -3.0, 0.0, 0.0]), -2),
        14 => (p(&[10.0, 0.0, -12.0, 0.0, 3.0, 0.0]), 1),
        15 => (p(&[10.0, 0.0, -12.0, 0.0, 3.0, 0.0]), -1),
        16 => (p(&[20.0, 0.0, -30.0, 0.0, 12.0, 0.0, -1.0]), 0),
        17 => (r.powi(4), 4),
        18 => (r.powi(4), -4),
        19 => (p(&[5.0, 0.0, -4.0, 0.0, 0.0, 0.0]), 3),
        20 => (p(&[5.0, 0.0, -4.0, 0.0, 0.0, 0.0]), -3),
        21 => (p(&[15.0, 0.0, -20.0, 0.0, 6.0, 0.0, 0.0]), 2),
        22 => (p(&[15.0, 0.0, -20.0, 0.0, 6.0, 0.0, 0.0]), -2),
        23 => (p(&[35.0, 0.0, -60.0, 0.0, 30.0, 0.0, -4.0, 0.0]), 1),
        24 => (p(&[35.0, 0.0, -60.0, 0.0, 30.0, 0.0, -4.0, 0.0]), -1),
        25 => (p(&[70.0, 0.0, -140.0, 0.0, 90.0, 0.0, -20.0, 0.0, 1.0]), 0),
        26 => (r.powi(5), 5),
        27 => (r.powi(5), -5),
        28 => (p(&[6.0, 0.0, -5.0, 0.0, 0.0, 0.0, 0.0]), 4),
        29 => (p(&[6.0, 0.0, -5.0, 0.0, 0.0, 0.0, 0.0]), -4),
        30 => (p(&[21.0, 0.0, -30.0, 0.0, 10.0, 0.0, 0.0, 0.0]), 3),
        31 => (p(&[21.0, 0.0, -30.0, 0.0, 10.0, 0.0, 0.0, 0.0]), -3),
        32 => (p(&[56.0, 0.0, -105.0, 0.0, 60.0, 0.0, -10.0, 0.0, 0.0]), 2),
        33 => (p(&[56.0, 0.0, -105.0, 0.0, 60.0, 0.0, -10.0, 0.0, 0.0]), -2),
        34 => (
            p(&[126.0, 0.0, -280.0, 0.0, 210.0, 0.0, -60.0, 0.0, 5.0, 0.0]),
            1,
        ),
        35 => (
            p(&[126.0, 0.0, -280.0, 0.0, 210.0, 0.0, -60.0, 0.0, 5.0, 0.0]),
            -1,
        ),
        36 => (
            p(&[
                252.0, 0.0, -630.0, 0.0, 560.0, 0.0, -210.0, 0.0, 30.0, 0.0, -1.0,
            ]),
            0,
        ),
        37 => (
            p(&[
                924.0, 0.0, -2772.0, 0.0, 3150.0, 0.0, -1680.0, 0.0, 420.0, 0.0, -42.0, 0.0, 1.0,
            ]),
            0,
        ),
        _ => panic!("fringe Z{j} is not in the 37-term set"),
    }
}

fn angular(m: i32, th: f64) -> f64 {
    if m < 0 {
        (f64::from(-m) * th).sin()
    } else {
        (f64::from(m) * th).cos()
    }
}

/// Points inside a 2 mm aperture.
const P2: [(f64, f64); 6] = [
    (0.5, -0.25),
    (-1.1, 0.9),
    (1.3, 1.2),
    (-0.35, -1.7),
    (0.05, 1.95),
    (-1.6, -0.4),
];

/// A fixed, irregular coefficient for term j (mm).
fn coefficient(j: usize) -> f64 {
    let j = j as f64;
    (if (j as i64) % 3 == 0 { -1.0 } else { 1.0 }) * (0.4 + 0.037 * j) * 1e-3 / (1.0 + j / 7.0)
}

#[test]
fn zernike_fringe_follows_the_37_term_table() {
    let coeffs: Vec<String> = (1..=37)
        .map(|j| format!("Z{j}: {} mm", coefficient(j)))
        .collect();
    let src = format!(
        "surface w = zernike {{ radius: 30 mm, conic: -0.4, sense: concave, norm_radius: 2.2 mm, ordering: fringe, aperture: circle(radius: 2 mm), {} }}",
        coeffs.join(", ")
    );
    surface(&src, "w").expect(
        &P2,
        |x, y| {
            let (rho, th) = (x.hypot(y) / 2.2, y.atan2(x));
            let sum: f64 = (1..=37)
                .map(|j| {
                    let (radial, m) = fringe_table(j, rho);
                    coefficient(j) * radial * angular(m, th)
                })
                .sum();
            z_only(conic_sag(1.0 / 30.0, -0.4, x * x + y * y) + sum)
        },
        "conic + Σ c_j Z_j (fringe table)",
    );
    // Each term alone, so a term in the wrong place cannot hide in the sum.
    for j in 1..=37 {
        let src = format!(
            "surface w = zernike {{ sense: concave, norm_radius: 2.2 mm, ordering: fringe, aperture: circle(radius: 2 mm), Z{j}: 1 mm }}"
        );
        surface(&src, "w").expect(
            &P2,
            |x, y| {
                let (radial, m) = fringe_table(j, x.hypot(y) / 2.2);
                z_only(radial * angular(m, y.atan2(x)))
            },
            &format!("fringe Z{j}"),
        );
    }
}

#[test]
fn zernike_ansi_is_normalised_and_numbered_from_zero() {
    // ANSI Z80.28-2017 (and Thibos et al., J. Refract. Surg. 18, 2002):
    // j = (n(n+2) + m)/2, Z_j = N R_n^|m|(ρ) {cos mθ, sin |m|θ}, N =
    // sqrt(2(n+1)/(1+δ_m0)); the radial polynomials taken from the fringe
    // table above (its (n, |m|) cover n ≤ 5).
    // (n, |m|) → the fringe term with that radial polynomial.
    let fringe_of = |n: i32, m: i32| match (n, m.abs()) {
        (0, 0) => 1,
        (1, 1) => 2,
        (2, 0) => 4,
        (2, 2) => 5,
        (3, 1) => 7,
        (4, 0) => 9,
        (3, 3) => 10,
        (4, 2) => 12,
        (5, 1) => 14,
        (4, 4) => 17,
        (5, 3) => 19,
        (5, 5) => 26,
        other => panic!("{other:?} not tabulated here"),
    };
    let radial = |n: i32, m: i32, rho: f64| fringe_table(fringe_of(n, m), rho).0;
    let mut terms = Vec::new();
    for n in 0..=5 {
        for m in (-n..=n).step_by(2) {
            terms.push(((n * (n + 2) + m) / 2, n, m));
        }
    }
    for &(j, n, m) in &terms {
        let src = format!(
            "surface w = zernike {{ sense: concave, norm_radius: 2.2 mm, ordering: ansi, aperture: circle(radius: 2 mm), Z{j}: 1 mm }}"
        );
        surface(&src, "w").expect(
            &P2,
            |x, y| {
                let norm = (2.0 * f64::from(n + 1) / if m == 0 { 2.0 } else { 1.0 }).sqrt();
                z_only(norm * radial(n, m, x.hypot(y) / 2.2) * angular(m, y.atan2(x)))
            },
            &format!("ANSI Z{j} = (n {n}, m {m})"),
        );
    }
}

/// Forbes 2007 ("Shape specification for axially symmetric optical
/// surfaces", Opt. Express 15, 5218): his Q_0 … Q_3 of Q-bfs in x = u².
fn forbes_qbfs(m: usize, x: f64) -> f64 {
    match m {
        0 => 1.0,
        1 => (13.0 - 16.0 * x) / 19f64.sqrt(),
        2 => (2.0f64 / 95.0).sqrt() * (29.0 - 4.0 * x * (25.0 - 19.0 * x)),
        3 => (2.0f64 / 2545.0).sqrt() * (207.0 - 4.0 * x * (315.0 - x * (577.0 - 320.0 * x))),
        _ => panic!("Q{m}"),
    }
}

#[test]
fn qbfs_is_forbes_2007() {
    let a = [2e-3, -1e-3, 5e-4, 2.5e-4];
    let src = "surface q = qbfs { radius: 25 mm, sense: convex, norm_radius: 4 mm, aperture: circle(radius: 4 mm), Q0: 2e-3 mm, Q1: -1e-3 mm, Q2: 5e-4 mm, Q3: 2.5e-4 mm }";
    let pts = [
        (1.3, -2.1),
        (0.2, 0.3),
        (-2.5, 1.9),
        (3.1, 2.2),
        (-0.9, -3.6),
        (4.0, 0.0),
    ];
    surface(src, "q").expect(
        &pts,
        |x, y| {
            let s = x * x + y * y;
            let (c, u2) = (1.0 / 25.0, s / 16.0);
            let sum: f64 = (0..4).map(|m| a[m] * forbes_qbfs(m, u2)).sum();
            z_only(-(conic_sag(c, 0.0, s) + u2 * (1.0 - u2) / (1.0 - c * c * s).sqrt() * sum))
        },
        "−(sphere + u²(1−u²)/sqrt(1−c²ρ²) Σ a_m Q_m) (Forbes 2007)",
    );
}

/// The Jacobi polynomial P_n^(α,β)(t) from its explicit sum (Abramowitz &
/// Stegun 22.3; DLMF §18.5):
/// Σ_s C(n+α, n−s) C(n+β, s) ((t−1)/2)^s ((t+1)/2)^(n−s).
fn jacobi(n: usize, alpha: usize, beta: usize, t: f64) -> f64 {
    let binom = |a: usize, b: usize| -> f64 {
        (0..b).fold(1.0, |acc, i| acc * (a - i) as f64 / (i + 1) as f64)
    };
    (0..=n)
        .map(|s| {
            binom(n + alpha, n - s)
                * binom(n + beta, s)
                * ((t - 1.0) / 2.0).powi(s as i32)
                * ((t + 1.0) / 2.0).powi((n - s) as i32)
        })
        .sum()
}

#[test]
fn qcon_is_the_conic_plus_jacobi_polynomials() {
    // Forbes 2007: z = conic + u⁴ Σ a_m Q_m^con(u²), with
    // Q_m^con(x) = P_m^(0,4)(2x − 1); his closed forms
    // Q_0 = 1, Q_1 = −(5 − 6x), Q_2 = 15 − 14x(3 − 2x),
    // Q_3 = −(35 − 12x(14 − x(21 − 10x))) hold for the sum above.
    for x in [0.0, 0.13, 0.5, 0.77, 1.0] {
        let t = 2.0 * x - 1.0;
        let closed = [
            1.0,
            -(5.0 - 6.0 * x),
            15.0 - 14.0 * x * (3.0 - 2.0 * x),
            -(35.0 - 12.0 * x * (14.0 - x * (21.0 - 10.0 * x))),
        ];
        for (m, q) in closed.iter().enumerate() {
            assert!((jacobi(m, 0, 4, t) - q).abs() < 1e-12, "Q{m}({x})");
        }
    }
    let a: Vec<f64> = (0..=8).map(|m| coefficient(m + 3)).collect();
    let coeffs: Vec<String> = a
        .iter()
        .enumerate()
        .map(|(m, v)| format!("Q{m}: {v} mm"))
        .collect();
    let src = format!(
        "surface q = qcon {{ radius: 12 mm, conic: -0.8, convention: optical, norm_radius: 3 mm, aperture: circle(radius: 3 mm), {} }}",
        coeffs.join(", ")
    );
    let pts = [
        (0.9, -2.2),
        (0.1, 0.2),
        (-1.7, 1.6),
        (2.5, 1.3),
        (-0.4, -2.95),
        (3.0, 0.0),
    ];
    surface(&src, "q").expect(
        &pts,
        |x, y| {
            let (s, c, k) = (x * x + y * y, 1.0 / 12.0, -0.8);
            let u2 = s / 9.0;
            let t = 2.0 * u2 - 1.0;
            let sum: f64 = a
                .iter()
                .enumerate()
                .map(|(m, am)| am * jacobi(m, 0, 4, t))
                .sum();
            // d/dt P_m^(0,4)(t) = (m + 5)/2 · P_{m−1}^(1,5)(t) (DLMF §18.9)
            let dsum: f64 = a
                .iter()
                .enumerate()
                .skip(1)
                .map(|(m, am)| am * (m as f64 + 5.0) / 2.0 * jacobi(m - 1, 1, 5, t))
                .sum();
            let z = conic_sag(c, k, s) + u2 * u2 * sum;
            // dz/dρ = conic′ + (2ρ/ρ_max²)(2u² S + u⁴ · 2 dS/dt)
            let r = s.sqrt();
            let dr = conic_slope(c, k, r) + 2.0 * r / 9.0 * (2.0 * u2 * sum + u2 * u2 * 2.0 * dsum);
            // the optical convention: the designer's sag, negated
            z_slopes(-z, -dr * x / r, -dr * y / r)
        },
        "−(conic + u⁴ Σ a_m P_m^(0,4)(2u² − 1))",
    );
}

#[test]
fn freeform_is_its_formula() {
    // DESIGN.md's roller pattern: 0.02 mm (sin 5x + cos 10y/3) − 0.04 mm.
    surface(
        "surface f = freeform { z(x, y) = 0.02 mm * (sin(5 rad/mm * x) + cos(10 rad/(3 mm) * y)) - 0.04 mm, domain: rect(x: 0 mm .. 6.283 mm, y: 0 mm .. 18.85 mm) }",
        "f",
    )
    .expect(
        &[(0.3, 0.4), (2.2, 9.1), (6.1, 18.0), (4.4, 3.3)],
        |x, y| {
            z_slopes(
                0.02 * ((5.0 * x).sin() + (10.0 * y / 3.0).cos()) - 0.04,
                0.1 * (5.0 * x).cos(),
                -0.02 * 10.0 / 3.0 * (10.0 * y / 3.0).sin(),
            )
        },
        "the formula",
    );
}

// ---------------------------------------------------------------------------
// Arrays, sections and tilts: the lookups and rotations written out here.
// ---------------------------------------------------------------------------

/// An array written out lenslet by lenslet: at each point, the lowest of the
/// lenslets whose aperture holds it, each less its rim height (its height at
/// the aperture's edge along +x), or the land (0) where none does
/// (docs/language/surfaces.md). Returns z and the slopes of the lenslet that wins.
fn array_by_hand(
    centres: &[(f64, f64)],
    lenslet: impl Fn(f64, f64) -> Want,
    inside: impl Fn(f64, f64) -> bool,
    rim: (f64, f64),
    x: f64,
    y: f64,
) -> Want {
    let rim_z = lenslet(rim.0, rim.1).z;
    let mut best = z_slopes(0.0, 0.0, 0.0);
    let mut found = false;
    for &(cx, cy) in centres {
        let (u, v) = (x - cx, y - cy);
        if !inside(u, v) {
            continue;
        }
        let w = lenslet(u, v);
        let z = w.z - rim_z;
        if !found || z < best.z {
            best = Want { z, ..w };
            found = true;
        }
    }
    best
}

#[test]
fn grid_lenslets_clipped_to_their_apertures() {
    // 3 × 2 concave spheres, pitch 1.0 × 1.2 mm, aperture radius 0.4 mm:
    // centres at x ∈ {−1, 0, 1}, y ∈ {−0.6, 0.6}.
    let src =
        "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.4 mm) }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1.2 mm, count_x: 3, count_y: 2)";
    let centres: Vec<(f64, f64)> = [-1.0, 0.0, 1.0]
        .iter()
        .flat_map(|&x| [(x, -0.6), (x, 0.6)])
        .collect();
    let sphere = |u: f64, v: f64| {
        let d = (4.0 - u * u - v * v).sqrt();
        z_slopes(2.0 - d, u / d, v / d)
    };
    let pts = [
        (-1.0, -0.6),
        (-0.83, 0.71),
        (0.12, -0.35),
        (0.95, 0.9),
        (1.3, -0.55),
        (0.5, 0.0),
        (-0.5, 0.61),
        (1.45, 0.6),
        (0.2, 0.05),
    ];
    surface(src, "a").expect(
        &pts,
        |x, y| array_by_hand(&centres, sphere, |u, v| u.hypot(v) < 0.4, (0.4, 0.0), x, y),
        "lenslet by lenslet",
    );
}

#[test]
fn hex_grid_rows_shift_by_half_a_pitch() {
    // Rows along x, every other row shifted half a pitch, centred on the
    // origin (docs/language/surfaces.md): row spacing p·√3/2, row j's centres at
    // (i − (n_x − 1)/2) p ∓ p/4 (even rows −, odd rows +).
    let src = "surface l = conic { radius: 3 mm, conic: -0.5, sense: convex, aperture: circle(radius: 0.45 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 4, count_y: 3)";
    let row = 3f64.sqrt() / 2.0;
    let mut centres = Vec::new();
    for j in 0..3 {
        for i in 0..4 {
            let shift = if j % 2 == 0 { -0.25 } else { 0.25 };
            centres.push(((f64::from(i) - 1.5) + shift, (f64::from(j) - 1.0) * row));
        }
    }
    let lens = |u: f64, v: f64| asphere(-1.0, 1.0 / 3.0, -0.5, &[], u, v);
    let pts = [
        (-1.75, -row),
        (-0.6, -row + 0.2),
        (1.33, -row - 0.1),
        (-1.25, 0.0),
        (0.9, 0.3),
        (0.25, row + 0.12),
        (-0.77, row - 0.3),
        (0.0, -0.43),
        (1.98, 0.05),
    ];
    surface(src, "h").expect(
        &pts,
        |x, y| array_by_hand(&centres, lens, |u, v| u.hypot(v) < 0.45, (0.45, 0.0), x, y),
        "lenslet by lenslet",
    );
}

#[test]
fn linear_array_of_cylinders_with_seams() {
    // Seed 004 (Lei 2021) style: cylinders across x, 0.8 mm wide on a 1 mm
    // pitch, 5 of them: centres at x = −2 … 2; 0.2 mm seams at the land.
    let src = "surface c = cylinder { radius: 2 mm, axis: y, sense: convex, aperture: rect(x: -0.4 mm .. 0.4 mm, y: -3 mm .. 3 mm) }
surface a = linear_array(c, pitch: 1 mm, count: 5, axis: x)";
    let centres: Vec<(f64, f64)> = (-2..=2).map(|i| (f64::from(i), 0.0)).collect();
    let cyl = |u: f64, _v: f64| {
        let d = (4.0 - u * u).sqrt();
        z_slopes(-(2.0 - d), -u / d, 0.0)
    };
    let pts = [
        (-2.0, 0.0),
        (-1.62, 1.1),
        (-0.45, -2.0),
        (0.13, 2.5),
        (1.39, -0.4),
        (2.3, 0.7),
        (0.5, 0.0),
    ];
    surface(src, "a").expect(
        &pts,
        |x, y| {
            array_by_hand(
                &centres,
                cyl,
                |u, v| u.abs() < 0.4 && v.abs() < 3.0,
                (0.4, 0.0),
                x,
                y,
            )
        },
        "lenslet by lenslet",
    );
}

#[test]
fn off_axis_sections_keep_or_remove_the_tilt() {
    // A convex asphere, sectioned about (3, −1.5): z(x, y) = z_p(x + 3, y − 1.5)
    // − z_p(3, −1.5); with `tilt: remove`, turned level at its centre.
    let src = "surface p = asphere { radius: 15 mm, conic: -1.3, sense: convex, aperture: circle(radius: 5 mm), A4: 2e-5 mm^-3 }
surface k = off_axis(p, x: 3 mm, y: -1.5 mm, aperture: circle(radius: 1 mm))
surface flat = off_axis(p, x: 3 mm, y: -1.5 mm, tilt: remove, aperture: circle(radius: 1 mm))";
    let parent = |x: f64, y: f64| asphere(-1.0, 1.0 / 15.0, -1.3, &[(4, 2e-5)], x, y);
    let o = parent(3.0, -1.5);
    let pts = [(0.3, 0.4), (-0.7, 0.55), (0.62, -0.61), (-0.2, -0.9)];
    surface(src, "k").expect(
        &pts,
        |x, y| {
            let w = parent(x + 3.0, y - 1.5);
            z_slopes(w.z - o.z, w.zx.expect("zx"), w.zy.expect("zy"))
        },
        "parent about (3, −1.5)",
    );
    // With `tilt: remove` the section is turned rigidly, not sheared: level
    // at its centre (the turn itself is checked point by point in
    // lensc-lang's lower::surface::tests::tilt_removed_is_the_exact_turned_section).
    surface(src, "flat").expect(
        &[(0.0, 0.0)],
        |_, _| z_slopes(0.0, 0.0, 0.0),
        "the section turned level at its centre",
    );
}

/// Bisection for f(p) = 0 on [lo, hi], f increasing, to the last bit.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(f(lo) < 0.0 && f(hi) > 0.0, "bracket");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn tilted_surfaces_solved_by_bisection() {
    // The parent point (p, q, z(p, q)) turned by the right-handed rotation
    // about y, R_y(θ) = [[cos, 0, sin], [0, 1, 0], [−sin, 0, cos]], lands at
    // X = p cos θ + z sin θ, Z = −p sin θ + z cos θ; for each machine X
    // the parent's p is found by bisection, and the slopes are those of the
    // parent's normal (−z_p, −z_q, 1) turned the same way.
    let src = "surface p = asphere { radius: 9 mm, conic: -0.6, sense: concave, aperture: circle(radius: 3 mm), A4: 1e-4 mm^-3, A3: -2e-4 mm^-2 }
surface ty = tilt(p, about: y, angle: 12 deg, aperture: circle(radius: 1.5 mm))
surface tx = tilt(p, about: x, angle: -8 deg, aperture: circle(radius: 1.5 mm))";
    let parent = |x: f64, y: f64| asphere(1.0, 1.0 / 9.0, -0.6, &[(3, -2e-4), (4, 1e-4)], x, y);
    let th = 12f64.to_radians();
    let (c, s) = (th.cos(), th.sin());
    surface(src, "ty").expect(
        &P15,
        |x, y| {
            let p = bisect(|p| p * c + parent(p, y).z * s - x, x - 2.0, x + 2.0);
            let w = parent(p, y);
            let n = (-w.zx.expect("zx"), -w.zy.expect("zy"), 1.0);
            let (nx, ny, nz) = (n.0 * c + n.2 * s, n.1, -n.0 * s + n.2 * c);
            z_slopes(-p * s + w.z * c, -nx / nz, -ny / nz)
        },
        "bisection, R_y(12°)",
    );
    // About x: R_x(φ) = [[1, 0, 0], [0, cos, −sin], [0, sin, cos]]:
    // Y = q cos φ − z sin φ, Z = q sin φ + z cos φ.
    let ph = (-8f64).to_radians();
    let (c, s) = (ph.cos(), ph.sin());
    surface(src, "tx").expect(
        &P15,
        |x, y| {
            let q = bisect(|q| q * c - parent(x, q).z * s - y, y - 2.0, y + 2.0);
            let w = parent(x, q);
            let n = (-w.zx.expect("zx"), -w.zy.expect("zy"), 1.0);
            let (nx, ny, nz) = (n.0, n.1 * c - n.2 * s, n.1 * s + n.2 * c);
            z_slopes(q * s + w.z * c, -nx / nz, -ny / nz)
        },
        "bisection, R_x(−8°)",
    );
}

// ---------------------------------------------------------------------------
// optiland 0.6.3.
// ---------------------------------------------------------------------------

/// Compares lensc with optiland rows [x, y, z, z_x, z_y]: `sign` = −1 for
/// `convention: optical` (z_lensc = −z_optiland), +1 for the `sense` form
/// with R_optiland = s·|R| (docs/language/sign-rule.md; see the module's notes).
fn against_optiland(src: &str, name: &str, rows: &[[f64; 5]], sign: f64, source: &str) {
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[1])).collect();
    surface(src, name).expect(
        &pts,
        |x, y| {
            let r = rows.iter().find(|r| r[0] == x && r[1] == y).expect("row");
            z_slopes(sign * r[2], sign * r[3], sign * r[4])
        },
        source,
    );
}

#[test]
fn sphere_and_conic_against_optiland() {
    against_optiland(
        "surface s = sphere { radius: -8.5 mm, convention: optical, aperture: circle(radius: 1.5 mm) }",
        "s",
        OPT_SPHERE,
        -1.0,
        "−optiland StandardGeometry(R = −8.5)",
    );
    against_optiland(
        "surface s = sphere { radius: 8.5 mm, sense: convex, aperture: circle(radius: 1.5 mm) }",
        "s",
        OPT_SPHERE,
        1.0,
        "optiland StandardGeometry(R = −8.5)",
    );
    // Kim 2008's convex lens (seed 001, Table 2), R = 22.405, κ = 43.098.
    against_optiland(
        "surface s = conic { radius: 22.405 mm, conic: 43.098, convention: optical, aperture: circle(radius: 1.6 mm) }",
        "s",
        OPT_CONIC,
        -1.0,
        "−optiland StandardGeometry(R = 22.405, k = 43.098)",
    );
}

#[test]
fn aspheres_against_optiland() {
    // Kim 2008's concave base (R = −4.254, κ = −3.359) with A2 … A8.
    against_optiland(
        "surface a = asphere { radius: -4.254 mm, conic: -3.359, convention: optical, aperture: circle(radius: 1.5 mm), A2: 0.002 mm^-1, A4: 0.001 mm^-3, A6: -2e-5 mm^-5, A8: 3e-7 mm^-7 }",
        "a",
        OPT_EVEN_ASPHERE,
        -1.0,
        "−optiland EvenAsphere",
    );
    // The same in `sense` form: R_optiland = −4.254 = s·|R| with s = −1,
    // convex, coefficients times s.
    against_optiland(
        "surface a = asphere { radius: 4.254 mm, conic: -3.359, sense: convex, aperture: circle(radius: 1.5 mm), A2: -0.002 mm^-1, A4: -0.001 mm^-3, A6: 2e-5 mm^-5, A8: -3e-7 mm^-7 }",
        "a",
        OPT_EVEN_ASPHERE,
        1.0,
        "optiland EvenAsphere",
    );
    against_optiland(
        "surface a = asphere { radius: 12 mm, conic: -0.8, convention: optical, aperture: circle(radius: 1.5 mm), A1: 0.0001, A3: 0.0004 mm^-2, A4: -0.0003 mm^-3, A5: 5e-5 mm^-4, A6: -2e-6 mm^-5 }",
        "a",
        OPT_ODD_ASPHERE,
        -1.0,
        "−optiland OddAsphere",
    );
}

#[test]
fn biconic_against_optiland_on_the_axes() {
    let src = "surface b = biconic { radius_x: 6 mm, radius_y: -9 mm, conic_x: -0.5, conic_y: 1.2, convention: optical, aperture: circle(radius: 1.5 mm) }";
    against_optiland(
        src,
        "b",
        OPT_BICONIC_AXES,
        -1.0,
        "−optiland BiconicGeometry",
    );
    // Off the axes optiland's biconic is the sum of the two sections (its
    // definition, not Zemax's): check that reading of it, and that lensc's
    // differs from it there by what Zemax's formula says.
    let (cx, cy, kx, ky) = (1.0 / 6.0, -1.0 / 9.0, -0.5, 1.2);
    let b = surface(src, "b");
    for r in OPT_BICONIC_OFF_AXES {
        let (x, y) = (r[0], r[1]);
        let sum = conic_sag(cx, kx, x * x) + conic_sag(cy, ky, y * y);
        expect("optiland", "sum of sections", "z", (x, y), r[2], sum);
        let zemax = zemax_biconic(cx, cy, kx, ky, x, y).z;
        let got = b.at(&[(x, y)])[0][0];
        expect(&b.label, "−Zemax biconic", "z", (x, y), got, -zemax);
        assert!(
            (got + r[2]).abs() > 1e-7,
            "off the axes the two definitions should differ at ({x}, {y})"
        );
    }
}

#[test]
fn toroids_against_optiland() {
    against_optiland(
        "surface t = toroid { radius: 5 mm, conic: -0.6, rotation_radius: 15 mm, convention: optical, aperture: circle(radius: 1.5 mm), A4: 0.0004 mm^-3, A6: -1e-5 mm^-5 }",
        "t",
        OPT_TOROID,
        -1.0,
        "−optiland ToroidalGeometry",
    );
    against_optiland(
        "surface t = toroid { radius: 5 mm, conic: -0.6, rotation_radius: 15 mm, sense: concave, aperture: circle(radius: 1.5 mm), A4: 0.0004 mm^-3, A6: -1e-5 mm^-5 }",
        "t",
        OPT_TOROID,
        1.0,
        "optiland ToroidalGeometry",
    );
    // Both radii negative in optiland: lensc's rotation radius follows the
    // profile's side.
    against_optiland(
        "surface t = toroid { radius: -7.5 mm, rotation_radius: 4 mm, convention: optical, aperture: circle(radius: 1.5 mm), A2: 0.001 mm^-1 }",
        "t",
        OPT_TOROID_CONVEX,
        -1.0,
        "−optiland ToroidalGeometry(R_x = −4, R_y = −7.5)",
    );
}

#[test]
fn xy_polynomial_against_optiland() {
    against_optiland(
        "surface p = xy_polynomial { radius: -20 mm, conic: -1, convention: optical, aperture: circle(radius: 1.5 mm), X1Y0: 0.001, X0Y2: 0.003 mm^-1, X2Y0: -0.002 mm^-1, X1Y1: 0.0015 mm^-1, X2Y1: 0.0004 mm^-2, X0Y3: -0.0002 mm^-2, X3Y1: 5e-5 mm^-3, X1Y3: -3e-5 mm^-3 }",
        "p",
        OPT_XY_POLYNOMIAL,
        -1.0,
        "−optiland PolynomialGeometry",
    );
}

#[test]
fn zernike_against_optiland() {
    let fringe: Vec<String> = OPT_FRINGE_COEFFS
        .iter()
        .enumerate()
        .map(|(i, c)| format!("Z{}: {c} mm", i + 1))
        .collect();
    against_optiland(
        &format!(
            "surface w = zernike {{ radius: 30 mm, conic: -0.4, convention: optical, norm_radius: 2.2 mm, ordering: fringe, aperture: circle(radius: 2 mm), {} }}",
            fringe.join(", ")
        ),
        "w",
        OPT_ZERNIKE_FRINGE,
        -1.0,
        "−optiland ZernikePolynomialGeometry(fringe)",
    );
    let ansi: Vec<String> = OPT_STANDARD_COEFFS
        .iter()
        .enumerate()
        .map(|(j, c)| format!("Z{j}: {c} mm"))
        .collect();
    against_optiland(
        &format!(
            "surface w = zernike {{ sense: concave, norm_radius: 2 mm, ordering: ansi, aperture: circle(radius: 2 mm), {} }}",
            ansi.join(", ")
        ),
        "w",
        OPT_ZERNIKE_STANDARD,
        1.0,
        "optiland ZernikePolynomialGeometry(standard)",
    );
}

#[test]
fn qbfs_against_optiland() {
    let coeffs = "Q0: 0.002 mm, Q1: -0.001 mm, Q2: 0.0005 mm, Q3: 0.00025 mm, Q4: -0.0003 mm, Q5: 0.00012 mm, Q6: -5e-5 mm";
    against_optiland(
        &format!(
            "surface q = qbfs {{ radius: 25 mm, sense: concave, norm_radius: 4 mm, aperture: circle(radius: 4 mm), {coeffs} }}"
        ),
        "q",
        OPT_QBFS,
        1.0,
        "optiland ForbesQNormalSlopeGeometry(conic 0)",
    );
    against_optiland(
        &format!(
            "surface q = qbfs {{ radius: 25 mm, convention: optical, norm_radius: 4 mm, aperture: circle(radius: 4 mm), {coeffs} }}"
        ),
        "q",
        OPT_QBFS,
        -1.0,
        "−optiland ForbesQNormalSlopeGeometry(conic 0)",
    );
}

// ---------------------------------------------------------------------------
// What the seed papers publish.
// ---------------------------------------------------------------------------

#[test]
fn seed_003_lenslet_sag_and_settling_offset() {
    // Hashimoto & Yan (seed 003), Table 1: lenslet diameter 1.7 mm, radius
    // 20 mm (concave), "Lens SAG (µm) 18", "Lens edge slope (°) 2.15".
    let s = surface(
        "surface l = sphere { radius: 20 mm, sense: concave, aperture: circle(diameter: 2 mm) }",
        "l",
    );
    let o = s.at(&[(0.85, 0.0), (0.0, 0.85), (0.75, 0.0)]);
    // Computed: R − sqrt(R² − (d/2)²) = 18.0706 µm; the paper prints 18.
    let sag = 20.0 - (400.0f64 - 0.85 * 0.85).sqrt();
    expect(
        &s.label,
        "R − sqrt(R² − (d/2)²)",
        "z",
        (0.85, 0.0),
        o[0][0],
        sag,
    );
    expect(
        &s.label,
        "R − sqrt(R² − (d/2)²)",
        "z",
        (0.0, 0.85),
        o[1][0],
        sag,
    );
    assert!(
        (o[0][0] * 1e3 - 18.0).abs() < 0.5,
        "Table 1's 18 µm sag, to the digits printed: {} µm",
        o[0][0] * 1e3
    );
    // The slope at the rim is asin(0.85/20) = 2.436°, not the 2.15° printed;
    // 2.15° is the slope at r = 0.75 mm (asin(0.75/20) = 2.149°), the rim
    // of a 1.5 mm lenslet. Recorded, not explained by the paper.
    let rim = o[0][1].atan().to_degrees();
    assert!((rim - (0.85f64 / 20.0).asin().to_degrees()).abs() < 1e-10);
    assert!((rim - 2.436).abs() < 5e-4, "{rim}°");
    let at_075 = o[2][1].atan().to_degrees();
    assert!((at_075 - 2.15).abs() < 5e-3, "{at_075}°");
    // Eq. 6, h_offset = sqrt(R² − (d/2)²) − sqrt(R² − (d/2 + d_traj)²) with
    // eq. 7, d_traj = v T_s: "5 m/min … 0.001 s … 3.7 µm" (the text after
    // eq. 7). On the
    // lenslet it is the rise from the rim to d/2 + d_traj.
    let d_traj = 5000.0 / 60.0 * 0.001;
    let h = s.at(&[(0.85 + d_traj, 0.0)])[0][0] - o[0][0];
    let eq6 = (400.0f64 - 0.85 * 0.85).sqrt() - (400.0f64 - (0.85 + d_traj).powi(2)).sqrt();
    expect(&s.label, "eq. 6", "h_offset", (0.85 + d_traj, 0.0), h, eq6);
    assert!(
        (h * 1e3 - 3.7).abs() < 0.05,
        "the paper's 3.7 µm: {} µm",
        h * 1e3
    );
}

#[test]
fn seed_002_microlens_depth() {
    // Liu et al. (seed 002), §3.2, eq. 11: ellipsoids a = b = 0.505 mm, c = 1.01 mm,
    // 100 µm apart along the roller's axis and 3.75° (on R = 3 mm) around
    // it, overlapping into ~100 × 200 µm cells, "the depth of the
    // microlens was approximately 5 µm". As examples/liu_roller_microlens.lens
    // lays it out (aperture radius 0.12 mm, so neighbours overlap), the
    // lowest seam, half way to the next dimple along x, stands
    // c (1 − sqrt(1 − 0.05²/a²)) = 4.96 µm above the dimple's bottom; the seam
    // around the roller (half of 196.3 µm) stands 19.3 µm above it. The
    // paper's 5 µm is the first.
    let around = 3.75f64.to_radians() * 3.0;
    let src = format!(
        "surface d = ellipsoid {{ a: 0.505 mm, b: 0.505 mm, c: 1.01 mm, sense: concave, aperture: circle(radius: 0.12 mm) }}
surface m = grid(d, pitch_x: 0.1 mm, pitch_y: {around} mm, count_x: 4, count_y: 3)"
    );
    let m = surface(&src, "m");
    let cap = |u: f64, v: f64| 1.01 * (1.0 - (1.0 - (u * u + v * v) / (0.505f64 * 0.505)).sqrt());
    // centres: x ∈ {−0.15, −0.05, 0.05, 0.15}, y ∈ {−around, 0, around}
    let o = m.at(&[(0.05, 0.0), (0.0, 0.0), (0.05, around / 2.0)]);
    let bottom = -cap(0.12, 0.0);
    expect(
        &m.label,
        "rim at the land",
        "z",
        (0.05, 0.0),
        o[0][0],
        bottom,
    );
    let seam_x = o[1][0] - o[0][0];
    expect(
        &m.label,
        "c(1 − sqrt(1 − 0.05²/a²))",
        "depth",
        (0.0, 0.0),
        seam_x,
        cap(0.05, 0.0),
    );
    assert!(
        (seam_x * 1e3 - 5.0).abs() < 0.1,
        "the paper's ~5 µm: {} µm",
        seam_x * 1e3
    );
    let seam_y = o[2][0] - o[0][0];
    expect(
        &m.label,
        "c(1 − sqrt(1 − (p_y/2)²/b²))",
        "depth",
        (0.05, around / 2.0),
        seam_y,
        cap(0.0, around / 2.0),
    );
}

#[test]
fn seed_001_table_2_conics() {
    // Kim, Yang & Kim 2008 (seed 001), Table 2: convex R = 22.405, κ =
    // 43.098, lens radius 1.6 mm, "height of lens 279.19 µm"; concave
    // R = −4.254, κ = −3.359, 1.5 mm, "84.05 µm". The paper's eq. 1 adds
    // Σ A_j |x|^j whose A_j it does not list. The conics alone, computed:
    // 60.764 µm and 247.48 µm at the edge (checked against the sag equation
    // here); the tabulated heights are not these, and cannot be checked
    // without the missing A_j.
    let convex = surface(
        "surface s = conic { radius: 22.405 mm, conic: 43.098, sense: convex, aperture: circle(radius: 1.6 mm) }",
        "s",
    );
    let z = convex.at(&[(1.6, 0.0)])[0][0];
    expect(
        &convex.label,
        "conic sag",
        "z",
        (1.6, 0.0),
        z,
        -conic_sag(1.0 / 22.405, 43.098, 2.56),
    );
    assert!((z * 1e3 + 60.764).abs() < 0.0005, "{} µm", z * 1e3);
    let concave = surface(
        "surface s = conic { radius: -4.254 mm, conic: -3.359, convention: optical, aperture: circle(radius: 1.5 mm) }",
        "s",
    );
    let z = concave.at(&[(1.5, 0.0)])[0][0];
    expect(
        &concave.label,
        "conic sag",
        "z",
        (1.5, 0.0),
        z,
        conic_sag(1.0 / 4.254, -3.359, 2.25),
    );
    assert!((z * 1e3 - 247.48).abs() < 0.005, "{} µm", z * 1e3);
}

// BEGIN optiland 0.6.3 (generated by tests/fixtures/optiland_sag.py; do not edit)

/// optiland 0.6.3, StandardGeometry(CoordinateSystem(), radius=-8.5, conic=0.0)
#[rustfmt::skip]
const OPT_SPHERE: &[[f64; 5]] = &[
    [0.3, 0.4, -0.014718625761429707, -0.035355339059327376, -0.047140452079103175],
    [-0.7, 0.55, -0.04674618859696133, 0.08280834997001192, -0.06506370354786652],
    [1.05, -0.62, -0.08791940124204468, -0.12482048735422631, 0.07370352586630506],
    [-0.21, -1.33, -0.10732462202903979, 0.02502181849559041, 0.15847151713873928],
    [1.2, 0.8, -0.12324645223461285, -0.14325358781984415, -0.0955023918798961],
];

/// optiland 0.6.3, StandardGeometry(CoordinateSystem(), radius=22.405, conic=43.098)
#[rustfmt::skip]
const OPT_CONIC: &[[f64; 5]] = &[
    [0.3, 0.4, 0.005610084771464061, 0.013539368534553623, 0.01805249137940483],
    [-0.7, 0.55, 0.018004806597336977, -0.032390876006033964, 0.02544997400474098],
    [1.05, -0.62, 0.03434302843003345, 0.050261981886956526, -0.029678503590393375],
    [-0.21, -1.33, 0.0422133734541568, -0.010222224015262455, -0.06474075209666222],
    [1.13, 1.13, 0.06060653062347051, 0.05726629979207874, 0.05726629979207874],
];

/// optiland 0.6.3, EvenAsphere(CoordinateSystem(), radius=-4.254, conic=-3.359, coefficients=[0.002, 0.001, -2e-05, 3e-07])
#[rustfmt::skip]
const OPT_EVEN_ASPHERE: &[[f64; 5]] = &[
    [0.3, 0.4, -0.028586342894954656, -0.06790232198706006, -0.0905364293160801],
    [-0.7, 0.55, -0.08865547112646971, 0.15169080268172752, -0.11918563067850023],
    [1.05, -0.62, -0.1619090677810998, -0.2157278269405828, 0.12738214543158222],
    [-0.21, -1.33, -0.19500503408779063, 0.0421138919142332, 0.2667213154568102],
    [1.2, 0.8, -0.22151792806035042, -0.23601278121624722, -0.15734185414416477],
];

/// optiland 0.6.3, OddAsphere(CoordinateSystem(), radius=12.0, conic=-0.8, coefficients=[0.0001, 0.0, 0.0004, -0.0003, 5e-05, -2e-06])
#[rustfmt::skip]
const OPT_ODD_ASPHERE: &[[f64; 5]] = &[
    [0.3, 0.4, 0.010500352298221207, 0.025163491408385596, 0.033551321877847456],
    [-0.7, 0.55, 0.03323969171036319, -0.05864437138620854, 0.046077720374878145],
    [1.05, -0.62, 0.06229832473358761, 0.08778761293247236, -0.051836495255364615],
    [-0.21, -1.33, 0.07592367602613082, -0.01753998499018694, -0.11108657160451735],
    [1.2, 0.8, 0.08706956266661209, 0.10014720616520306, 0.06676480411013538],
];

/// optiland 0.6.3, BiconicGeometry(CoordinateSystem(), radius_x=6.0, radius_y=-9.0, conic_x=-0.5, conic_y=1.2), on the axes
#[rustfmt::skip]
const OPT_BICONIC_AXES: &[[f64; 5]] = &[
    [0.4, 0.0, 0.013340748982642413, 0.06674086442659999, -0.0],
    [-1.1, 0.0, 0.10126057096803216, -0.1848935354136907, -0.0],
    [1.45, 0.0, 0.17650643845060487, 0.24527437553913403, -0.0],
    [0.0, 0.6, -0.020049129371936654, 0.0, -0.06699500235922905],
    [0.0, -1.25, -0.08774660140715065, 0.0, 0.1419332389509149],
    [0.0, 1.5, -0.12697040352310007, 0.0, -0.17200522903844537],
];

/// optiland 0.6.3, BiconicGeometry(CoordinateSystem(), radius_x=6.0, radius_y=-9.0, conic_x=-0.5, conic_y=1.2), off the axes
#[rustfmt::skip]
const OPT_BICONIC_OFF_AXES: &[[f64; 5]] = &[
    [0.3, 0.4, -0.0013962217777882865, 0.05003127932742599, -0.04454133098211333],
    [-0.7, 0.55, 0.024062827215097164, -0.11706569527495388, -0.06136371468719008],
    [1.05, -0.62, 0.07081783872174643, 0.1763554300335454, 0.0692513465585952],
    [-0.21, -1.33, -0.09580624750011224, -0.03501072367644037, 0.15146097174276738],
    [1.2, 0.8, 0.0848946497811092, 0.20203050891044214, -0.0896716741599481],
];

/// optiland 0.6.3, ToroidalGeometry(CoordinateSystem(), radius_x=15.0, radius_y=5.0, conic=-0.6, coeffs_poly_y=[0.0, 0.0004, -1e-05])
#[rustfmt::skip]
const OPT_TOROID: &[[f64; 5]] = &[
    [0.3, 0.4, 0.01902396070798622, 0.020025397491669556, 0.08022046265863983],
    [-0.7, 0.55, 0.046698392189526455, -0.04681240426758816, 0.11065139240822036],
    [1.05, -0.62, 0.07544801505127675, 0.07035387065949555, -0.12506729728700808],
    [-0.21, -1.33, 0.18084375235847638, -0.014170847279744528, -0.2733880241548758],
    [1.2, 0.8, 0.11261068095127713, 0.08060513326299427, 0.16214928898507455],
];

/// optiland 0.6.3, ToroidalGeometry(CoordinateSystem(), radius_x=-4.0, radius_y=-7.5, conic=0.0, coeffs_poly_y=[0.001])
#[rustfmt::skip]
const OPT_TOROID_CONVEX: &[[f64; 5]] = &[
    [0.3, 0.4, -0.021809902927191604, -0.07541117761585676, -0.052758725935612774],
    [-0.7, 0.55, -0.08193098023009754, 0.17865943567301146, -0.07357821194853091],
    [1.05, -0.62, -0.1664833634503038, -0.2738999460675455, 0.08472017279751512],
    [-0.21, -1.33, -0.12278265397482103, 0.05416255558004413, 0.17778938681932646],
    [1.2, 0.8, -0.22845035628245247, -0.31817160407762307, -0.11089887541138896],
];

/// optiland 0.6.3, PolynomialGeometry(CoordinateSystem(), radius=-20.0, conic=-1.0, coefficients=C) with C[1][0]=0.001, C[0][2]=0.003, C[2][0]=-0.002, C[1][1]=0.0015, C[2][1]=0.0004, C[0][3]=-0.0002, C[3][1]=5e-05, C[1][3]=-3e-05, the rest 0
#[rustfmt::skip]
const OPT_XY_POLYNOMIAL: &[[f64; 5]] = &[
    [0.3, 0.4, -0.005468436, -0.01450052, -0.017212969999999998],
    [-0.7, 0.55, -0.021093913625000002, 0.039352433749999985, -0.025233592500000002],
    [1.05, -0.62, -0.038404933443, -0.05724618266000002, 0.02908691545],
    [-0.21, -1.33, -0.039464689556600006, 0.01063022116, 0.05719426916],
    [1.2, 0.8, -0.049910912000000016, -0.061674559999999996, -0.03319072],
];

/// Fringe Z1 … Z36 of OPT_ZERNIKE_FRINGE (mm), in order.
#[rustfmt::skip]
const OPT_FRINGE_COEFFS: [f64; 36] = [-0.00123, 0.00136, -0.00149, 0.00081, -0.000875, 0.00094, -0.001005, 0.0007133, -0.0007567, 0.0008, -0.0008433, 0.000665, -0.0006975, 0.00073, -0.0007625, 0.000636, -0.000662, 0.000688, -0.000714, 0.0006167, -0.0006383, 0.00066, -0.0006817, 0.0006029, -0.0006214, 0.00064, -0.0006586, 0.0005925, -0.0006087, 0.000625, -0.0006413, 0.0005844, -0.0005989, 0.0006133, -0.0006278, 0.000578];
/// optiland 0.6.3, ZernikePolynomialGeometry(CoordinateSystem(), radius=30.0, conic=-0.4, coefficients=OPT_FRINGE_COEFFS, zernike_type="fringe", norm_radius=2.2)
#[rustfmt::skip]
const OPT_ZERNIKE_FRINGE: &[[f64; 5]] = &[
    [0.5, -0.25, 0.004455731572305729, 0.020016049126475706, -0.011407811513900497],
    [-1.1, 0.9, 0.03037503362117593, -0.03550188216155232, 0.034650688261699744],
    [1.3, 1.2, 0.051765116402202924, 0.04594664365712307, 0.04142635755872334],
    [-0.35, -1.7, 0.049939080239894025, -0.012041221711122749, -0.05821555612219106],
    [0.0, 1.95, 0.06167204745529914, 0.00042584040442804626, 0.06556422237267497],
];

/// ANSI Z0 … Z27 of OPT_ZERNIKE_STANDARD (mm), in order.
#[rustfmt::skip]
const OPT_STANDARD_COEFFS: [f64; 28] = [0.0009, 0.00107, -0.00124, -0.00141, 0.00158, 0.000875, -0.00096, -0.001045, 0.00113, 0.001215, -0.0008667, -0.0009233, 0.00098, 0.0010367, -0.0010933, -0.0008625, 0.000905, 0.0009475, -0.00099, -0.0010325, 0.00086, 0.000894, -0.000928, -0.000962, 0.000996, 0.0008583, -0.0008867, -0.000915];
/// optiland 0.6.3, ZernikePolynomialGeometry(CoordinateSystem(), radius=inf, conic=0.0, coefficients=OPT_STANDARD_COEFFS, zernike_type="standard", norm_radius=2.0)
#[rustfmt::skip]
const OPT_ZERNIKE_STANDARD: &[[f64; 5]] = &[
    [0.5, -0.25, -0.00504500727804324, 0.00423618570529632, 0.003121601918371264],
    [-1.1, 0.9, 0.000790575732644472, 0.013978693528824854, 0.0045559868138196485],
    [1.3, 1.2, -0.003948067216427171, 0.009857916546940486, 0.00953448942716984],
    [-0.35, -1.7, 0.0009236021338633343, 0.0010421009476093653, 0.0011450792767672773],
    [0.0, 1.95, -0.0029464984712804696, 0.015608652453350974, -0.028722025052490645],
];

/// optiland 0.6.3, ForbesQNormalSlopeGeometry(CoordinateSystem(), ForbesSurfaceConfig(radius=25.0, conic=0.0, norm_radius=4.0, terms={0: 0.002, 1: -0.001, 2: 0.0005, 3: 0.00025, 4: -0.0003, 5: 0.00012, 6: -5e-05}))
#[rustfmt::skip]
const OPT_QBFS: &[[f64; 5]] = &[
    [1.3, -2.1, 0.12243214016688649, 0.05226021448290753, -0.08442034647238908],
    [0.2, 0.3, 0.0026082128632673087, 0.008026013170296624, 0.012039019755444936],
    [-2.5, 1.9, 0.1982111058467205, -0.10103767637713035, 0.07678863404661908],
    [3.1, 2.2, 0.2909233874116124, 0.12475410642493028, 0.08853517230156344],
    [-0.9, -3.6, 0.2772285688352458, -0.03628327042646495, -0.1451330817058598],
];

// END optiland 0.6.3
