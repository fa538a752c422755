//! The built-in kinds a `.lens` file constructs (`conic { … }`,
//! `round_nose { … }`, `circle(diameter: …)`): for each, its parameters with
//! their dimension, whether they are required and what range is allowed.
//! The checker validates every block against these tables.

use lensc_grammar::ast::DeclKind;

use crate::units::Dim;

/// What a kind makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    Surface,
    Tool,
    Machine,
    Strategy,
    Aperture,
}

impl Category {
    pub fn of(kind: DeclKind) -> Category {
        match kind {
            DeclKind::Surface => Category::Surface,
            DeclKind::Tool => Category::Tool,
            DeclKind::Machine => Category::Machine,
            DeclKind::Strategy => Category::Strategy,
        }
    }
    pub fn noun(self) -> &'static str {
        match self {
            Category::Surface => "a surface",
            Category::Tool => "a tool",
            Category::Machine => "a machine",
            Category::Strategy => "a strategy",
            Category::Aperture => "an aperture",
        }
    }
}

/// The type a parameter's value must have.
#[derive(Clone, Copy, Debug)]
pub enum Ty {
    /// A quantity of one of these dimensions.
    Quantity(&'static [Dim]),
    /// One of these words.
    Word(&'static [&'static str]),
    /// A value constructed by a kind of this category.
    Object(Category),
    /// A nested block with its own parameters.
    Block(&'static [Param]),
    /// `lo .. hi`, both of this dimension.
    Range(Dim),
    /// `name(coords) = expr` giving this dimension, over these coordinates.
    Formula {
        coords: &'static [&'static str],
        result: Dim,
    },
}

/// Allowed values of a quantity, in base units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Check {
    Any,
    Positive,
    NonNegative,
    /// lo ≤ v < hi
    HalfOpen(f64, f64),
}

#[derive(Clone, Copy, Debug)]
pub struct Param {
    pub name: &'static str,
    pub ty: Ty,
    pub required: bool,
    pub check: Check,
    pub doc: &'static str,
}

const fn req(name: &'static str, ty: Ty, check: Check, doc: &'static str) -> Param {
    Param {
        name,
        ty,
        required: true,
        check,
        doc,
    }
}
const fn opt(name: &'static str, ty: Ty, check: Check, doc: &'static str) -> Param {
    Param {
        name,
        ty,
        required: false,
        check,
        doc,
    }
}

pub const LENGTH: Ty = Ty::Quantity(&[Dim::LENGTH]);
pub const NUMBER: Ty = Ty::Quantity(&[Dim::NONE]);
pub const ANGLE: Ty = Ty::Quantity(&[Dim::ANGLE]);
const DEG90: f64 = std::f64::consts::FRAC_PI_2;

#[derive(Debug)]
pub struct Kind {
    pub name: &'static str,
    pub category: Category,
    pub params: &'static [Param],
    /// Parameter names that positional arguments fill, in order.
    pub positional: &'static [&'static str],
    /// At most one of each group may be given; `exactly_one` groups need one.
    pub exclusive: &'static [(&'static [&'static str], bool)],
    pub doc: &'static str,
}

impl Kind {
    pub fn param(&self, name: &str) -> Option<&'static Param> {
        self.params.iter().find(|p| p.name == name)
    }
}

const SENSE: Param = req(
    "sense",
    Ty::Word(&["convex", "concave"]),
    Check::Any,
    "which side is material: convex (a dome) or concave (a bowl)",
);
const APERTURE: Param = req(
    "aperture",
    Ty::Object(Category::Aperture),
    Check::Any,
    "the region to machine",
);
const VERTEX_RADIUS: Param = req(
    "radius",
    LENGTH,
    Check::Positive,
    "vertex radius of curvature (magnitude; `sense` gives the side)",
);
const CONIC_CONSTANT: Param = opt(
    "conic",
    NUMBER,
    Check::Any,
    "conic constant k (0 sphere, -1 paraboloid); default 0",
);

macro_rules! coefficients {
    ($($name:literal = $p:literal),* $(,)?) => {
        &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, APERTURE,
          $(opt($name, Ty::Quantity(&[Dim::new(1 - $p, 0, 0)]), Check::Any, "coefficient of |r|^j, in mm^(1-j)")),*]
    };
}

pub static KINDS: &[Kind] = &[
    Kind {
        name: "sphere",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, SENSE, APERTURE],
        positional: &[],
        exclusive: &[],
        doc: "a sphere of the given radius",
    },
    Kind {
        name: "conic",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, APERTURE],
        positional: &[],
        exclusive: &[],
        doc: "a conic of revolution: sag = r²/R / (1 + sqrt(1 - (1+k) r²/R²))",
    },
    Kind {
        name: "asphere",
        category: Category::Surface,
        params: coefficients!(
            "A1" = 1,
            "A2" = 2,
            "A3" = 3,
            "A4" = 4,
            "A5" = 5,
            "A6" = 6,
            "A7" = 7,
            "A8" = 8,
            "A9" = 9,
            "A10" = 10,
            "A11" = 11,
            "A12" = 12,
            "A13" = 13,
            "A14" = 14,
            "A15" = 15,
            "A16" = 16,
            "A17" = 17,
            "A18" = 18,
            "A19" = 19,
            "A20" = 20
        ),
        positional: &[],
        exclusive: &[],
        doc: "a conic plus Σ Aj |r|^j, each coefficient named by its power j",
    },
    Kind {
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
        positional: &[],
        exclusive: &[],
        doc: "a height written as a formula of x and y",
    },
    Kind {
        name: "circle",
        category: Category::Aperture,
        params: &[
            opt("diameter", LENGTH, Check::Positive, "diameter"),
            opt("radius", LENGTH, Check::Positive, "radius"),
        ],
        positional: &[],
        exclusive: &[(&["diameter", "radius"], true)],
        doc: "a circular aperture centred on the axis",
    },
    Kind {
        name: "rect",
        category: Category::Aperture,
        params: &[
            req("x", Ty::Range(Dim::LENGTH), Check::Any, "x from .. to"),
            req("y", Ty::Range(Dim::LENGTH), Check::Any, "y from .. to"),
        ],
        positional: &[],
        exclusive: &[],
        doc: "a rectangle x × y",
    },
    Kind {
        name: "round_nose",
        category: Category::Tool,
        params: &[
            req(
                "nose_radius",
                LENGTH,
                Check::Positive,
                "radius of the cutting edge's nose",
            ),
            req(
                "clearance",
                ANGLE,
                Check::HalfOpen(0.0, DEG90),
                "clearance angle of the flank",
            ),
            opt(
                "rake",
                ANGLE,
                Check::HalfOpen(-DEG90, DEG90),
                "rake angle; default 0°",
            ),
            opt(
                "included_angle",
                ANGLE,
                Check::HalfOpen(0.0, std::f64::consts::PI),
                "opening angle of the cutting edge",
            ),
        ],
        positional: &[],
        exclusive: &[],
        doc: "a round-nose diamond turning tool, referenced at its nose centre",
    },
    Kind {
        name: "lathe",
        category: Category::Machine,
        params: &[
            req(
                "dialect",
                Ty::Word(&["linuxcnc"]),
                Check::Any,
                "the controller's program dialect",
            ),
            req(
                "resolution",
                LENGTH,
                Check::Positive,
                "smallest programmable step",
            ),
            req(
                "travel",
                Ty::Block(&[
                    req("x", Ty::Range(Dim::LENGTH), Check::Any, "X (radius) travel"),
                    req("z", Ty::Range(Dim::LENGTH), Check::Any, "Z travel"),
                ]),
                Check::Any,
                "axis travel",
            ),
            req(
                "max_feed",
                Ty::Quantity(&[Dim::SPEED]),
                Check::Positive,
                "fastest cutting feed",
            ),
            req(
                "spindle",
                Ty::Block(&[req(
                    "max_speed",
                    Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
                    Check::Positive,
                    "spindle speed limit",
                )]),
                Check::Any,
                "the work spindle",
            ),
        ],
        positional: &[],
        exclusive: &[],
        doc: "a 2-axis lathe: X (radius) and Z (spindle axis)",
    },
    Kind {
        name: "profile_turning",
        category: Category::Strategy,
        params: &[
            req(
                "feed",
                Ty::Quantity(&[Dim::FEED_PER_REV, Dim::SPEED]),
                Check::Positive,
                "feed per revolution or feed speed",
            ),
            req(
                "spindle_speed",
                Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
                Check::Positive,
                "constant spindle speed",
            ),
            opt(
                "chord_tolerance",
                LENGTH,
                Check::Positive,
                "largest chord deviation from the exact tool-centre path; default 10 nm",
            ),
            opt(
                "from",
                LENGTH,
                Check::NonNegative,
                "radius where the cut starts; default the aperture edge",
            ),
            opt(
                "to",
                LENGTH,
                Check::NonNegative,
                "radius where the cut ends; default 0",
            ),
            opt(
                "retract",
                LENGTH,
                Check::Positive,
                "clearance above the part for rapid moves; default 1 mm",
            ),
        ],
        positional: &[],
        exclusive: &[],
        doc: "one facing pass along the profile with the nose centre offset along the normal",
    },
];

/// The parameters of a job block.
pub static JOB_PARAMS: &[Param] = &[
    req(
        "surface",
        Ty::Object(Category::Surface),
        Check::Any,
        "the surface to make",
    ),
    req(
        "tool",
        Ty::Object(Category::Tool),
        Check::Any,
        "the tool that cuts it",
    ),
    req(
        "machine",
        Ty::Object(Category::Machine),
        Check::Any,
        "the machine that moves the tool",
    ),
    req(
        "strategy",
        Ty::Object(Category::Strategy),
        Check::Any,
        "how the path is planned",
    ),
];

pub fn kind(name: &str) -> Option<&'static Kind> {
    KINDS.iter().find(|k| k.name == name)
}
