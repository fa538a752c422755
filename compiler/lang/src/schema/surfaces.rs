//! The surface kinds of one formula: plane, rotational (conic, asphere,
//! Forbes), cylindrical, biconic and toric, ellipsoid, polynomial and
//! Zernike, and freeform formulas.

use super::coefficients::{
    POWER_COEFFICIENTS, QBFS_COEFFICIENTS, QCON_COEFFICIENTS, XY_COEFFICIENTS, ZERNIKE_COEFFICIENTS,
};
use super::{Category, Check, Kind, LENGTH, NUMBER, Param, Ty, opt, req};
use crate::units::Dim;

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

const AXIS: Param = req(
    "axis",
    Ty::Word(&["x", "y"]),
    Check::Any,
    "the direction the profile is extruded along; the profile varies across it",
);

pub(super) const PLANE: Kind = Kind {
    name: "plane",
    category: Category::Surface,
    params: &[APERTURE],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a flat surface at z = 0",
};

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
