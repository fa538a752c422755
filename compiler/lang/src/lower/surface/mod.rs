//! Lowering checked surfaces to the runtime's expression IR: the height
//! z(x, y) in mm as a `SurfaceTape` (with its exact derivatives) and the
//! domain it is defined on.
//!
//! A surface is read once into its typed parameters (`schema::Surface`)
//! and lowered from them: nothing here looks a parameter up by its name.
//!
//! This file holds what every family shares (the lowered surface, the
//! material side, the domain, the conic sag and power series) and the one
//! dispatch `height`; each family lowers in its own file: `rotational`,
//! `anamorphic`, `polynomial`, `formula`, `arrays` and `derived`.

mod anamorphic;
mod arrays;
mod derived;
mod formula;
mod polynomial;
mod rotational;
#[cfg(test)]
mod tests;

pub use arrays::{array_cells, array_centres, array_lenslet, lower_trajectory};
pub use formula::lower_formula;
pub use polynomial::{zernike_ansi, zernike_fringe};
use rotational::Radial;
pub use rotational::rotational_sag;

use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::{Binary, Graph, Id, SurfaceTape};

use crate::domain::domain;
use crate::schema::{Category, Facing, Surface};
use crate::value::{self, Object, Reader};

/// A surface ready to evaluate.
pub struct LoweredSurface {
    pub tape: SurfaceTape,
    pub domain: Domain,
}

/// Why a checked surface cannot be lowered (yet).
#[derive(Debug, PartialEq)]
pub enum LowerError {
    /// The kind (or a part of it) has no IR lowering yet.
    Unsupported(&'static str),
    /// The aperture or domain is of a shape the surface cannot use.
    Aperture(&'static str),
    /// A parameter the checker requires is missing (a declaration that did
    /// not check): E0121's words.
    Missing(String),
}

/// How the material side enters the height: z = σ · sag(c), with c the
/// signed vertex curvature used in the sag formula.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Side {
    /// +1 or −1: multiplies the whole sag (coefficients included).
    pub sigma: f64,
    /// Whether the radius is used with its sign (optical convention).
    pub signed: bool,
}

impl From<Facing> for Side {
    /// With `sense`, radii are magnitudes and σ = +1 concave, −1 convex
    /// (Lin's s). With `convention: optical` (light along +z into the
    /// material), the sag is the lens designer's, seen from the other side:
    /// σ = −1 and radii keep their sign, so R > 0 is convex to the tool.
    fn from(facing: Facing) -> Side {
        match facing {
            Facing::Optical => Side {
                sigma: -1.0,
                signed: true,
            },
            Facing::Convex => Side {
                sigma: -1.0,
                signed: false,
            },
            Facing::Concave => Side {
                sigma: 1.0,
                signed: false,
            },
        }
    }
}

impl Side {
    /// The side of a checked surface with these fields (`sense` /
    /// `convention`, read as `Facing`).
    pub fn of(f: &[value::Field]) -> Side {
        Side::from(Facing::read(&Reader::new(f)))
    }
    /// σ · sag, as a node: the height on the material's side.
    pub(crate) fn apply(self, g: &mut Graph, sag: Id) -> Id {
        let s = g.constant_node(self.sigma);
        g.mul(s, sag)
    }
    /// The curvature 1/R the sag formula uses.
    pub fn curvature(self, radius: f64) -> f64 {
        if self.signed {
            1.0 / radius
        } else {
            1.0 / radius.abs()
        }
    }
}

/// Lowers a checked surface object.
pub fn lower_surface(o: &Object) -> Result<LoweredSurface, LowerError> {
    lower(&read(o)?)
}

/// A checked surface's parameters, read once for lowering.
fn read(o: &Object) -> Result<Surface, LowerError> {
    if o.kind.category != Category::Surface {
        return Err(LowerError::Unsupported(o.kind.name));
    }
    Surface::read(o).map_err(|d| LowerError::Missing(d.message))
}

/// Lowers a surface read.
fn lower(s: &Surface) -> Result<LoweredSurface, LowerError> {
    let domain = domain(s).ok_or(LowerError::Aperture("no aperture or domain"))?;
    if let Some(tape) = rotational::radial_tape(s) {
        return Ok(LoweredSurface { tape, domain });
    }
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let closed_forms = match s {
        Surface::Array(a) => Some(arrays::array_outputs(&mut g, a, x, y)?),
        Surface::Tilt(t) => Some(derived::tilted_outputs(&mut g, t, x, y)?),
        Surface::Revolve(r) => Some(derived::revolved_outputs(&mut g, r, x, y)?),
        _ => None,
    };
    if let Some(outputs) = closed_forms {
        return Ok(LoweredSurface {
            tape: SurfaceTape::with_outputs(g, outputs),
            domain,
        });
    }
    let z = height(&mut g, s, x, y)?;
    Ok(LoweredSurface {
        tape: SurfaceTape::new(g, z),
        domain,
    })
}

/// The height of surface `s` at the coordinates `x`, `y` (nodes of `g`),
/// built into `g`: sections and wrapped designs build their parent's height
/// at moved coordinates.
pub fn height(g: &mut Graph, s: &Surface, x: Id, y: Id) -> Result<Id, LowerError> {
    match s {
        Surface::Plane(_) => Ok(g.constant_node(0.0)),
        Surface::Sphere(p) | Surface::Conic(p) | Surface::Asphere(p) => {
            Ok(rotational::conic_height(g, p, x, y))
        }
        Surface::Qbfs(p) => Ok(rotational::forbes_height(g, Radial::Qbfs(p), x, y)),
        Surface::Qcon(p) => Ok(rotational::forbes_height(g, Radial::Qcon(p), x, y)),
        Surface::Cylinder(p) | Surface::Acylinder(p) => Ok(anamorphic::cylinder_height(g, p, x, y)),
        Surface::Biconic(p) => Ok(anamorphic::biconic_height(g, p, x, y)),
        Surface::Toroid(p) => Ok(anamorphic::toroid_height(g, p, x, y)),
        Surface::Ellipsoid(p) => Ok(anamorphic::ellipsoid_height(g, p, x, y)),
        Surface::XyPolynomial(p) => Ok(polynomial::xy_polynomial_height(g, p, x, y)),
        Surface::Zernike(p) => polynomial::zernike_height(g, p, x, y),
        Surface::Freeform(p) => Ok(formula::freeform_height(g, p, x, y)),
        Surface::Wrap(p) => derived::wrap_height(g, p, x, y),
        Surface::Revolve(p) => derived::revolve_height(g, p, x, y),
        Surface::OffAxis(p) => derived::off_axis_height(g, p, x, y),
        Surface::Array(p) => arrays::array_height(g, p, x, y),
        Surface::Tilt(p) => derived::tilted_height(g, p, x, y),
    }
}

/// x² + y².
fn radius_squared(g: &mut Graph, x: Id, y: Id) -> Id {
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    g.add(x2, y2)
}

/// c s / (1 + sqrt(1 − (1+k) c² s)) with s = r² (or u²): the conic sag,
/// smooth through the vertex.
fn conic_sag(g: &mut Graph, c: f64, k: f64, s: Id) -> Id {
    let cc = g.constant_node(c);
    let num = g.mul(cc, s);
    let q = g.constant_node((1.0 + k) * c * c);
    let qs = g.mul(q, s);
    let one = g.constant_node(1.0);
    let u = g.sub(one, qs);
    let root = g.sqrt(u);
    let den = g.add(one, root);
    g.div(num, den)
}

/// sag + Σ A_j (s)^(j/2), with s = r². The even terms are one polynomial
/// in s, evaluated by Horner's rule (fewer nodes, and so fewer in every
/// derivative); odd terms are real powers of s.
fn add_power_terms(g: &mut Graph, mut sag: Id, s: Id, terms: &[(u32, f64)]) -> Id {
    let mut even: Vec<(u32, f64)> = terms
        .iter()
        .filter(|(j, _)| j % 2 == 0)
        .map(|&(j, a)| (j / 2, a))
        .collect();
    even.sort_unstable_by_key(|t| t.0);
    if let Some(&(lowest, _)) = even.first() {
        // Σ a_m s^m = s^lowest · (a_lowest + s (a_next + s (…)))
        let top = even.last().expect("non-empty").0;
        let mut poly = g.constant_node(0.0);
        for m in (lowest..=top).rev() {
            let a = even.iter().find(|t| t.0 == m).map_or(0.0, |t| t.1);
            let times = g.mul(poly, s);
            let ac = g.constant_node(a);
            poly = g.add(times, ac);
        }
        let base = g.powi(s, lowest as i32);
        let t = g.mul(base, poly);
        sag = g.add(sag, t);
    }
    for &(j, a) in terms.iter().filter(|(j, _)| j % 2 == 1) {
        let half = g.constant_node(f64::from(j) / 2.0);
        let t = g.binary(Binary::Pow, s, half);
        let ac = g.constant_node(a);
        let term = g.mul(ac, t);
        sag = g.add(sag, term);
    }
    sag
}
