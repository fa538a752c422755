//! The strategies: how a path is planned, with the parameters the spiral
//! strategies share.

use super::{ANGLE, Category, Check, DEG90, Kind, LENGTH, NUMBER, Param, Ty, opt, req};
use crate::units::Dim;

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
    "largest chord deviation from the exact tool-centre path; default 10 nm, or the smallest the machine's resolution holds (resolution × √axes, rounded up to a whole nm) where that is coarser",
);
const CHORDS: Param = opt(
    "chords",
    Ty::Word(&["on_path", "straddle", "straddle_long", "clear"]),
    Check::Any,
    "where the points sit across the curve: `on_path` (convex stretches gouge by up to the chords' sag), `straddle` (moved off the path so each chord errs by at most ±half the sag), `straddle_long` (chords sampled to twice the sag, about 1/√2 the points, each within ±the sag), `clear` (raised so no chord enters the material); default the one with the fewest points whose promised gouge, residual, PV and RMS meet the job's acceptance criteria (stated or default): `straddle_long` where its promise meets them on a servo spiral, else the first of on_path, straddle, clear that meets them all, else the first whose gouge meets `max_gouge`",
);
/// A roller helix's points are a fixed C step apart: no `straddle_long`.
const ROLLER_CHORDS: Param = opt(
    "chords",
    Ty::Word(&["on_path", "straddle", "clear"]),
    Check::Any,
    "where the points sit across the curve: `on_path` (convex stretches gouge by up to the chords' sag), `straddle` (moved off the path so each chord errs by at most ±half the sag), `clear` (raised so no chord enters the material); default the first of these whose promised gouge, residual, PV and RMS meet the job's acceptance criteria (stated or default), else the first whose gouge meets `max_gouge`",
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
    "radius where the spiral starts; default where the first revolution's contacts lie a feed beyond the aperture all round, never inside its outermost point",
);

pub(super) const FTS_SPIRAL: Kind = Kind {
    name: "fts_spiral",
    category: Category::Strategy,
    params: &[
        SPIRAL_FEED,
        SPIRAL_SPINDLE_SPEED,
        SURFACE_SPEED,
        SPINDLE_CAP,
        CHORD_TOLERANCE,
        CHORDS,
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
};

pub(super) const SPIRAL_TURNING: Kind = Kind {
    name: "spiral_turning",
    category: Category::Strategy,
    params: &[
        SPIRAL_FEED,
        SPIRAL_SPINDLE_SPEED,
        SURFACE_SPEED,
        SPINDLE_CAP,
        CHORD_TOLERANCE,
        CHORDS,
        SEED_ARC,
        SPIRAL_FROM,
        RETRACT,
    ],
    family: None,
    positional: &[],
    exclusive: &[(&["spindle_speed", "surface_speed"], true)],
    doc: "spiral turning with a slow tool servo: X and C on an Archimedean spiral, Z following the surface",
};

pub(super) const ROLLER_HELIX: Kind = Kind {
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
        ROLLER_CHORDS,
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
};

pub(super) const RASTER: Kind = Kind {
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
        CHORDS,
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
        opt(
            "spindle_speed",
            Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
            Check::Positive,
            "the cutter's spindle speed: required for a rotating cutter (`ball_end`); a `microshaper` knife cuts with the spindle held still and takes none",
        ),
        RETRACT,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "iso-plane raster: passes along x or y at a fixed stepover, the tool centre exact",
};

pub(super) const PROFILE_GRINDING: Kind = Kind {
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
        req(
            "spindle_speed",
            Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
            Check::Positive,
            "the work spindle's speed (the program's S word)",
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
};

/// Every strategy kind, in the order messages list them (the last of
/// `KINDS`): a strategy's schema entry is its constant and its line here.
pub(super) const ALL: &[Kind] = &[
    FTS_SPIRAL,
    SPIRAL_TURNING,
    ROLLER_HELIX,
    RASTER,
    PROFILE_GRINDING,
    PROFILE_TURNING,
];

pub(super) const PROFILE_TURNING: Kind = Kind {
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
            "the path's tolerance: the most the program, as the machine runs it, may stray from the exact tool-centre path; default 10 nm, or the smallest the machine's resolution holds (resolution × √axes, rounded up to a whole nm) where that is coarser",
        ),
        CHORDS,
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
            "clearance above the part for rapid moves between passes; each pass's approach rapids on down to 0.1 mm (or the retract, if less) over the part's top and feeds through the air to 0.1 mm over the material at its first point; default 1 mm",
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
        opt(
            "rough_feed",
            Ty::Quantity(&[Dim::FEED_PER_REV, Dim::SPEED]),
            Check::Positive,
            "the roughing passes' feed; needed with a stock",
        ),
        opt(
            "rough_spindle_speed",
            Ty::Quantity(&[Dim::ROTATIONAL_SPEED]),
            Check::Positive,
            "the roughing passes' constant spindle speed; default the finish's spindle (its speed, or its surface speed and cap)",
        ),
    ],
    family: None,
    positional: &[],
    exclusive: &[
        (&["stock_top", "stock_allowance"], false),
        (&["spindle_speed", "surface_speed"], true),
    ],
    doc: "one facing pass along the profile with the nose centre offset along the normal",
};

// The strategies' checked parameters, read once, one struct per kind
// (both spiral kinds share one). Each `read` is the only place its kind's
// parameters are named; a required one missing is E0121 from `finish`.

use crate::value::{Object, Reader, Stated};
use lensc_grammar::Diagnostic;

/// Where the points sit across the curve, and the path tolerance, as a
/// strategy states them (both optional).
#[derive(Clone, Copy, Debug, Default)]
pub struct PathParams {
    /// `chord_tolerance` (mm).
    pub chord_tolerance: Option<Stated<f64>>,
    /// `chords`: `on_path`, `straddle`, `straddle_long` or `clear`.
    pub chords: Option<Stated<&'static str>>,
}

impl PathParams {
    /// Reads the path parameters every strategy that has them shares.
    pub fn read(o: &Object) -> PathParams {
        path(&Reader::new(&o.fields))
    }
}

fn path(r: &Reader) -> PathParams {
    PathParams {
        chord_tolerance: r.stated_num("chord_tolerance"),
        chords: r.stated_word("chords").map(|w| Stated {
            value: static_word(CHORDS.ty, w.value),
            site: w.site,
        }),
    }
}

/// The schema's own `&'static` spelling of a checked word.
fn static_word(ty: Ty, word: &str) -> &'static str {
    match ty {
        Ty::Word(words) => words.iter().find(|w| **w == word).copied().unwrap_or(""),
        _ => "",
    }
}

fn finish<T>(r: Reader, o: &Object, value: T) -> Result<T, Diagnostic> {
    r.finish(o.kind.name, (o.file, o.head))?;
    Ok(value)
}

/// A feed as stated: per revolution (mm/rad) or per time (mm/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StatedFeed {
    PerRevolution(f64),
    PerTime(f64),
}

fn feed(r: &Reader, name: &str) -> Option<StatedFeed> {
    r.quantity(name).map(|(v, d)| {
        if d == Dim::FEED_PER_REV {
            StatedFeed::PerRevolution(v)
        } else {
            StatedFeed::PerTime(v)
        }
    })
}

/// `profile_turning`'s parameters.
#[derive(Clone, Copy, Debug)]
pub struct ProfileTurningParams {
    pub feed: Option<StatedFeed>,
    pub spindle_speed: Option<f64>,
    pub surface_speed: Option<f64>,
    pub spindle_cap: Option<f64>,
    pub from: Option<Stated<f64>>,
    pub to: Option<f64>,
    pub retract: Option<f64>,
    /// `search`: `exact`, `sequential` or `binary`.
    pub search: Option<&'static str>,
    pub search_spacing: Option<f64>,
    pub search_step: Option<f64>,
    pub stock_top: Option<f64>,
    pub stock_allowance: Option<f64>,
    pub depth_of_cut: Option<f64>,
    pub finish_allowance: Option<f64>,
    pub rough_feed: Option<StatedFeed>,
    pub rough_spindle_speed: Option<f64>,
}

impl ProfileTurningParams {
    pub fn read(o: &Object) -> Result<ProfileTurningParams, Diagnostic> {
        let r = Reader::new(&o.fields);
        let search_ty = PROFILE_TURNING.param("search").map(|p| p.ty);
        let v = ProfileTurningParams {
            feed: feed(&r, "feed"),
            spindle_speed: r.num("spindle_speed"),
            surface_speed: r.num("surface_speed"),
            spindle_cap: r.num("spindle_cap"),
            from: r.stated_num("from"),
            to: r.num("to"),
            retract: r.num("retract"),
            search: r
                .word("search")
                .zip(search_ty)
                .map(|(w, ty)| static_word(ty, w)),
            search_spacing: r.num("search_spacing"),
            search_step: r.num("search_step"),
            stock_top: r.num("stock_top"),
            stock_allowance: r.num("stock_allowance"),
            depth_of_cut: r.num("depth_of_cut"),
            finish_allowance: r.num("finish_allowance"),
            rough_feed: feed(&r, "rough_feed"),
            rough_spindle_speed: r.num("rough_spindle_speed"),
        };
        finish(r, o, v)
    }
}

/// The spiral strategies' parameters (`fts_spiral`, `spiral_turning`).
#[derive(Clone, Copy, Debug)]
pub struct SpiralParams {
    /// Radial feed per revolution (mm/rad).
    pub feed: f64,
    pub spindle_speed: Option<f64>,
    pub surface_speed: Option<f64>,
    pub spindle_cap: Option<f64>,
    pub seed_arc: Option<f64>,
    /// `settle` (`fts_spiral` only): `auto` or `none`.
    pub settle: Option<&'static str>,
    pub settling_time: Option<f64>,
    pub from: Option<f64>,
    pub retract: Option<f64>,
}

impl SpiralParams {
    pub fn read(o: &Object) -> Result<SpiralParams, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let settle_ty = FTS_SPIRAL.param("settle").map(|p| p.ty);
        let v = SpiralParams {
            feed: r.required_num("feed"),
            spindle_speed: r.num("spindle_speed"),
            surface_speed: r.num("surface_speed"),
            spindle_cap: r.num("spindle_cap"),
            seed_arc: r.num("seed_arc"),
            settle: r
                .word("settle")
                .zip(settle_ty)
                .map(|(w, ty)| static_word(ty, w)),
            settling_time: r.num("settling_time"),
            from: r.num("from"),
            retract: r.num("retract"),
        };
        finish(r, o, v)
    }
}

/// `raster`'s parameters.
#[derive(Clone, Copy, Debug)]
pub struct RasterParams {
    /// Along y (else along x).
    pub along_y: bool,
    pub zigzag: bool,
    pub stepover: f64,
    pub max_step: Option<f64>,
    pub lin_angle: Option<f64>,
    /// Cutting feed (mm/s).
    pub feed: f64,
    pub spindle_speed: Option<Stated<f64>>,
    pub retract: Option<f64>,
}

impl RasterParams {
    pub fn read(o: &Object) -> Result<RasterParams, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let v = RasterParams {
            along_y: r.word("along") == Some("y"),
            zigzag: r.word("direction") == Some("zigzag"),
            stepover: r.required_num("stepover"),
            max_step: r.num("max_step"),
            lin_angle: r.num("lin_angle"),
            feed: r.required_num("feed"),
            spindle_speed: r.stated_num("spindle_speed"),
            retract: r.num("retract"),
        };
        finish(r, o, v)
    }
}

/// `profile_grinding`'s parameters.
#[derive(Clone, Copy, Debug)]
pub struct ProfileGrindingParams {
    pub interval: f64,
    /// Feed (mm/s).
    pub feed: f64,
    pub smoothness: f64,
    pub spindle_speed: f64,
    pub from: Option<f64>,
    pub to: Option<f64>,
    pub retract: Option<f64>,
}

impl ProfileGrindingParams {
    pub fn read(o: &Object) -> Result<ProfileGrindingParams, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let v = ProfileGrindingParams {
            interval: r.required_num("interval"),
            feed: r.required_num("feed"),
            smoothness: r.required_num("smoothness"),
            spindle_speed: r.required_num("spindle_speed"),
            from: r.num("from"),
            to: r.num("to"),
            retract: r.num("retract"),
        };
        finish(r, o, v)
    }
}

/// One pass of a roller helix: its C step (rad) and pitch (mm per rev).
#[derive(Clone, Copy, Debug)]
pub struct HelixPassParams {
    pub c_step: f64,
    pub pitch: f64,
}

/// `roller_helix`'s parameters.
#[derive(Clone, Copy, Debug)]
pub struct RollerHelixParams {
    /// The rough pass and the radial stock it leaves for the finish.
    pub rough: Option<(HelixPassParams, f64)>,
    pub finish: HelixPassParams,
    /// Axial range of the cut (mm, the design's x).
    pub z: Option<(f64, f64)>,
    pub spindle_speed: f64,
    pub blank_radius: Option<f64>,
    pub retract: Option<f64>,
}

impl RollerHelixParams {
    pub fn read(o: &Object) -> Result<RollerHelixParams, Diagnostic> {
        let mut r = Reader::new(&o.fields);
        let pass = |b: &mut Reader| HelixPassParams {
            c_step: b.required_num("c_step"),
            pitch: b.required_num("pitch"),
        };
        let v = RollerHelixParams {
            rough: r.block("rough", |b| (pass(b), b.required_num("finish_allowance"))),
            finish: r.required_block("finish", pass),
            z: r.range("z"),
            spindle_speed: r.required_num("spindle_speed"),
            blank_radius: r.num("blank_radius"),
            retract: r.num("retract"),
        };
        finish(r, o, v)
    }
}
