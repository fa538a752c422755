//! The surface kinds of one formula: plane, rotational (conic, asphere,
//! Forbes), cylindrical, biconic and toric, ellipsoid, polynomial and
//! Zernike, and freeform formulas. Beside each, the struct its parameters
//! are read into (`composite::Surface` holds any of them).

use std::rc::Rc;

use lensc_grammar::Diagnostic;

use super::apertures::Aperture;
use super::coefficients::{
    POWER_COEFFICIENTS, QBFS_COEFFICIENTS, QCON_COEFFICIENTS, XY_COEFFICIENTS,
    ZERNIKE_COEFFICIENTS, forbes_terms, power_terms, xy_terms, zernike_terms,
};
use super::{Category, Check, Kind, LENGTH, NUMBER, Param, Ty, finish, opt, req, required_object};
use crate::units::Dim;
use crate::value::{Formula, Object, Reader, Value};

const SENSE: Param = opt(
    "sense",
    Ty::Word(&["convex", "concave"]),
    Check::Any,
    "which side is material: convex (a dome) or concave (a bowl); needed unless `convention: optical`",
);
const CONVENTION: Param = opt(
    "convention",
    Ty::Word(&["sense", "optical"]),
    Check::Any,
    "`sense` (default): radius is a magnitude and `sense` gives the side; `optical`: radius is signed as in lens design, light along +z into the material, R > 0 convex and R < 0 concave as the tool sees it",
);
pub(super) const APERTURE: Param = req(
    "aperture",
    Ty::Object(Category::Aperture),
    Check::Any,
    "the region to machine",
);

/// Which side of a surface is material, as it states it (`SENSE`,
/// `CONVENTION`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// `convention: optical`: radii signed as in lens design.
    Optical,
    /// `sense: convex`.
    Convex,
    /// `sense: concave`. A surface that reads `Facing` states its side:
    /// the checker refuses one with neither `sense` nor `convention:
    /// optical` (E0121), a plane base with coefficients too.
    Concave,
}

impl Facing {
    pub fn read(r: &Reader) -> Facing {
        if r.word("convention") == Some("optical") {
            Facing::Optical
        } else if r.word("sense") == Some("convex") {
            Facing::Convex
        } else {
            Facing::Concave
        }
    }
}

/// The surface's required `aperture`, read.
pub(super) fn aperture(r: &Reader, o: &Object) -> Result<Aperture, Diagnostic> {
    Aperture::read(required_object(r, o, "aperture")?)
}
const VERTEX_RADIUS: Param = req(
    "radius",
    LENGTH,
    Check::Any,
    "vertex radius of curvature: a positive magnitude with `sense`, signed with `convention: optical`",
);
const CONIC_CONSTANT: Param = opt(
    "conic",
    NUMBER,
    Check::Any,
    "conic constant k (0 sphere, -1 paraboloid, < -1 hyperboloid); default 0",
);

/// A vertex radius and conic constant (`VERTEX_RADIUS`, `CONIC_CONSTANT`):
/// the base most surfaces add their terms to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Base {
    /// A magnitude with `sense`, signed with `convention: optical`.
    pub radius: f64,
    /// k, 0 when not given (and for kinds without one).
    pub conic: f64,
}

impl Base {
    fn read(r: &mut Reader) -> Base {
        Base {
            radius: r.required_num("radius"),
            conic: r.num("conic").unwrap_or(0.0),
        }
    }
    /// A polynomial surface's base: none (a plane) without a `radius`.
    fn read_optional(r: &Reader) -> Option<Base> {
        let conic = r.num("conic").unwrap_or(0.0);
        r.num("radius").map(|radius| Base { radius, conic })
    }
}

const AXIS: Param = req(
    "axis",
    Ty::Word(&["x", "y"]),
    Check::Any,
    "the direction the profile is extruded along; the profile varies across it",
);

/// A word `x` or `y` naming an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
}

impl Axis {
    /// The axis the word `name` names; `otherwise` if it names none.
    pub(super) fn read(r: &Reader, name: &str, otherwise: Axis) -> Axis {
        match r.word(name) {
            Some("x") => Axis::X,
            Some("y") => Axis::Y,
            _ => otherwise,
        }
    }
}

pub(super) const PLANE: Kind = Kind {
    name: "plane",
    category: Category::Surface,
    params: &[APERTURE],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a flat surface at z = 0",
};

/// `PLANE`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub aperture: Aperture,
}

impl Plane {
    pub fn read(o: &Object) -> Result<Plane, Diagnostic> {
        let r = Reader::new(&o.fields);
        let plane = Plane {
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(plane)
    }
}

pub(super) const SPHERE: Kind = Kind {
    name: "sphere",
    category: Category::Surface,
    params: &[VERTEX_RADIUS, SENSE, CONVENTION, APERTURE],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a sphere of the given radius",
};

pub(super) const CONIC: Kind = Kind {
    name: "conic",
    category: Category::Surface,
    params: &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, CONVENTION, APERTURE],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a conic of revolution: sag = r²/R / (1 + sqrt(1 - (1+k) r²/R²))",
};

pub(super) const ASPHERE: Kind = Kind {
    name: "asphere",
    category: Category::Surface,
    params: &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, CONVENTION, APERTURE],
    family: Some(&POWER_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "a conic plus Σ Aj |r|^j, each coefficient named by its power j",
};

/// The parameters of `SPHERE`, `CONIC` and `ASPHERE` (a sphere's conic
/// constant is 0, and only an asphere has power terms).
#[derive(Clone, Debug, PartialEq)]
pub struct Conic {
    pub base: Base,
    pub facing: Facing,
    /// (j, Aj), by power.
    pub terms: Vec<(u32, f64)>,
    pub aperture: Aperture,
}

impl Conic {
    pub fn read(o: &Object) -> Result<Conic, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let conic = Conic {
            base: Base::read(&mut r),
            facing: Facing::read(&r),
            terms: power_terms(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(conic)
    }
}

pub(super) const CYLINDER: Kind = Kind {
    name: "cylinder",
    category: Category::Surface,
    params: &[VERTEX_RADIUS, AXIS, SENSE, CONVENTION, APERTURE],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a circular cylinder: a circle of the given radius across `axis`, extruded along it",
};

pub(super) const ACYLINDER: Kind = Kind {
    name: "acylinder",
    category: Category::Surface,
    params: &[
        VERTEX_RADIUS,
        CONIC_CONSTANT,
        AXIS,
        SENSE,
        CONVENTION,
        APERTURE,
    ],
    family: Some(&POWER_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "an aspheric profile (conic plus Σ Aj |u|^j) across `axis`, extruded along it",
};

/// The parameters of `CYLINDER` and `ACYLINDER` (a cylinder's conic
/// constant is 0 and it has no power terms).
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    pub base: Base,
    /// The direction the profile is extruded along.
    pub axis: Axis,
    pub facing: Facing,
    /// (j, Aj), by power.
    pub terms: Vec<(u32, f64)>,
    pub aperture: Aperture,
}

impl Cylinder {
    pub fn read(o: &Object) -> Result<Cylinder, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let cylinder = Cylinder {
            base: Base::read(&mut r),
            axis: Axis::read(&r, "axis", Axis::Y),
            facing: Facing::read(&r),
            terms: power_terms(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(cylinder)
    }
}

pub(super) const BICONIC: Kind = Kind {
    name: "biconic",
    category: Category::Surface,
    params: &[
        req(
            "radius_x",
            LENGTH,
            Check::Any,
            "vertex radius of the x–z section (a magnitude with `sense`, signed with `convention: optical`)",
        ),
        req(
            "radius_y",
            LENGTH,
            Check::Any,
            "vertex radius of the y–z section (as `radius_x`)",
        ),
        opt(
            "conic_x",
            NUMBER,
            Check::Any,
            "conic constant of the x–z section; default 0",
        ),
        opt(
            "conic_y",
            NUMBER,
            Check::Any,
            "conic constant of the y–z section; default 0",
        ),
        SENSE,
        CONVENTION,
        APERTURE,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "z = (cx x² + cy y²) / (1 + sqrt(1 - (1+kx) cx² x² - (1+ky) cy² y²))",
};

/// `BICONIC`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Biconic {
    pub radius_x: f64,
    pub radius_y: f64,
    /// 0 when not given.
    pub conic_x: f64,
    /// 0 when not given.
    pub conic_y: f64,
    pub facing: Facing,
    pub aperture: Aperture,
}

impl Biconic {
    pub fn read(o: &Object) -> Result<Biconic, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let biconic = Biconic {
            radius_x: r.required_num("radius_x"),
            radius_y: r.required_num("radius_y"),
            conic_x: r.num("conic_x").unwrap_or(0.0),
            conic_y: r.num("conic_y").unwrap_or(0.0),
            facing: Facing::read(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(biconic)
    }
}

pub(super) const TOROID: Kind = Kind {
    name: "toroid",
    category: Category::Surface,
    params: &[
        VERTEX_RADIUS,
        CONIC_CONSTANT,
        req(
            "rotation_radius",
            LENGTH,
            Check::Positive,
            "distance from the vertex to the axis the y–z profile sweeps about (parallel to y)",
        ),
        SENSE,
        CONVENTION,
        APERTURE,
    ],
    family: Some(&POWER_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "a y–z profile (conic plus Σ Aj |y|^j) swept about an axis parallel to y at `rotation_radius`",
};

/// `TOROID`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Toroid {
    /// The y–z profile's.
    pub base: Base,
    pub rotation_radius: f64,
    pub facing: Facing,
    /// (j, Aj) of the profile, by power.
    pub terms: Vec<(u32, f64)>,
    pub aperture: Aperture,
}

impl Toroid {
    pub fn read(o: &Object) -> Result<Toroid, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let toroid = Toroid {
            base: Base::read(&mut r),
            rotation_radius: r.required_num("rotation_radius"),
            facing: Facing::read(&r),
            terms: power_terms(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(toroid)
    }
}

pub(super) const ELLIPSOID: Kind = Kind {
    name: "ellipsoid",
    category: Category::Surface,
    params: &[
        req("a", LENGTH, Check::Positive, "semi-axis along x"),
        req("b", LENGTH, Check::Positive, "semi-axis along y"),
        req(
            "c",
            LENGTH,
            Check::Positive,
            "semi-axis along z (the depth scale)",
        ),
        req(
            "sense",
            Ty::Word(&["convex", "concave"]),
            Check::Any,
            "convex (a cap) or concave (a dimple)",
        ),
        APERTURE,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "the cap of an ellipsoid: z = c (1 - sqrt(1 - x²/a² - y²/b²))",
};

/// `ELLIPSOID`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Ellipsoid {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    /// Its `sense` (it has no `convention`).
    pub facing: Facing,
    pub aperture: Aperture,
}

impl Ellipsoid {
    pub fn read(o: &Object) -> Result<Ellipsoid, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let ellipsoid = Ellipsoid {
            a: r.required_num("a"),
            b: r.required_num("b"),
            c: r.required_num("c"),
            facing: Facing::read(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(ellipsoid)
    }
}

pub(super) const XY_POLYNOMIAL: Kind = Kind {
    name: "xy_polynomial",
    category: Category::Surface,
    params: &[
        opt(
            "radius",
            LENGTH,
            Check::Any,
            "vertex radius of the conic base; a plane if absent",
        ),
        CONIC_CONSTANT,
        SENSE,
        CONVENTION,
        APERTURE,
    ],
    family: Some(&XY_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "a conic base plus Σ Cij x^i y^j, each coefficient named `XiYj`",
};

/// `XY_POLYNOMIAL`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct XyPolynomial {
    /// None: a plane.
    pub base: Option<Base>,
    pub facing: Facing,
    /// (i, j, Cij), in order of (i, j).
    pub terms: Vec<(u32, u32, f64)>,
    pub aperture: Aperture,
}

impl XyPolynomial {
    pub fn read(o: &Object) -> Result<XyPolynomial, Diagnostic> {
        let r = Reader::new(&o.fields);
        let polynomial = XyPolynomial {
            base: Base::read_optional(&r),
            facing: Facing::read(&r),
            terms: xy_terms(&o.fields),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(polynomial)
    }
}

pub(super) const ZERNIKE: Kind = Kind {
    name: "zernike",
    category: Category::Surface,
    params: &[
        opt(
            "radius",
            LENGTH,
            Check::Any,
            "vertex radius of the conic base; a plane if absent",
        ),
        CONIC_CONSTANT,
        SENSE,
        CONVENTION,
        APERTURE,
        req(
            "norm_radius",
            LENGTH,
            Check::Positive,
            "normalisation radius of the Zernike terms",
        ),
        req(
            "ordering",
            Ty::Word(&["fringe", "ansi"]),
            Check::Any,
            "fringe (unnormalised, Z1 … Z37, Z1 piston) or ansi (ANSI Z80.28: Z0 piston, Z4 defocus, normalised)",
        ),
    ],
    family: Some(&ZERNIKE_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "a conic base plus Zernike polynomials over the normalisation radius",
};

/// How a Zernike surface numbers its terms (`ordering`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ordering {
    Fringe,
    Ansi,
}

/// `ZERNIKE`'s parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Zernike {
    /// None: a plane.
    pub base: Option<Base>,
    pub facing: Facing,
    pub norm_radius: f64,
    pub ordering: Ordering,
    /// (j, Zj), in order of j.
    pub terms: Vec<(u32, f64)>,
    pub aperture: Aperture,
}

impl Zernike {
    pub fn read(o: &Object) -> Result<Zernike, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let zernike = Zernike {
            base: Base::read_optional(&r),
            facing: Facing::read(&r),
            norm_radius: r.required_num("norm_radius"),
            ordering: if r.word("ordering") == Some("ansi") {
                Ordering::Ansi
            } else {
                Ordering::Fringe
            },
            terms: zernike_terms(&o.fields),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(zernike)
    }
}

pub(super) const QBFS: Kind = Kind {
    name: "qbfs",
    category: Category::Surface,
    params: &[
        req(
            "radius",
            LENGTH,
            Check::Any,
            "radius of the best-fit sphere (a magnitude with `sense`, signed with `convention: optical`)",
        ),
        SENSE,
        CONVENTION,
        req(
            "norm_radius",
            LENGTH,
            Check::Positive,
            "ρ_max, the normalisation radius (usually the aperture's)",
        ),
        APERTURE,
    ],
    family: Some(&QBFS_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "Forbes Q-bfs: best-fit sphere plus u²(1-u²)/sqrt(1-c²ρ²) Σ a_m Q_m(u²), u = ρ/ρ_max",
};

pub(super) const QCON: Kind = Kind {
    name: "qcon",
    category: Category::Surface,
    params: &[
        req(
            "radius",
            LENGTH,
            Check::Any,
            "vertex radius of the base conic (a magnitude with `sense`, signed with `convention: optical`)",
        ),
        opt("conic", NUMBER, Check::Any, "conic constant k of the base"),
        SENSE,
        CONVENTION,
        req(
            "norm_radius",
            LENGTH,
            Check::Positive,
            "ρ_max, the normalisation radius (usually the aperture's)",
        ),
        APERTURE,
    ],
    family: Some(&QCON_COEFFICIENTS),
    positional: &[],
    exclusive: &[],
    doc: "Forbes Q-con: a conic plus u⁴ Σ a_m Q_m^con(u²), Q_m^con(x) = P_m^(0,4)(2x-1), u = ρ/ρ_max",
};

/// The parameters of `QBFS` and `QCON` (a Q-bfs's base is its best-fit
/// sphere: conic constant 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Forbes {
    pub base: Base,
    pub facing: Facing,
    /// ρ_max.
    pub norm_radius: f64,
    /// (m, a_m), by order.
    pub terms: Vec<(usize, f64)>,
    pub aperture: Aperture,
}

impl Forbes {
    pub fn read(o: &Object) -> Result<Forbes, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let forbes = Forbes {
            base: Base::read(&mut r),
            facing: Facing::read(&r),
            norm_radius: r.required_num("norm_radius"),
            terms: forbes_terms(&r),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(forbes)
    }
}

pub(super) const FREEFORM: Kind = Kind {
    name: "freeform",
    category: Category::Surface,
    params: &[
        req(
            "z",
            Ty::Formula {
                coords: &["x", "y"],
                result: Dim::LENGTH,
            },
            Check::Any,
            "the height z(x, y), a length",
        ),
        req(
            "domain",
            Ty::Object(Category::Aperture),
            Check::Any,
            "where the formula applies",
        ),
        opt(
            "sense",
            Ty::Word(&["convex", "concave"]),
            Check::Any,
            "material side; the formula's z is already signed",
        ),
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a height written as a formula of x and y",
};

/// `FREEFORM`'s parameters (its `sense` is the checker's alone: the
/// formula's z is already signed).
#[derive(Clone, Debug)]
pub struct Freeform {
    pub z: Rc<Formula>,
    pub domain: Aperture,
}

impl Freeform {
    pub fn read(o: &Object) -> Result<Freeform, Diagnostic> {
        let r = Reader::new(&o.fields);
        let z = match r.field("z").map(|f| &f.value) {
            Some(Value::Formula(z)) => z.clone(),
            _ => return Err(super::missing(o, "z")),
        };
        let freeform = Freeform {
            z,
            domain: Aperture::read(required_object(&r, o, "domain")?)?,
        };
        finish(r, o)?;
        Ok(freeform)
    }
}
