//! The tools: turning inserts, the fast-tool-servo microshaper, ball-end
//! cutters and grinding wheels.

use super::{ANGLE, Category, Check, DEG90, Kind, LENGTH, opt, req};

pub(super) const ROUND_NOSE: Kind = Kind {
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
};

pub(super) const MICROSHAPER: Kind = Kind {
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
};

pub(super) const BALL_END: Kind = Kind {
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
};

pub(super) const SPHERICAL_WHEEL: Kind = Kind {
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
};
