//! Surfaces made of other surfaces: a design wrapped onto a roller, an
//! off-axis section, a profile revolved, arrays of lenslets, a tilted
//! surface; beside each, the struct its parameters are read into, the
//! surfaces it is made of read with it; at the end, `Surface`, any
//! surface read once, those of one formula (`surfaces`) included.

use lensc_grammar::Diagnostic;

use super::apertures::Aperture;
use super::surfaces::{
    APERTURE, Axis, Biconic, Conic, Cylinder, Ellipsoid, Forbes, Freeform, Plane, Toroid,
    XyPolynomial, Zernike, aperture,
};
use super::{
    ANGLE, Category, Check, Kind, LENGTH, NUMBER, Param, Ty, finish, not_a, opt, req,
    required_object,
};
use crate::value::{Object, Reader};

/// The required surface `name` of `o`, read.
fn surface(r: &Reader, o: &Object, name: &str) -> Result<Box<Surface>, Diagnostic> {
    Surface::read(required_object(r, o, name)?).map(Box::new)
}

const LENSLET: Param = req(
    "lenslet",
    Ty::Object(Category::Surface),
    Check::Any,
    "the surface repeated, clipped to its own aperture, its rim at the array's land (z = 0); where lenslets overlap the deepest cut wins",
);
const ARRAY_APERTURE: Param = opt(
    "aperture",
    Ty::Object(Category::Aperture),
    Check::Any,
    "the region of the array to machine; default the rectangle around every cell",
);

pub(super) const WRAP: Kind = Kind {
    name: "wrap",
    category: Category::Surface,
    params: &[
        req(
            "surface",
            Ty::Object(Category::Surface),
            Check::Any,
            "the flat design: x along the roller's axis, y around it",
        ),
        req(
            "onto",
            Ty::Object(Category::Roller),
            Check::Any,
            "the roller it is wrapped onto",
        ),
    ],
    family: None,
    positional: &["surface"],
    exclusive: &[],
    doc: "a flat design wrapped onto a roller: y becomes the arc length R·c around it",
};

/// `WRAP`'s parameters.
#[derive(Clone, Debug)]
pub struct Wrap {
    /// The flat design.
    pub surface: Box<Surface>,
    pub onto: Roller,
}

impl Wrap {
    pub fn read(o: &Object) -> Result<Wrap, Diagnostic> {
        let r = Reader::new(&o.fields);
        let wrap = Wrap {
            surface: surface(&r, o, "surface")?,
            onto: Roller::read(required_object(&r, o, "onto")?)?,
        };
        finish(r, o)?;
        Ok(wrap)
    }
}

pub(super) const OFF_AXIS: Kind = Kind {
    name: "off_axis",
    category: Category::Surface,
    params: &[
        req(
            "parent",
            Ty::Object(Category::Surface),
            Check::Any,
            "the parent surface the section is cut from",
        ),
        req(
            "x",
            LENGTH,
            Check::Any,
            "x of the section's centre on the parent",
        ),
        req(
            "y",
            LENGTH,
            Check::Any,
            "y of the section's centre on the parent",
        ),
        opt(
            "tilt",
            Ty::Word(&["keep", "remove"]),
            Check::Any,
            "`keep` (default) the parent's slope at the centre, or `remove` it (the section turned rigidly, about y then x, until it is level at its centre: mounted square to the spindle; under 45°)",
        ),
        APERTURE,
    ],
    family: None,
    positional: &["parent"],
    exclusive: &[],
    doc: "an off-axis section of a parent surface, in coordinates centred on (x, y), its height zero there",
};

/// `OFF_AXIS`'s parameters.
#[derive(Clone, Debug)]
pub struct OffAxis {
    pub parent: Box<Surface>,
    /// The section's centre on the parent.
    pub x: f64,
    pub y: f64,
    /// `tilt: remove`: the section turned rigidly until level at its centre.
    pub remove_tilt: bool,
    pub aperture: Aperture,
}

impl OffAxis {
    pub fn read(o: &Object) -> Result<OffAxis, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let section = OffAxis {
            parent: surface(&r, o, "parent")?,
            x: r.required_num("x"),
            y: r.required_num("y"),
            remove_tilt: r.word("tilt") == Some("remove"),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(section)
    }
}

pub(super) const REVOLVE: Kind = Kind {
    name: "revolve",
    category: Category::Surface,
    params: &[
        req(
            "profile",
            Ty::Object(Category::Surface),
            Check::Any,
            "the surface whose section along +x at y = 0 is turned about the z axis",
        ),
        opt(
            "start",
            LENGTH,
            Check::Any,
            "x on the profile that lies on the axis; default 0",
        ),
        APERTURE,
    ],
    family: None,
    positional: &["profile"],
    exclusive: &[],
    doc: "a surface of revolution: z(x, y) = profile(start + sqrt(x² + y²), 0), what a 2-axis lathe makes of a profile",
};

/// `REVOLVE`'s parameters.
#[derive(Clone, Debug)]
pub struct Revolve {
    pub profile: Box<Surface>,
    /// x on the profile that lies on the axis; 0 when not given.
    pub start: f64,
    pub aperture: Aperture,
}

impl Revolve {
    pub fn read(o: &Object) -> Result<Revolve, Diagnostic> {
        let r = Reader::new(&o.fields);
        let revolved = Revolve {
            profile: surface(&r, o, "profile")?,
            start: r.num("start").unwrap_or(0.0),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(revolved)
    }
}

pub(super) const GRID: Kind = Kind {
    name: "grid",
    category: Category::Surface,
    params: &[
        LENSLET,
        req(
            "pitch_x",
            LENGTH,
            Check::Positive,
            "centre-to-centre distance along x",
        ),
        req(
            "pitch_y",
            LENGTH,
            Check::Positive,
            "centre-to-centre distance along y",
        ),
        req("count_x", NUMBER, Check::Count, "lenslets along x"),
        req("count_y", NUMBER, Check::Count, "lenslets along y"),
        ARRAY_APERTURE,
    ],
    family: None,
    positional: &["lenslet"],
    exclusive: &[],
    doc: "a rectangular array of a lenslet, centred on the origin",
};

pub(super) const HEX_GRID: Kind = Kind {
    name: "hex_grid",
    category: Category::Surface,
    params: &[
        LENSLET,
        req(
            "pitch",
            LENGTH,
            Check::Positive,
            "centre-to-centre distance to every neighbour",
        ),
        req("count_x", NUMBER, Check::Count, "lenslets per row"),
        req(
            "count_y",
            NUMBER,
            Check::Positive,
            "rows (every other row shifted by half a pitch)",
        ),
        ARRAY_APERTURE,
    ],
    family: None,
    positional: &["lenslet"],
    exclusive: &[],
    doc: "a hexagonal array of a lenslet, rows along x, centred on the origin",
};

pub(super) const LINEAR_ARRAY: Kind = Kind {
    name: "linear_array",
    category: Category::Surface,
    params: &[
        LENSLET,
        req(
            "pitch",
            LENGTH,
            Check::Positive,
            "centre-to-centre distance; the seam is the pitch less the lenslet's aperture width",
        ),
        req("count", NUMBER, Check::Count, "number of lenslets"),
        opt(
            "axis",
            Ty::Word(&["x", "y"]),
            Check::Any,
            "the direction the lenslets repeat along; default x",
        ),
        ARRAY_APERTURE,
    ],
    family: None,
    positional: &["lenslet"],
    exclusive: &[],
    doc: "a row of a lenslet (a cylinder, say) with seams between them",
};

/// How an array's cells are laid out: the parameters of `GRID`,
/// `HEX_GRID` and `LINEAR_ARRAY` beyond the lenslet and aperture they
/// share (counts are whole numbers, but for a hex grid's rows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Layout {
    Grid {
        pitch_x: f64,
        pitch_y: f64,
        count_x: f64,
        count_y: f64,
    },
    Hex {
        pitch: f64,
        count_x: f64,
        count_y: f64,
    },
    Linear {
        pitch: f64,
        count: f64,
        /// The direction the lenslets repeat along; x when not given.
        axis: Axis,
    },
}

/// The parameters of an array of lenslets.
#[derive(Clone, Debug)]
pub struct Array {
    pub lenslet: Box<Surface>,
    pub layout: Layout,
    /// None: the rectangle around every cell.
    pub aperture: Option<Aperture>,
}

impl Array {
    pub fn read(o: &Object) -> Result<Array, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let layout = match o.kind.name {
            "grid" => Layout::Grid {
                pitch_x: r.required_num("pitch_x"),
                pitch_y: r.required_num("pitch_y"),
                count_x: r.required_num("count_x"),
                count_y: r.required_num("count_y"),
            },
            "hex_grid" => Layout::Hex {
                pitch: r.required_num("pitch"),
                count_x: r.required_num("count_x"),
                count_y: r.required_num("count_y"),
            },
            "linear_array" => Layout::Linear {
                pitch: r.required_num("pitch"),
                count: r.required_num("count"),
                axis: Axis::read(&r, "axis", Axis::X),
            },
            _ => return Err(not_a(o, "an array of lenslets")),
        };
        let array = Array {
            lenslet: surface(&r, o, "lenslet")?,
            layout,
            aperture: r
                .object("aperture")
                .map(|a| Aperture::read(a))
                .transpose()?,
        };
        finish(r, o)?;
        Ok(array)
    }
}

pub(super) const TILT: Kind = Kind {
    name: "tilt",
    category: Category::Surface,
    params: &[
        req(
            "parent",
            Ty::Object(Category::Surface),
            Check::Any,
            "the surface to tilt",
        ),
        req(
            "about",
            Ty::Word(&["x", "y"]),
            Check::Any,
            "the axis through the vertex it turns about",
        ),
        req(
            "angle",
            ANGLE,
            Check::HalfOpen(-std::f64::consts::FRAC_PI_4, std::f64::consts::FRAC_PI_4),
            "the turn, right-handed about `about`, under 45° either way",
        ),
        APERTURE,
    ],
    family: None,
    positional: &["parent"],
    exclusive: &[],
    doc: "a surface turned about the x or y axis through its vertex, as a height over the machine's x–y plane",
};

/// `TILT`'s parameters.
#[derive(Clone, Debug)]
pub struct Tilt {
    pub parent: Box<Surface>,
    /// The axis through the vertex it turns about.
    pub about: Axis,
    pub angle: f64,
    pub aperture: Aperture,
}

impl Tilt {
    pub fn read(o: &Object) -> Result<Tilt, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let tilt = Tilt {
            parent: surface(&r, o, "parent")?,
            about: Axis::read(&r, "about", Axis::Y),
            angle: r.required_num("angle"),
            aperture: aperture(&r, o)?,
        };
        finish(r, o)?;
        Ok(tilt)
    }
}

pub(super) const ROLLER: Kind = Kind {
    name: "roller",
    category: Category::Roller,
    params: &[req(
        "radius",
        LENGTH,
        Check::Positive,
        "the roller's radius",
    )],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a cylindrical roller to wrap a design onto",
};

/// `ROLLER`'s parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roller {
    pub radius: f64,
}

impl Roller {
    pub fn read(o: &Object) -> Result<Roller, Diagnostic> {
        if o.kind.category != Category::Roller {
            return Err(not_a(o, Category::Roller.noun()));
        }
        let mut r = Reader::new(&o.fields);
        let roller = Roller {
            radius: r.required_num("radius"),
        };
        finish(r, o)?;
        Ok(roller)
    }
}

/// A checked surface of any kind read once, with every surface it is made
/// of: what lowering and the domain work from, no parameter looked up by
/// its name after.
#[derive(Clone, Debug)]
pub enum Surface {
    Plane(Plane),
    Sphere(Conic),
    Conic(Conic),
    Asphere(Conic),
    Cylinder(Cylinder),
    Acylinder(Cylinder),
    Biconic(Biconic),
    Toroid(Toroid),
    Ellipsoid(Ellipsoid),
    XyPolynomial(XyPolynomial),
    Zernike(Zernike),
    Qbfs(Forbes),
    Qcon(Forbes),
    Freeform(Freeform),
    Wrap(Wrap),
    OffAxis(OffAxis),
    Revolve(Revolve),
    /// `grid`, `hex_grid` and `linear_array`, told apart by their layout.
    Array(Array),
    Tilt(Tilt),
}

impl Surface {
    /// Reads a checked surface: E0121 for a parameter it (or a surface or
    /// aperture in it) lacks, E0124 if `o` is not a surface.
    pub fn read(o: &Object) -> Result<Surface, Diagnostic> {
        Ok(match o.kind.name {
            "plane" => Surface::Plane(Plane::read(o)?),
            "sphere" => Surface::Sphere(Conic::read(o)?),
            "conic" => Surface::Conic(Conic::read(o)?),
            "asphere" => Surface::Asphere(Conic::read(o)?),
            "cylinder" => Surface::Cylinder(Cylinder::read(o)?),
            "acylinder" => Surface::Acylinder(Cylinder::read(o)?),
            "biconic" => Surface::Biconic(Biconic::read(o)?),
            "toroid" => Surface::Toroid(Toroid::read(o)?),
            "ellipsoid" => Surface::Ellipsoid(Ellipsoid::read(o)?),
            "xy_polynomial" => Surface::XyPolynomial(XyPolynomial::read(o)?),
            "zernike" => Surface::Zernike(Zernike::read(o)?),
            "qbfs" => Surface::Qbfs(Forbes::read(o)?),
            "qcon" => Surface::Qcon(Forbes::read(o)?),
            "freeform" => Surface::Freeform(Freeform::read(o)?),
            "wrap" => Surface::Wrap(Wrap::read(o)?),
            "off_axis" => Surface::OffAxis(OffAxis::read(o)?),
            "revolve" => Surface::Revolve(Revolve::read(o)?),
            "grid" | "hex_grid" | "linear_array" => Surface::Array(Array::read(o)?),
            "tilt" => Surface::Tilt(Tilt::read(o)?),
            _ => return Err(not_a(o, Category::Surface.noun())),
        })
    }

    /// The region it is machined on, if it states one: its aperture, or a
    /// freeform's domain (an array's aperture is optional; a wrapped
    /// design has none of its own).
    pub fn region(&self) -> Option<&Aperture> {
        match self {
            Surface::Plane(Plane { aperture })
            | Surface::Sphere(Conic { aperture, .. })
            | Surface::Conic(Conic { aperture, .. })
            | Surface::Asphere(Conic { aperture, .. })
            | Surface::Cylinder(Cylinder { aperture, .. })
            | Surface::Acylinder(Cylinder { aperture, .. })
            | Surface::Biconic(Biconic { aperture, .. })
            | Surface::Toroid(Toroid { aperture, .. })
            | Surface::Ellipsoid(Ellipsoid { aperture, .. })
            | Surface::XyPolynomial(XyPolynomial { aperture, .. })
            | Surface::Zernike(Zernike { aperture, .. })
            | Surface::Qbfs(Forbes { aperture, .. })
            | Surface::Qcon(Forbes { aperture, .. })
            | Surface::OffAxis(OffAxis { aperture, .. })
            | Surface::Revolve(Revolve { aperture, .. })
            | Surface::Tilt(Tilt { aperture, .. }) => Some(aperture),
            Surface::Freeform(Freeform { domain, .. }) => Some(domain),
            Surface::Array(Array { aperture, .. }) => aperture.as_ref(),
            Surface::Wrap(_) => None,
        }
    }
}
