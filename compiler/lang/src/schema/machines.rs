//! The machines: lathes (with fast and slow tool servos), mills and
//! grinders, with the limits every program must keep.

use super::{Category, Check, Kind, LENGTH, NUMBER, Param, Ty, opt, req};
use crate::units::Dim;

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
/// How programs reach the control (`delivery { … }`): what it holds, the
/// largest file it runs, and the link that brings the program and how
/// fast. A machine that states none is held only to the build's
/// `--max-program-size` (4 GB by default) and its programs are never
/// split (`compiler/builder/src/delivery.rs`).
const DELIVERY: Param = opt(
    "delivery",
    Ty::Block(&[
        opt(
            "link",
            Ty::Word(&["memory", "disk", "dnc", "data_server"]),
            Check::Any,
            "how the program reaches the control: `memory` (loaded whole into the control's memory before it runs: it must fit `memory`), `disk` (read from the control's own disk as it runs, as LinuxCNC and PC-based controls do: no memory or rate limit), `dnc` (streamed over a serial link at `baud`), `data_server` (streamed from an Ethernet data server, e.g. Fanuc's Fast Data Server in buffer mode or Sinumerik EXTCALL, at `rate`); default memory",
        ),
        opt(
            "memory",
            NUMBER,
            Check::Positive,
            "bytes of program the control holds (with `link: memory`, the largest program it can run whole); default no limit",
        ),
        opt(
            "file_limit",
            NUMBER,
            Check::Positive,
            "bytes of the largest program file the control runs (a data server's buffer-mode file, a file system's limit); a larger program is split into parts a main program calls; default no limit",
        ),
        opt(
            "baud",
            NUMBER,
            Check::Positive,
            "a serial DNC link's baud rate (bits per second; 10 bits a byte: start, 8 data, stop); the link's byte rate is baud / 10 unless `rate` states it",
        ),
        opt(
            "rate",
            NUMBER,
            Check::Positive,
            "bytes per second the link delivers to the control (`dnc`, `data_server`); a program consuming more while it cuts is warned of (W0050); default baud / 10 for `dnc`, none (unchecked) otherwise",
        ),
        opt(
            "buffer",
            NUMBER,
            Check::Positive,
            "bytes of program the control holds ahead of the block it runs, filled by a streaming link: a stretch of short blocks that asks more bytes a second than the link delivers runs on this buffer, and one that would empty it is warned of (W0050); default 4096 (an assumption: see the Delivery page)",
        ),
    ]),
    Check::Any,
    "how programs reach the control: memory, file-size limit, link and its byte rate (see the language guide's Delivery page); default none stated: programs are held to `--max-program-size` only",
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

pub(super) const LATHE: Kind = Kind {
    name: "lathe",
    category: Category::Machine,
    params: &[
        DIALECT,
        OTHER_DIALECTS,
        DELIVERY,
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
};

pub(super) const FTS_LATHE: Kind = Kind {
    name: "fts_lathe",
    category: Category::Machine,
    params: &[
        DIALECT,
        OTHER_DIALECTS,
        DELIVERY,
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
                opt(
                    "feed_forward",
                    Ty::Word(&["none", "inverse_model"]),
                    Check::Any,
                    "whether the controller leads the servo: `inverse_model` (it feeds the commanded velocity and acceleration forward through the servo's inverse model, so the servo follows the commanded path) or `none` (it does not: lensc writes the pre-compensated command, the inverse model applied to the path, and judges the servo unled on it); default none",
                ),
                opt(
                    "letter",
                    Ty::Word(&["U", "V", "W"]),
                    Check::Any,
                    "the axis letter the control gives the servo, its own axis beside the slides (with `max_velocity`): a dialect that programs the fast axis as moves (LinuxCNC) writes the servo's motion on this letter and holds the Z slide still, the tool tip at Z plus the servo; without it the servo's motion is written on Z and held to the machine's `max_feed`",
                ),
                opt(
                    "max_velocity",
                    Ty::Quantity(&[Dim::SPEED]),
                    Check::Positive,
                    "the servo's velocity limit as its own axis (with `letter`; LinuxCNC's `[AXIS_W] MAX_VELOCITY`): no move may drive the servo faster",
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
};

pub(super) const STS_LATHE: Kind = Kind {
    name: "sts_lathe",
    category: Category::Machine,
    params: &[
        DIALECT,
        OTHER_DIALECTS,
        DELIVERY,
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
};

pub(super) const MILL_3AXIS: Kind = Kind {
    name: "mill_3axis",
    category: Category::Machine,
    params: &[
        DIALECT,
        OTHER_DIALECTS,
        DELIVERY,
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
};

pub(super) const GRINDER_2AXIS: Kind = Kind {
    name: "grinder_2axis",
    category: Category::Machine,
    params: &[
        DIALECT,
        OTHER_DIALECTS,
        DELIVERY,
        RESOLUTION,
        LATHE_TRAVEL,
        MAX_FEED,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a 2-axis (X, Z) grinder with a spherical wheel",
};

/// A machine's checked parameters, read once (every machine kind; what a
/// kind lacks is `None`): the limits every program must keep. The dialects
/// are chosen by `lower::dialect`.
#[derive(Clone, Debug)]
pub struct MachineParams {
    /// The machine's kind (`lathe`, `fts_lathe`, `mill_3axis`, …).
    pub kind: &'static str,
    /// Smallest programmable step (mm).
    pub resolution: f64,
    /// Fastest cutting feed (mm/s).
    pub max_feed: f64,
    /// The work spindle's limit (rad/s), where the machine has one to
    /// state (a lathe's; a mill's and a grinder's state none).
    pub max_spindle_speed: Option<f64>,
    /// X, Y, Z and C travel where the machine states one (mm, rad).
    pub travel: [Option<(f64, f64)>; 4],
    /// A fast-tool-servo lathe's W axis.
    pub fast_axis: Option<FastAxisParams>,
    /// A slow-tool-servo lathe's Z, which follows the surface.
    pub z_axis: Option<ZAxisParams>,
    /// How programs reach the control, if the machine states it.
    pub delivery: Option<DeliveryParams>,
}

/// How programs reach the control (`delivery { … }`), as stated, each
/// with where the file states it (for the messages about it).
#[derive(Clone, Copy, Debug)]
pub struct DeliveryParams {
    /// `memory`, `disk`, `dnc` or `data_server` (default `memory`).
    pub link: crate::value::Stated<&'static str>,
    /// Bytes the control holds.
    pub memory: Option<crate::value::Stated<f64>>,
    /// Bytes of the largest file the control runs.
    pub file_limit: Option<crate::value::Stated<f64>>,
    /// A serial link's baud rate (bits per second).
    pub baud: Option<crate::value::Stated<f64>>,
    /// Bytes per second the link delivers, as stated.
    pub rate: Option<crate::value::Stated<f64>>,
    /// Bytes the control holds ahead of the block it runs, as stated.
    pub buffer: Option<crate::value::Stated<f64>>,
}

/// A fast tool servo (`fast_axis { … }`) and its second-order model.
#[derive(Clone, Copy, Debug)]
pub struct FastAxisParams {
    pub stroke: f64,
    pub max_acceleration: f64,
    pub resonance: Option<f64>,
    pub resonant_peak: Option<f64>,
    pub natural_frequency: Option<f64>,
    pub damping: Option<f64>,
    /// Rate at which the servo takes positions (Hz).
    pub data_rate: Option<f64>,
    /// Settling band as a fraction of the step.
    pub settling_band: Option<f64>,
    /// The controller leads the servo by its inverse model
    /// (`feed_forward: inverse_model`); otherwise (`none`, the default)
    /// the program must.
    pub controller_leads: bool,
    /// The servo's own axis letter (upper case) and velocity limit (mm/s),
    /// where the control programs it as an axis of its own (`letter`,
    /// `max_velocity`); `None`: the servo's motion is written on Z.
    pub own_axis: Option<(char, f64)>,
}

/// A slow tool servo's Z (`z_axis { … }`).
#[derive(Clone, Copy, Debug)]
pub struct ZAxisParams {
    pub max_acceleration: f64,
    /// Rate at which the controller takes positions (Hz).
    pub data_rate: Option<f64>,
}

impl MachineParams {
    /// Reads a checked machine (E0121 for a required parameter missing).
    pub fn read(o: &crate::value::Object) -> Result<MachineParams, lensc_grammar::Diagnostic> {
        let mut r = crate::value::Reader::new(&o.fields);
        let m = MachineParams {
            kind: o.kind.name,
            resolution: r.required_num("resolution"),
            max_feed: r.required_num("max_feed"),
            max_spindle_speed: r.block("spindle", |s| s.required_num("max_speed")),
            travel: r
                .block("travel", |t| ["x", "y", "z", "c"].map(|a| t.range(a)))
                .unwrap_or([None; 4]),
            fast_axis: r.block("fast_axis", |f| FastAxisParams {
                stroke: f.required_num("stroke"),
                max_acceleration: f.required_num("max_acceleration"),
                resonance: f.num("resonance"),
                resonant_peak: f.num("resonant_peak"),
                natural_frequency: f.num("natural_frequency"),
                damping: f.num("damping"),
                data_rate: f.num("data_rate"),
                settling_band: f.num("settling_band"),
                controller_leads: f.word("feed_forward") == Some("inverse_model"),
                own_axis: f
                    .word("letter")
                    .and_then(|l| l.chars().next())
                    .map(|l| l.to_ascii_uppercase())
                    .zip(f.num("max_velocity")),
            }),
            z_axis: r.block("z_axis", |z| ZAxisParams {
                max_acceleration: z.required_num("max_acceleration"),
                data_rate: z.num("data_rate"),
            }),
            delivery: {
                let site = r.site("delivery").unwrap_or((o.file, o.head));
                r.block("delivery", |d| DeliveryParams {
                    link: d
                        .stated_word("link")
                        .map(|w| crate::value::Stated {
                            value: link_word(w.value),
                            site: w.site,
                        })
                        .unwrap_or(crate::value::Stated {
                            value: "memory",
                            site,
                        }),
                    memory: d.stated_num("memory"),
                    file_limit: d.stated_num("file_limit"),
                    baud: d.stated_num("baud"),
                    rate: d.stated_num("rate"),
                    buffer: d.stated_num("buffer"),
                })
            },
        };
        r.finish(o.kind.name, (o.file, o.head))?;
        Ok(m)
    }
}

/// The link word as the schema's own `'static` word (the checker allows
/// no other; anything else reads as `memory`, the default).
fn link_word(w: &str) -> &'static str {
    ["memory", "disk", "dnc", "data_server"]
        .into_iter()
        .find(|l| *l == w)
        .unwrap_or("memory")
}
