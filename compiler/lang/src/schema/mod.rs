//! The built-in kinds a `.lens` file constructs (`conic { … }`,
//! `round_nose { … }`, `circle(diameter: …)`): for each, its parameters with
//! their dimension, whether they are required and what range is allowed.
//! The checker validates every block against these tables.
//!
//! Beside each kind, the typed struct its parameters are read into, once
//! (`Surface::read`, `Aperture::read`, `Gcode::read`): the only place a
//! checked parameter is looked up by its name.
//!
//! This file holds the lookups (the types of the tables are in `kind`,
//! which knows no kind, so a value can name its kind); the kinds live
//! by category: `surfaces` (one formula each), `composite` (surfaces made
//! of others), `coefficients` (the `A4`, `X2Y1`, `Z11`, `Q3` families),
//! `apertures`, `tools`, `machines`, `dialects` and `strategies`.

use std::collections::HashSet;
use std::rc::Rc;
use std::sync::OnceLock;

use lensc_grammar::Diagnostic;

use crate::units::Dim;
use crate::value::{Object, Reader};

pub mod kind;

pub use kind::{ANGLE, Category, Check, Family, Kind, LENGTH, NUMBER, Param, Ty};
use kind::{DEG90, opt, req};

mod apertures;
mod coefficients;
mod composite;
mod dialects;
pub mod machines;
pub mod strategies;
mod surfaces;
pub mod tools;

pub use apertures::Aperture;
pub use coefficients::{
    FORBES_TOP, POWER_COEFFICIENTS, QBFS_COEFFICIENTS, QCON_COEFFICIENTS, XY_COEFFICIENTS,
    ZERNIKE_COEFFICIENTS, xy_powers,
};
pub use composite::{Array, Layout, OffAxis, Revolve, Roller, Surface, Tilt, Wrap};
pub use dialects::{Gcode, Line, OfferedDialect, offered_dialects};
pub use surfaces::{
    Axis, Base, Biconic, Conic, Cylinder, Ellipsoid, Facing, Forbes, Freeform, Ordering, Plane,
    Toroid, XyPolynomial, Zernike,
};

/// E0121 for a required parameter `name` that `o` lacks (worded as
/// `Reader::finish` words it): what a kind's `read` returns for a
/// parameter the checker should have refused to leave out.
fn missing(o: &Object, name: &str) -> Diagnostic {
    Diagnostic::error(
        crate::codes::MISSING_PARAMETER,
        format!("`{}` is missing `{name}`", o.kind.name),
        o.file,
        o.head,
    )
    .with_label("here")
}

/// E0124: `o`, read as `what` (`an aperture`), is not one.
fn not_a(o: &Object, what: &str) -> Diagnostic {
    Diagnostic::error(
        crate::codes::WRONG_KIND,
        format!("`{}` is not {what}", o.kind.name),
        o.file,
        o.head,
    )
    .with_label("here")
}

/// E0121 for whatever required parameter `r` found missing in `o`.
fn finish(r: Reader, o: &Object) -> Result<(), Diagnostic> {
    r.finish(o.kind.name, (o.file, o.head))
}

/// The required object `name` of `o`, or its E0121.
fn required_object<'a>(
    r: &Reader<'a>,
    o: &Object,
    name: &str,
) -> Result<&'a Rc<Object>, Diagnostic> {
    r.object(name).ok_or_else(|| missing(o, name))
}

/// The required range `name` of `o`, or its E0121.
fn required_range(r: &Reader, o: &Object, name: &str) -> Result<(f64, f64), Diagnostic> {
    r.range(name).ok_or_else(|| missing(o, name))
}

/// Every kind but the strategies, in the order messages list them.
const PART_KINDS: &[Kind] = &[
    dialects::GCODE,
    surfaces::PLANE,
    surfaces::SPHERE,
    surfaces::CONIC,
    surfaces::ASPHERE,
    surfaces::CYLINDER,
    surfaces::ACYLINDER,
    surfaces::BICONIC,
    surfaces::TOROID,
    surfaces::ELLIPSOID,
    surfaces::XY_POLYNOMIAL,
    surfaces::ZERNIKE,
    surfaces::QBFS,
    surfaces::QCON,
    surfaces::FREEFORM,
    composite::WRAP,
    composite::OFF_AXIS,
    composite::REVOLVE,
    composite::GRID,
    composite::HEX_GRID,
    composite::LINEAR_ARRAY,
    composite::TILT,
    composite::ROLLER,
    apertures::CIRCLE,
    apertures::ANNULUS,
    apertures::RECT,
    tools::ROUND_NOSE,
    machines::LATHE,
    tools::MICROSHAPER,
    tools::BALL_END,
    tools::SPHERICAL_WHEEL,
    machines::FTS_LATHE,
    machines::STS_LATHE,
    machines::MILL_3AXIS,
    machines::GRINDER_2AXIS,
];

const KIND_COUNT: usize = PART_KINDS.len() + strategies::ALL.len();

/// Every kind, in the order messages list them: the parts', then the
/// strategies' (`strategies::ALL`, so a strategy is declared in one file).
pub static KINDS: &[Kind] = &concat::<KIND_COUNT>(PART_KINDS, strategies::ALL);

/// `a` then `b`, as one array of `N` (their lengths' sum) kinds.
const fn concat<const N: usize>(a: &[Kind], b: &[Kind]) -> [Kind; N] {
    let mut out = [a[0]; N];
    let mut i = 0;
    while i < N {
        out[i] = if i < a.len() { a[i] } else { b[i - a.len()] };
        i += 1;
    }
    out
}

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
            opt(
                "x",
                Ty::Range(Dim::LENGTH),
                Check::Any,
                "the window's extent in x; the whole part's when left out",
            ),
            opt(
                "y",
                Ty::Range(Dim::LENGTH),
                Check::Any,
                "the window's extent in y; the whole part's when left out",
            ),
            opt(
                "spacing",
                LENGTH,
                Check::Positive,
                "the grid's spacing; default 1 um",
            ),
        ]),
        Check::Any,
        "the window of a surface job's height-map simulation (design x, y); `simulate: { spacing: 2 um }` sets the whole part's spacing; default the whole part, at the finest spacing within its budget of cells",
    ),
    opt(
        "tool_number",
        NUMBER,
        Check::Count,
        "the tool's number in the machine's turret, magazine or tool table (the program's T word); default 1",
    ),
    opt(
        "tool_offset",
        NUMBER,
        Check::Count,
        "the tool's offset register (Fanuc's second T pair, H; Siemens' D); default the tool number",
    ),
    opt(
        "spindle_direction",
        Ty::Word(&["cw", "ccw"]),
        Check::Any,
        "which way the spindle turns, as M3 (`cw`, default) and M4 (`ccw`) name it: the way that brings the work into the tool's rake face as it is set up",
    ),
    opt(
        "coolant",
        Ty::Word(&["flood", "mist", "off"]),
        Check::Any,
        "coolant through the whole program: `flood` (M8), `mist` (M7) or `off` (default)",
    ),
    opt(
        "interpolation",
        Ty::Word(&["lines_arcs", "spline"]),
        Check::Any,
        "how the program moves the tool between planned points: `lines_arcs` (straight moves and arcs) or `spline` (the controller's own spline, fitted within the path tolerance's share, where its dialect has one: E0182 where not); default the dialect's (`lines_arcs` in every standard dialect)",
    ),
    opt(
        "compensate",
        Ty::Block(COMPENSATE_PARAMS),
        Check::Any,
        "cut a corrected surface from a measurement of the part this job cut: the design less `gain` times the measured error, registered to the design and smoothed over `smoothing` (docs/usage/compensate.md); default none, the design as it is",
    ),
    opt(
        "accept",
        Ty::BlockOr(ACCEPT_PARAMS, &["none"]),
        Check::Any,
        "the acceptance criteria the simulated part must meet for the program to be written, or `none`; each left out has a default from the machine: its held tolerance (10 nm, or the smallest the machine holds where coarser; the strategy's `chord_tolerance` where tighter) and its resolution, which no looser tolerance or feed widens (docs/language/acceptance.md)",
    ),
];

/// The parameters of a job's `compensate` block.
pub static COMPENSATE_PARAMS: &[Param] = &[
    req(
        "measurement",
        Ty::Text,
        Check::Any,
        "the measured part's file (X3P, SDF, MetroPro, x y z points, an x z profile), relative to the job's file and read under the project root like a `use`d file",
    ),
    req(
        "gain",
        NUMBER,
        Check::Open(0.0, 2.0),
        "the share of the measured error taken out of the next cut (1: all of it; below 1 approaches in steps, above 1 over-corrects)",
    ),
    req(
        "smoothing",
        LENGTH,
        Check::Positive,
        "the shortest period of error the correction follows: the fitted polynomials' order is the aperture's width over it (at most 12)",
    ),
    opt(
        "units",
        Ty::Word(&["mm", "um", "nm"]),
        Check::Any,
        "what a plain-text measurement's numbers are (a text file carries no unit); default mm",
    ),
];

/// A job's `compensate` block, read once.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensateParams {
    /// The measurement file as written, relative to the job's file.
    pub measurement: crate::value::Stated<String>,
    pub gain: f64,
    /// The smoothing length (mm).
    pub smoothing: f64,
    /// mm per unit of a plain-text file's numbers.
    pub units: f64,
}

/// A job's own checked parameters beyond its four parts, read once.
#[derive(Clone, Debug)]
pub struct JobParams {
    pub tool_number: Option<crate::value::Stated<f64>>,
    pub tool_offset: Option<crate::value::Stated<f64>>,
    /// `spindle_direction: ccw` (else clockwise).
    pub spindle_ccw: bool,
    /// `coolant`: `flood`, `mist` or `off`.
    pub coolant: Option<crate::value::Stated<&'static str>>,
    /// The `simulate` block, with where it was written.
    pub simulate: Option<crate::value::Stated<SimulateParams>>,
    /// Where the job names its surface, tool, machine and strategy.
    pub part_sites: PartSites,
    /// The `accept` block as written.
    pub accept: AcceptParams,
    /// `interpolation: spline` (true) or `lines_arcs` (false), with where;
    /// none: the dialect's default.
    pub interpolation: Option<crate::value::Stated<bool>>,
    /// The `compensate` block, with where it was written.
    pub compensate: Option<crate::value::Stated<CompensateParams>>,
}

/// A job's `accept`, as written: none (the defaults), `none`, or a block.
#[derive(Clone, Debug, Default)]
pub enum AcceptParams {
    #[default]
    Defaults,
    Nothing,
    /// Each criterion the block states (its name, its value and dimension,
    /// where), in the schema's order, and where the block is.
    Stated {
        criteria: Vec<(&'static str, crate::value::Stated<(f64, Dim)>)>,
        site: (lensc_grammar::FileId, lensc_grammar::ast::Span),
    },
}

/// Where a job names each of its four parts (for a message about one).
#[derive(Clone, Copy, Debug, Default)]
pub struct PartSites {
    pub surface: Option<(lensc_grammar::FileId, lensc_grammar::ast::Span)>,
    pub tool: Option<(lensc_grammar::FileId, lensc_grammar::ast::Span)>,
    pub machine: Option<(lensc_grammar::FileId, lensc_grammar::ast::Span)>,
    pub strategy: Option<(lensc_grammar::FileId, lensc_grammar::ast::Span)>,
}

/// A job's `simulate { x: …, y: …, spacing: … }` window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimulateParams {
    pub x: Option<(f64, f64)>,
    pub y: Option<(f64, f64)>,
    pub spacing: Option<f64>,
}

impl JobParams {
    /// Reads a checked job's own fields.
    pub fn read(fields: &[crate::value::Field]) -> JobParams {
        let mut r = Reader::new(fields);
        let coolant_ty = JOB_PARAMS
            .iter()
            .find(|p| p.name == "coolant")
            .map(|p| p.ty);
        JobParams {
            tool_number: r.stated_num("tool_number"),
            tool_offset: r.stated_num("tool_offset"),
            spindle_ccw: r.word("spindle_direction") == Some("ccw"),
            coolant: r.stated_word("coolant").map(|w| crate::value::Stated {
                value: match coolant_ty {
                    Some(Ty::Word(words)) => words
                        .iter()
                        .find(|x| **x == w.value)
                        .copied()
                        .unwrap_or("off"),
                    _ => "off",
                },
                site: w.site,
            }),
            simulate: r.site("simulate").and_then(|site| {
                r.block("simulate", |b| SimulateParams {
                    x: b.range("x"),
                    y: b.range("y"),
                    spacing: b.num("spacing"),
                })
                .map(|value| crate::value::Stated { value, site })
            }),
            accept: match (r.site("accept"), r.word("accept")) {
                (None, _) => AcceptParams::Defaults,
                (Some(_), Some("none")) => AcceptParams::Nothing,
                (Some(site), _) => r
                    .block("accept", |b| AcceptParams::Stated {
                        criteria: ACCEPT_PARAMS
                            .iter()
                            .filter_map(|c| {
                                let (value, at) = (b.quantity(c.name)?, b.site(c.name)?);
                                Some((c.name, crate::value::Stated { value, site: at }))
                            })
                            .collect(),
                        site,
                    })
                    .unwrap_or_default(),
            },
            interpolation: r
                .stated_word("interpolation")
                .map(|w| crate::value::Stated {
                    value: w.value == "spline",
                    site: w.site,
                }),
            compensate: r.site("compensate").and_then(|site| {
                let stated = r.block("compensate", |b| {
                    let measurement = b.field("measurement").and_then(|f| match &f.value {
                        crate::value::Value::Str(s) => Some(crate::value::Stated {
                            value: s.clone(),
                            site: (f.file, f.span),
                        }),
                        _ => None,
                    })?;
                    Some(CompensateParams {
                        measurement,
                        gain: b.num("gain")?,
                        smoothing: b.num("smoothing")?,
                        units: match b.word("units") {
                            Some("um") => 1e-3,
                            Some("nm") => 1e-6,
                            _ => 1.0,
                        },
                    })
                })??;
                Some(crate::value::Stated {
                    value: stated,
                    site,
                })
            }),
            part_sites: PartSites {
                surface: r.site("surface"),
                tool: r.site("tool"),
                machine: r.site("machine"),
                strategy: r.site("strategy"),
            },
        }
    }
}

/// The criteria of a job's `accept` block: each a limit on a figure of
/// the simulated part (docs/language/acceptance.md says how each is
/// measured and how its default is derived).
pub static ACCEPT_PARAMS: &[Param] = &[
    opt(
        "form_pv",
        LENGTH,
        Check::NonNegative,
        "the largest peak-to-valley form error (largest minus least of cut − design at the contacts); default 2 × (held tolerance + resolution)",
    ),
    opt(
        "form_rms",
        LENGTH,
        Check::NonNegative,
        "the largest RMS form error, about its mean, at the contacts; default (held tolerance + resolution) / 2",
    ),
    opt(
        "max_gouge",
        LENGTH,
        Check::NonNegative,
        "the deepest cut below the design allowed anywhere; default held tolerance + resolution",
    ),
    opt(
        "max_residual",
        LENGTH,
        Check::NonNegative,
        "the most material allowed above the design at the contacts (scallops apart); default held tolerance + resolution",
    ),
    opt(
        "uncut_area",
        Ty::Quantity(&[Dim::AREA, Dim::NONE]),
        Check::NonNegative,
        "the most area left uncut: an area (`0.01 mm^2`), or a plain number, a fraction of the area simulated (`0`, `0.001`); default 0",
    ),
    opt(
        "max_following_error",
        LENGTH,
        Check::NonNegative,
        "the largest following error of the fast tool servo's model (jobs with a servo model; its lag cuts the part where the commands do not show it); default held tolerance + resolution",
    ),
    opt(
        "max_cutting_time",
        Ty::Quantity(&[Dim::TIME]),
        Check::NonNegative,
        "the longest estimated cutting time",
    ),
];

pub fn kind(name: &str) -> Option<&'static Kind> {
    KINDS.iter().find(|k| k.name == name)
}

/// Whether `name` is a word some parameter takes (`convex`, `linuxcnc`…):
/// such names cannot be declared, so `sense: convex` always means the word.
/// Asked once per declared name: the words are gathered into a set once.
pub fn is_word(name: &str) -> bool {
    fn gather(params: &'static [Param], into: &mut HashSet<&'static str>) {
        for p in params {
            match p.ty {
                Ty::Word(words) => into.extend(words.iter().copied()),
                Ty::Block(sub) => gather(sub, into),
                Ty::BlockOr(sub, words) => {
                    gather(sub, into);
                    into.extend(words.iter().copied());
                }
                _ => {}
            }
        }
    }
    static WORDS: OnceLock<HashSet<&'static str>> = OnceLock::new();
    WORDS
        .get_or_init(|| {
            let mut words = HashSet::new();
            for k in KINDS {
                gather(k.params, &mut words);
            }
            gather(JOB_PARAMS, &mut words);
            words
        })
        .contains(name)
}
