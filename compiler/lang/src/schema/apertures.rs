//! The apertures: the region of a surface to machine.

use super::{Category, Check, Kind, LENGTH, Ty, opt, req};
use crate::units::Dim;

pub(super) const CIRCLE: Kind = Kind {
    name: "circle",
    category: Category::Aperture,
    params: &[
        opt("diameter", LENGTH, Check::Positive, "diameter"),
        opt("radius", LENGTH, Check::Positive, "radius"),
    ],
    family: None,
    positional: &[],
    exclusive: &[(&["diameter", "radius"], true)],
    doc: "a circular aperture centred on the axis",
};

pub(super) const ANNULUS: Kind = Kind {
    name: "annulus",
    category: Category::Aperture,
    params: &[
        req("inner", LENGTH, Check::NonNegative, "inner radius"),
        req("outer", LENGTH, Check::Positive, "outer radius"),
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a ring about the axis, inner ≤ r ≤ outer",
};

pub(super) const RECT: Kind = Kind {
    name: "rect",
    category: Category::Aperture,
    params: &[
        req("x", Ty::Range(Dim::LENGTH), Check::Any, "x from .. to"),
        req("y", Ty::Range(Dim::LENGTH), Check::Any, "y from .. to"),
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a rectangle x × y",
};
