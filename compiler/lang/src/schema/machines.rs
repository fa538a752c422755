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
};

pub(super) const STS_LATHE: Kind = Kind {
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
};

pub(super) const MILL_3AXIS: Kind = Kind {
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
};

pub(super) const GRINDER_2AXIS: Kind = Kind {
    name: "grinder_2axis",
    category: Category::Machine,
    params: &[DIALECT, OTHER_DIALECTS, RESOLUTION, LATHE_TRAVEL, MAX_FEED],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a 2-axis (X, Z) grinder with a spherical wheel",
};
