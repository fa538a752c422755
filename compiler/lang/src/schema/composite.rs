//! Surfaces made of other surfaces: a design wrapped onto a roller, an
//! off-axis section, a profile revolved, arrays of lenslets, a tilted surface.

use super::surfaces::APERTURE;
use super::{ANGLE, Category, Check, Kind, LENGTH, NUMBER, Param, Ty, opt, req};

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
            "`keep` (default) the parent's slope at the centre, or `remove` it (the section mounted square to the spindle, small-angle)",
        ),
        APERTURE,
    ],
    family: None,
    positional: &["parent"],
    exclusive: &[],
    doc: "an off-axis section of a parent surface, in coordinates centred on (x, y), its height zero there",
};

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
