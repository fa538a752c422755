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

/// A tool's checked parameters, read once (every tool kind; what a kind
/// lacks is `None`).
#[derive(Clone, Copy, Debug)]
pub struct ToolParams {
    /// The tool's kind (`round_nose`, `microshaper`, `ball_end`, …).
    pub kind: &'static str,
    /// Radius of the cutting edge's nose (a round nose, a knife) (mm).
    pub nose_radius: Option<f64>,
    /// Diameter of a ball-end mill's ball or a wheel's tip (mm).
    pub diameter: Option<f64>,
    /// Clearance angle of the flank (rad).
    pub clearance: Option<f64>,
    /// Rake angle (rad).
    pub rake: Option<f64>,
    /// Opening angle of the cutting edge (rad).
    pub included_angle: Option<f64>,
    /// Height of the edge above the spindle axis as set (mm).
    pub centre_height: Option<f64>,
}

impl ToolParams {
    /// Reads a checked tool (E0121 for a required parameter missing).
    pub fn read(o: &crate::value::Object) -> Result<ToolParams, lensc_grammar::Diagnostic> {
        let mut r = crate::value::Reader::new(&o.fields);
        // What the kind requires is read as required.
        let mut need = |name: &str| {
            let required = o.kind.param(name).is_some_and(|p| p.required);
            if required {
                Some(r.required_num(name))
            } else {
                r.num(name)
            }
        };
        let t = ToolParams {
            kind: o.kind.name,
            nose_radius: need("nose_radius"),
            diameter: need("diameter"),
            clearance: need("clearance"),
            rake: need("rake"),
            included_angle: need("included_angle"),
            centre_height: need("centre_height"),
        };
        r.finish(o.kind.name, (o.file, o.head))?;
        Ok(t)
    }
}
