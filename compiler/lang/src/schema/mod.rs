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
    Roller,
    Dialect,
}

impl Category {
    pub fn of(kind: DeclKind) -> Category {
        match kind {
            DeclKind::Surface => Category::Surface,
            DeclKind::Tool => Category::Tool,
            DeclKind::Machine => Category::Machine,
            DeclKind::Strategy => Category::Strategy,
            DeclKind::Dialect => Category::Dialect,
        }
    }
    pub fn noun(self) -> &'static str {
        match self {
            Category::Surface => "a surface",
            Category::Tool => "a tool",
            Category::Machine => "a machine",
            Category::Strategy => "a strategy",
            Category::Aperture => "an aperture",
            Category::Roller => "a roller",
            Category::Dialect => "a dialect",
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
    /// A list `[a, b]` of values of this category.
    Objects(Category),
    /// A string `"…"`.
    Text,
    /// A list of strings `["…", "…"]`.
    Texts,
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
    /// lo < v < hi
    Open(f64, f64),
    /// A whole number from 1 to 100 000.
    Count,
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

/// A family of parameters named by a pattern (`X2Y1`, `Z11`): a
/// description for messages, and the parameter a name stands for.
pub struct Family {
    pub describe: &'static str,
    pub param: fn(&str) -> Option<Param>,
}

impl std::fmt::Debug for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe)
    }
}

#[derive(Debug)]
pub struct Kind {
    pub name: &'static str,
    pub category: Category,
    pub params: &'static [Param],
    /// Coefficients named by a pattern, beyond `params`.
    pub family: Option<&'static Family>,
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
const APERTURE: Param = req(
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

/// `A1` … `A20`: the coefficient of |r|^j (or |u|^j for a cylinder), in mm^(1−j).
pub static POWER_COEFFICIENTS: Family = Family {
    describe: "coefficients `A1` … `A20` named by their power, in mm^(1-j)",
    param: |name| {
        let j: i8 = name.strip_prefix('A')?.parse().ok()?;
        (1..=20).contains(&j).then_some(Param {
            name: "A",
            ty: Ty::Quantity(power_dims(j)),
            required: false,
            check: Check::Any,
            doc: "coefficient of |r|^j, in mm^(1-j)",
        })
    },
};

/// `XiYj`: the coefficient of x^i y^j (i + j from 1 to 20), in mm^(1−i−j).
pub static XY_COEFFICIENTS: Family = Family {
    describe: "coefficients `XiYj` of x^i y^j (1 <= i + j <= 20), in mm^(1-i-j)",
    param: |name| {
        let (i, j) = xy_powers(name)?;
        Some(Param {
            name: "XiYj",
            ty: Ty::Quantity(power_dims((i + j) as i8)),
            required: false,
            check: Check::Any,
            doc: "coefficient of x^i y^j, in mm^(1-i-j)",
        })
    },
};

/// `Z1`, `Z2`, …: Zernike coefficients (lengths), in the surface's ordering.
pub static ZERNIKE_COEFFICIENTS: Family = Family {
    describe: "Zernike coefficients (lengths) numbered in the chosen `ordering`: `Z1` … `Z37` fringe, `Z0` … `Z230` ansi",
    param: |name| {
        let j: u32 = name.strip_prefix('Z')?.parse().ok()?;
        (0..=230).contains(&j).then_some(Param {
            name: "Zj",
            ty: LENGTH,
            required: false,
            check: Check::Any,
            doc: "Zernike coefficient, a length",
        })
    },
};

/// `Q0` … `Q20`: Forbes Q-bfs coefficients (lengths).
pub static QBFS_COEFFICIENTS: Family = Family {
    describe: "Forbes Q-bfs coefficients `Q0` … `Q20` (lengths)",
    param: |name| {
        let m: usize = name.strip_prefix('Q')?.parse().ok()?;
        (m <= 20).then_some(Param {
            name: "Qm",
            ty: LENGTH,
            required: false,
            check: Check::Any,
            doc: "Q-bfs coefficient a_m, a length",
        })
    },
};

/// `Q0` … `Q20`: Forbes Q-con coefficients (lengths).
pub static QCON_COEFFICIENTS: Family = Family {
    describe: "Forbes Q-con coefficients `Q0` … `Q20` (lengths)",
    param: |name| {
        let m: usize = name.strip_prefix('Q')?.parse().ok()?;
        (m <= 20).then_some(Param {
            name: "Qm",
            ty: LENGTH,
            required: false,
            check: Check::Any,
            doc: "Q-con coefficient a_m, a length",
        })
    },
};

/// The (i, j) of a name `XiYj`, if it is one with 1 ≤ i + j ≤ 20.
pub fn xy_powers(name: &str) -> Option<(u32, u32)> {
    let rest = name.strip_prefix('X')?;
    let (i, j) = rest.split_once('Y')?;
    let (i, j): (u32, u32) = (i.parse().ok()?, j.parse().ok()?);
    (1..=20).contains(&(i + j)).then_some((i, j))
}

/// The dimension mm^(1−n) of a coefficient of a term of total power n,
/// as a static slice for `Ty::Quantity`.
fn power_dims(n: i8) -> &'static [Dim] {
    const fn d(n: i8) -> [Dim; 1] {
        [Dim::new(1 - n, 0, 0)]
    }
    static DIMS: [[Dim; 1]; 21] = [
        d(0),
        d(1),
        d(2),
        d(3),
        d(4),
        d(5),
        d(6),
        d(7),
        d(8),
        d(9),
        d(10),
        d(11),
        d(12),
        d(13),
        d(14),
        d(15),
        d(16),
        d(17),
        d(18),
        d(19),
        d(20),
    ];
    &DIMS[n.clamp(0, 20) as usize]
}

const DIALECT: Param = req(
    "dialect",
    Ty::Object(Category::Dialect),
    Check::Any,
    "the controller's program dialect (see `std::dialects`): programs are written in it unless `lensc build --dialect` names one of `other_dialects`",
);
const OTHER_DIALECTS: Param = opt(
    "other_dialects",
    Ty::Objects(Category::Dialect),
    Check::Any,
    "further dialects the controller accepts, chosen with `lensc build --dialect NAME`",
);
const RESOLUTION: Param = req(
    "resolution",
    LENGTH,
    Check::Positive,
    "smallest programmable step",
);
const MAX_FEED: Param = req(
    "max_feed",
    Ty::Quantity(&[Dim::SPEED]),
    Check::Positive,
    "fastest cutting feed",
);
const SPINDLE: Param = req(
    "spindle",
    Ty::Block(&[req(
        "max_speed",
        Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
        Check::Positive,
        "spindle speed limit",
    )]),
    Check::Any,
    "the work spindle",
);
const LATHE_TRAVEL: Param = req(
    "travel",
    Ty::Block(&[
        req("x", Ty::Range(Dim::LENGTH), Check::Any, "X (radius) travel"),
        req("z", Ty::Range(Dim::LENGTH), Check::Any, "Z travel"),
    ]),
    Check::Any,
    "axis travel",
);
const RETRACT: Param = opt(
    "retract",
    LENGTH,
    Check::Positive,
    "clearance above the part for rapid moves; default 1 mm",
);
const CHORD_TOLERANCE: Param = opt(
    "chord_tolerance",
    LENGTH,
    Check::Positive,
    "largest chord deviation from the exact tool-centre path; default 10 nm",
);

// The parameters both spiral strategies share.
const SPIRAL_FEED: Param = req(
    "feed",
    Ty::Quantity(&[Dim::FEED_PER_REV]),
    Check::Positive,
    "radial feed per revolution",
);
const SPIRAL_SPINDLE_SPEED: Param = opt(
    "spindle_speed",
    Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
    Check::Positive,
    "constant spindle speed",
);
const SURFACE_SPEED: Param = opt(
    "surface_speed",
    Ty::Quantity(&[Dim::SPEED]),
    Check::Positive,
    "constant surface speed at the tool",
);
const SPINDLE_CAP: Param = opt(
    "spindle_cap",
    Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
    Check::Positive,
    "highest spindle speed under constant surface speed; default the machine's",
);
const SEED_ARC: Param = opt(
    "seed_arc",
    LENGTH,
    Check::Positive,
    "largest arc between the samples the chord test starts from; default 0.1 mm",
);
const SPIRAL_FROM: Param = opt(
    "from",
    LENGTH,
    Check::NonNegative,
    "radius where the spiral starts; default the outermost point of the surface",
);

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

const AXIS: Param = req(
    "axis",
    Ty::Word(&["x", "y"]),
    Check::Any,
    "the direction the profile is extruded along; the profile varies across it",
);

const fn text(name: &'static str, doc: &'static str) -> Param {
    opt(name, Ty::Text, Check::Any, doc)
}
const fn texts(name: &'static str, doc: &'static str) -> Param {
    opt(name, Ty::Texts, Check::Any, doc)
}

/// A G-code dialect: everything a post-processor needs to know about a
/// controller, so a shop adds one in a `.lens` file without rebuilding
/// lensc. Lines may hold `{job}`, `{JOB}` (upper case), `{number}` and
/// `{tolerance}` (mm, to the machine's decimals).
const GCODE_PARAMS: &[Param] = &[
    req(
        "extension",
        Ty::Text,
        Check::Any,
        "the program file's extension, without the dot",
    ),
    req(
        "comment",
        Ty::Word(&["parentheses", "semicolon"]),
        Check::Any,
        "comment syntax: `(text)` or `; text`",
    ),
    texts(
        "start",
        "lines before the header comments (`%`, `O{number}`, a program name line)",
    ),
    opt(
        "program_number",
        NUMBER,
        Check::Count,
        "the program number `{number}` stands for; default 1",
    ),
    texts(
        "lathe_setup",
        "the safe-start lines of a lathe program (plane, units, absolute, radius or diameter mode, cancels)",
    ),
    texts("mill_setup", "the safe-start lines of a mill program"),
    texts(
        "path_tolerance",
        "lines that hold the controller's blending to `{tolerance}`; left out if absent",
    ),
    texts(
        "c_axis_on",
        "lines that switch the spindle to a position-controlled C axis before a C move",
    ),
    texts(
        "c_axis_off",
        "lines that give the spindle back after C moves",
    ),
    texts("end", "the blocks that end the program (`M2`, `M30`)"),
    texts(
        "trailer",
        "lines after the last block, written as they are (`%`)",
    ),
    req(
        "lathe_x",
        Ty::Word(&["radius", "diameter"]),
        Check::Any,
        "whether a lathe's X word is the radius or the diameter (the setup lines must select the same)",
    ),
    text("rapid", "the rapid-move word; default `G0`"),
    text("linear", "the linear-move word; default `G1`"),
    text("arc_cw", "the clockwise-arc word; default `G2`"),
    text("arc_ccw", "the counter-clockwise-arc word; default `G3`"),
    texts(
        "arc_planes",
        "planes the controller interpolates arcs in, of \"xy\" (G17), \"zx\" (G18), \"yz\" (G19); none: no arcs",
    ),
    req(
        "arc_centre",
        Ty::Word(&["incremental", "absolute"]),
        Check::Any,
        "arc centres I J K from the arc's start (`incremental`) or in work coordinates",
    ),
    texts(
        "surface_speed",
        "blocks that set constant surface speed before the spindle-on word (`{speed}` m/min, `{cap}` rpm); none: the controller cannot",
    ),
    text(
        "fts_table",
        "the extension of a fast-tool-servo table file (rows `C X W`: degrees, mm, mm) written beside the program; absent: the fast axis's motion is programmed on Z",
    ),
    texts(
        "fts_on",
        "blocks that arm the servo to follow its table, before the plunge (`{table}`: the table's file name)",
    ),
    texts(
        "fts_off",
        "blocks that release the servo after the last revolution",
    ),
    opt(
        "arc_radius_tolerance",
        LENGTH,
        Check::Positive,
        "the most an arc's end radius may differ from its start radius before the controller refuses it; default 0.001 mm (LinuxCNC allows about 0.025 mm, Beckhoff 0.005 mm); arcs are checked after rounding",
    ),
    text(
        "per_minute",
        "the word for feeds per minute; absent: not available",
    ),
    text(
        "per_revolution",
        "the word for feeds per revolution; absent: not available",
    ),
    text(
        "inverse_time",
        "the word for inverse-time feeds (F = 1/minutes of the move); absent: moves that turn the C axis cannot be timed",
    ),
    text("spindle_on", "the spindle-on word; default `M3`"),
    text("spindle_off", "the spindle-off word; default `M5`"),
    text("c_letter", "the spindle's C-axis letter; default `C`"),
    opt(
        "c_decimals",
        NUMBER,
        Check::Count,
        "decimals of C in degrees; default 5 (4 nm of arc at 25 mm)",
    ),
    opt(
        "max_decimals",
        NUMBER,
        Check::Count,
        "the most decimals a linear axis takes; a machine whose resolution needs more is refused",
    ),
    opt(
        "max_digits",
        NUMBER,
        Check::Count,
        "the most digits in one value (Fanuc: 8); a program needing more is refused",
    ),
    opt(
        "max_line_length",
        NUMBER,
        Check::Count,
        "the longest line the controller reads, in characters",
    ),
    opt(
        "line_numbers",
        NUMBER,
        Check::Count,
        "number each block `N…` in steps of this; absent: no numbers",
    ),
    opt(
        "max_line_number",
        NUMBER,
        Check::Count,
        "block numbers start again from the step after this",
    ),
    text(
        "block_end",
        "text closing every block (Heidenhain ISO: ` *`); default none",
    ),
];

pub static KINDS: &[Kind] = &[
    Kind {
        name: "gcode",
        category: Category::Dialect,
        params: GCODE_PARAMS,
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a G-code (ISO 6983 family) program dialect: how one controller wants its programs written",
    },
    Kind {
        name: "plane",
        category: Category::Surface,
        params: &[APERTURE],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a flat surface at z = 0",
    },
    Kind {
        name: "sphere",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, SENSE, CONVENTION, APERTURE],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a sphere of the given radius",
    },
    Kind {
        name: "conic",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, CONVENTION, APERTURE],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a conic of revolution: sag = r²/R / (1 + sqrt(1 - (1+k) r²/R²))",
    },
    Kind {
        name: "asphere",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, CONIC_CONSTANT, SENSE, CONVENTION, APERTURE],
        family: Some(&POWER_COEFFICIENTS),
        positional: &[],
        exclusive: &[],
        doc: "a conic plus Σ Aj |r|^j, each coefficient named by its power j",
    },
    Kind {
        name: "cylinder",
        category: Category::Surface,
        params: &[VERTEX_RADIUS, AXIS, SENSE, CONVENTION, APERTURE],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a circular cylinder: a circle of the given radius across `axis`, extruded along it",
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a height written as a formula of x and y",
    },
    Kind {
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
    },
    Kind {
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
                "`keep` (default) the parent's slope at the centre, or `remove` it (the section mounted square to the spindle, small-angle)",
            ),
            APERTURE,
        ],
        family: None,
        positional: &["parent"],
        exclusive: &[],
        doc: "an off-axis section of a parent surface, in coordinates centred on (x, y), its height zero there",
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
    },
    Kind {
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
            opt(
                "centre_height",
                LENGTH,
                Check::Any,
                "height of the edge above the spindle axis as set (below: negative); profile turning corrects X for it; default 0",
            ),
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a round-nose diamond turning tool, referenced at its nose centre",
    },
    Kind {
        name: "lathe",
        category: Category::Machine,
        params: &[
            DIALECT,
            OTHER_DIALECTS,
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
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a 2-axis lathe: X (radius) and Z (spindle axis)",
    },
    Kind {
        name: "microshaper",
        category: Category::Tool,
        params: &[
            req(
                "nose_radius",
                LENGTH,
                Check::Positive,
                "radius of the knife's nose, the arc of its cutting edge in the rake face (across the cut)",
            ),
            opt(
                "clearance",
                ANGLE,
                Check::HalfOpen(0.0, DEG90),
                "clearance angle of the flank; when given, checked against the steepest slope along the cut",
            ),
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "Lin's microshaper knife (seed 000): scrapes along the cut, rake face forward, its edge a nose arc across the cut",
    },
    Kind {
        name: "ball_end",
        category: Category::Tool,
        params: &[req(
            "diameter",
            LENGTH,
            Check::Positive,
            "diameter of the ball",
        )],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a ball-end mill, referenced at the ball's centre",
    },
    Kind {
        name: "spherical_wheel",
        category: Category::Tool,
        params: &[req(
            "diameter",
            LENGTH,
            Check::Positive,
            "diameter D_t of the wheel's spherical tip",
        )],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a spherical grinding wheel, referenced at its centre (seed 001)",
    },
    Kind {
        name: "fts_lathe",
        category: Category::Machine,
        params: &[
            DIALECT,
            OTHER_DIALECTS,
            RESOLUTION,
            LATHE_TRAVEL,
            MAX_FEED,
            SPINDLE,
            req(
                "fast_axis",
                Ty::Block(&[
                    req("stroke", LENGTH, Check::Positive, "travel of the fast axis"),
                    req(
                        "max_acceleration",
                        Ty::Quantity(&[Dim::ACCELERATION]),
                        Check::Positive,
                        "acceleration limit of the fast axis",
                    ),
                    opt(
                        "resonance",
                        Ty::Quantity(&[Dim::FREQUENCY]),
                        Check::Positive,
                        "resonance frequency of the closed-loop servo (with `resonant_peak`)",
                    ),
                    opt(
                        "resonant_peak",
                        NUMBER,
                        Check::Positive,
                        "resonant peak of the closed-loop servo, in dB (with `resonance`)",
                    ),
                    opt(
                        "natural_frequency",
                        Ty::Quantity(&[Dim::FREQUENCY]),
                        Check::Positive,
                        "natural frequency of the servo model (with `damping`, instead of the resonance)",
                    ),
                    opt(
                        "damping",
                        NUMBER,
                        Check::Open(0.0, 1.0),
                        "damping ratio of the servo model (with `natural_frequency`)",
                    ),
                    opt(
                        "data_rate",
                        Ty::Quantity(&[Dim::FREQUENCY]),
                        Check::Positive,
                        "rate at which the servo takes positions; default 20 kHz",
                    ),
                    opt(
                        "settling_band",
                        NUMBER,
                        Check::Positive,
                        "settling band as a fraction of the step; default 0.002 (0.2 %)",
                    ),
                ]),
                Check::Any,
                "the fast tool servo (W axis) and its second-order model",
            ),
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a lathe with C-axis spindle and a fast tool servo W along Z",
    },
    Kind {
        name: "sts_lathe",
        category: Category::Machine,
        params: &[
            DIALECT,
            OTHER_DIALECTS,
            RESOLUTION,
            LATHE_TRAVEL,
            MAX_FEED,
            SPINDLE,
            req(
                "z_axis",
                Ty::Block(&[
                    req(
                        "max_acceleration",
                        Ty::Quantity(&[Dim::ACCELERATION]),
                        Check::Positive,
                        "acceleration limit of Z",
                    ),
                    opt(
                        "data_rate",
                        Ty::Quantity(&[Dim::FREQUENCY]),
                        Check::Positive,
                        "rate at which the controller takes positions; default 1 kHz",
                    ),
                ]),
                Check::Any,
                "Z, which follows the surface as the spindle turns",
            ),
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a lathe whose spindle is a C axis and whose Z follows the surface: slow-tool-servo turning",
    },
    Kind {
        name: "mill_3axis",
        category: Category::Machine,
        params: &[
            DIALECT,
            OTHER_DIALECTS,
            RESOLUTION,
            req(
                "travel",
                Ty::Block(&[
                    req("x", Ty::Range(Dim::LENGTH), Check::Any, "X travel"),
                    req("y", Ty::Range(Dim::LENGTH), Check::Any, "Y travel"),
                    req("z", Ty::Range(Dim::LENGTH), Check::Any, "Z travel"),
                ]),
                Check::Any,
                "axis travel",
            ),
            MAX_FEED,
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a 3-axis mill: X, Y, Z",
    },
    Kind {
        name: "grinder_2axis",
        category: Category::Machine,
        params: &[DIALECT, OTHER_DIALECTS, RESOLUTION, LATHE_TRAVEL, MAX_FEED],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "a 2-axis (X, Z) grinder with a spherical wheel",
    },
    Kind {
        name: "fts_spiral",
        category: Category::Strategy,
        params: &[
            SPIRAL_FEED,
            SPIRAL_SPINDLE_SPEED,
            SURFACE_SPEED,
            SPINDLE_CAP,
            CHORD_TOLERANCE,
            SEED_ARC,
            opt(
                "settle",
                Ty::Word(&["auto", "none"]),
                Check::Any,
                "`auto` (default): hold the tool h_offset above the land so the servo settles before each lenslet (Hashimoto & Yan eqs 6-7); `none`: follow the land",
            ),
            opt(
                "settling_time",
                Ty::Quantity(&[Dim::TIME]),
                Check::Positive,
                "the servo's settling time for h_offset; default from the machine's servo model",
            ),
            SPIRAL_FROM,
            RETRACT,
        ],
        family: None,
        positional: &[],
        exclusive: &[(&["spindle_speed", "surface_speed"], true)],
        doc: "fast-tool-servo spiral turning: X and C on an Archimedean spiral, W carrying the surface",
    },
    Kind {
        name: "spiral_turning",
        category: Category::Strategy,
        params: &[
            SPIRAL_FEED,
            SPIRAL_SPINDLE_SPEED,
            SURFACE_SPEED,
            SPINDLE_CAP,
            CHORD_TOLERANCE,
            SEED_ARC,
            SPIRAL_FROM,
            RETRACT,
        ],
        family: None,
        positional: &[],
        exclusive: &[(&["spindle_speed", "surface_speed"], true)],
        doc: "spiral turning with a slow tool servo: X and C on an Archimedean spiral, Z following the surface",
    },
    Kind {
        name: "roller_helix",
        category: Category::Strategy,
        params: &[
            opt(
                "rough",
                Ty::Block(&[
                    req(
                        "c_step",
                        ANGLE,
                        Check::Positive,
                        "spindle angle between points",
                    ),
                    req(
                        "pitch",
                        LENGTH,
                        Check::Positive,
                        "axial feed per revolution",
                    ),
                    req(
                        "finish_allowance",
                        LENGTH,
                        Check::NonNegative,
                        "radial stock left for the finish pass",
                    ),
                ]),
                Check::Any,
                "the rough pass (Liu et al.: 1° and 0.1 mm)",
            ),
            req(
                "finish",
                Ty::Block(&[
                    req(
                        "c_step",
                        ANGLE,
                        Check::Positive,
                        "spindle angle between points",
                    ),
                    req(
                        "pitch",
                        LENGTH,
                        Check::Positive,
                        "axial feed per revolution",
                    ),
                ]),
                Check::Any,
                "the finish pass (Liu et al.: 0.1° and 5 µm)",
            ),
            opt(
                "z",
                Ty::Range(Dim::LENGTH),
                Check::Any,
                "axial range of the cut, in the design's x; default the whole design",
            ),
            req(
                "spindle_speed",
                Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
                Check::Positive,
                "spindle speed",
            ),
            opt(
                "blank_radius",
                LENGTH,
                Check::Positive,
                "radius of the roller blank; default the top of the design",
            ),
            RETRACT,
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "roller helix turning (Liu et al., seed 002): the wrapped design cut along a helix z = P·c/360, rough then finish",
    },
    Kind {
        name: "raster",
        category: Category::Strategy,
        params: &[
            req(
                "along",
                Ty::Word(&["x", "y"]),
                Check::Any,
                "the cutting direction",
            ),
            opt(
                "direction",
                Ty::Word(&["one_way", "zigzag"]),
                Check::Any,
                "one_way (default): every pass cut the same way; zigzag: alternate passes reversed",
            ),
            req(
                "stepover",
                LENGTH,
                Check::Positive,
                "distance between passes",
            ),
            CHORD_TOLERANCE,
            opt(
                "max_step",
                LENGTH,
                Check::Positive,
                "longest step along a pass",
            ),
            opt(
                "lin_angle",
                ANGLE,
                Check::HalfOpen(0.0, DEG90),
                "Lin's angle α: steps no longer than eqs 2-3 allow (2ρ sin(α/2) cos θ)",
            ),
            req(
                "feed",
                Ty::Quantity(&[Dim::SPEED]),
                Check::Positive,
                "cutting feed",
            ),
            RETRACT,
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "iso-plane raster: passes along x or y at a fixed stepover, the tool centre exact",
    },
    Kind {
        name: "profile_grinding",
        category: Category::Strategy,
        params: &[
            req(
                "interval",
                LENGTH,
                Check::Positive,
                "distance interval δ along x between commanded points",
            ),
            req(
                "feed",
                Ty::Quantity(&[Dim::SPEED]),
                Check::Positive,
                "feed v_f along x",
            ),
            req(
                "smoothness",
                NUMBER,
                Check::Open(0.0, 1.0),
                "γ: the share of each interval spent accelerating (Kim et al. eqs 17-19)",
            ),
            opt(
                "from",
                LENGTH,
                Check::Any,
                "x where grinding starts; default the centre",
            ),
            opt(
                "to",
                LENGTH,
                Check::Any,
                "x where grinding ends; default the aperture edge",
            ),
            RETRACT,
        ],
        family: None,
        positional: &[],
        exclusive: &[],
        doc: "profile grinding with a spherical wheel: position-based interpolation of Kim et al. (seed 001)",
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
            SPIRAL_SPINDLE_SPEED,
            SURFACE_SPEED,
            SPINDLE_CAP,
            opt(
                "chord_tolerance",
                LENGTH,
                Check::Positive,
                "the path's tolerance: the most the program, as the machine runs it, may stray from the exact tool-centre path; default 10 nm",
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
            opt(
                "search",
                Ty::Word(&["exact", "sequential", "binary"]),
                Check::Any,
                "how the nose-centre height is found: exact (default), or Lei et al.'s sequential or binary search over the discretised profile (reference methods)",
            ),
            opt(
                "search_spacing",
                LENGTH,
                Check::Positive,
                "profile discretisation of the sequential and binary searches; default 1 µm",
            ),
            opt(
                "search_step",
                LENGTH,
                Check::Positive,
                "descent step of the sequential search (default 10 nm) or final bracket of the binary search (default 1 nm)",
            ),
            opt(
                "stock_top",
                LENGTH,
                Check::Any,
                "the stock is flat, its face at this height: roughing passes take it down `depth_of_cut` at a time",
            ),
            opt(
                "stock_allowance",
                LENGTH,
                Check::Positive,
                "the stock is the design offset by this much along its normal: roughing passes take it down `depth_of_cut` at a time",
            ),
            opt(
                "depth_of_cut",
                LENGTH,
                Check::Positive,
                "most material one roughing pass removes; needed with a stock",
            ),
            opt(
                "finish_allowance",
                LENGTH,
                Check::NonNegative,
                "material the roughing passes leave for the finish pass; default 0",
            ),
        ],
        family: None,
        positional: &[],
        exclusive: &[
            (&["stock_top", "stock_allowance"], false),
            (&["spindle_speed", "surface_speed"], true),
        ],
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
    opt(
        "simulate",
        Ty::Block(&[
            req(
                "x",
                Ty::Range(Dim::LENGTH),
                Check::Any,
                "the window's extent in x",
            ),
            req(
                "y",
                Ty::Range(Dim::LENGTH),
                Check::Any,
                "the window's extent in y",
            ),
            opt(
                "spacing",
                LENGTH,
                Check::Positive,
                "the grid's spacing; default 1 um",
            ),
        ]),
        Check::Any,
        "the window of a surface job's height-map simulation (design x, y); default a 0.2 mm square where the surface is representative",
    ),
];

pub fn kind(name: &str) -> Option<&'static Kind> {
    KINDS.iter().find(|k| k.name == name)
}

/// Whether `name` is a word some parameter takes (`convex`, `linuxcnc`…):
/// such names cannot be declared, so `sense: convex` always means the word.
pub fn is_word(name: &str) -> bool {
    fn in_params(params: &[Param], name: &str) -> bool {
        params.iter().any(|p| match p.ty {
            Ty::Word(words) => words.contains(&name),
            Ty::Block(sub) => in_params(sub, name),
            _ => false,
        })
    }
    KINDS.iter().any(|k| in_params(k.params, name)) || in_params(JOB_PARAMS, name)
}
