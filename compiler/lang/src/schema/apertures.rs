//! The apertures: the region of a surface to machine, and `Aperture`,
//! their parameters read once.

use lensc_grammar::Diagnostic;

use super::{Category, Check, Kind, LENGTH, Ty, opt, req};
use crate::units::Dim;
use crate::value::{Object, Reader};

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

/// A checked aperture's parameters, read once: the only place the
/// apertures' parameters are named.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aperture {
    /// `circle`: its `radius`, or half its `diameter`.
    Circle { radius: f64 },
    /// `annulus`: `inner` ≤ r ≤ `outer`.
    Annulus { inner: f64, outer: f64 },
    /// `rect`: `x` × `y`, each `from .. to`.
    Rect { x: (f64, f64), y: (f64, f64) },
}

impl Aperture {
    /// Reads a checked aperture; E0121 for a size it lacks, E0124 if `o`
    /// is not an aperture.
    pub fn read(o: &Object) -> Result<Aperture, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let aperture = match o.kind.name {
            "circle" => Aperture::Circle {
                radius: match r.num("radius") {
                    Some(radius) => radius,
                    None => r.required_num("diameter") / 2.0,
                },
            },
            "annulus" => Aperture::Annulus {
                inner: r.required_num("inner"),
                outer: r.required_num("outer"),
            },
            "rect" => Aperture::Rect {
                x: super::required_range(&r, o, "x")?,
                y: super::required_range(&r, o, "y")?,
            },
            _ => return Err(super::not_a(o, Category::Aperture.noun())),
        };
        super::finish(r, o)?;
        Ok(aperture)
    }

    /// The outer radius of a circle or an annulus.
    pub fn radius(&self) -> Option<f64> {
        match *self {
            Aperture::Circle { radius } | Aperture::Annulus { outer: radius, .. } => Some(radius),
            Aperture::Rect { .. } => None,
        }
    }

    /// The inner radius of an annulus (0 for any other aperture).
    pub fn inner_radius(&self) -> f64 {
        match *self {
            Aperture::Annulus { inner, .. } => inner,
            _ => 0.0,
        }
    }
}
