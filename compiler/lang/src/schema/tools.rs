//! The tools: turning inserts, the fast-tool-servo microshaper, ball-end
//! cutters and grinding wheels.

use super::{ANGLE, Category, Check, DEG90, Kind, LENGTH, Param, Ty, opt, req};

/// The words `control_point` takes.
pub const CONTROL_POINTS: &[&str] = &["tool_tip", "tool_centre"];

/// What the tool's length offset (and on a lathe its X offset) is
/// measured to, so the point the program's coordinates are.
const CONTROL_POINT: Param = opt(
    "control_point",
    Ty::Word(CONTROL_POINTS),
    Check::Any,
    "what the tool's offsets are measured to, the point the program's coordinates move: `tool_tip` (a mill's length to the lowest point of the ball or nose; a lathe's imaginary tip, the nose's -X and -Z sides touched off) or `tool_centre` (the ball's, nose's or wheel's centre); default `tool_tip` on a `mill_3axis` and a `lathe`, `tool_centre` on the servo lathes and the grinder (docs/language/machines-and-tools.md)",
);

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
        opt(
            "edge_profile",
            Ty::Text,
            Check::Any,
            "the edge as measured: a text file of angle (deg, from the tool's axis, + towards +X) and deviation from the nose circle (um, + proud) a line, relative to the job's file; profile turning offsets the path by R + δ at the angle of contact, spiral turning and the fast tool servo clear each ray's section with this edge, the roller helix each axial section (+ towards +Z, along the roller), and the simulation cuts with it (docs/language/edge-profile.md); default none, a perfect circle",
        ),
        CONTROL_POINT,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a round-nose diamond turning tool; its path is planned for its nose centre and programmed for its `control_point`",
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
        CONTROL_POINT,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "Lin's microshaper knife (seed 000): scrapes along the cut, rake face forward, its edge a nose arc across the cut",
};

pub(super) const BALL_END: Kind = Kind {
    name: "ball_end",
    category: Category::Tool,
    params: &[
        req("diameter", LENGTH, Check::Positive, "diameter of the ball"),
        CONTROL_POINT,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a ball-end mill; its path is planned for the ball's centre and programmed for its `control_point`",
};

pub(super) const SPHERICAL_WHEEL: Kind = Kind {
    name: "spherical_wheel",
    category: Category::Tool,
    params: &[
        req(
            "diameter",
            LENGTH,
            Check::Positive,
            "diameter D_t of the wheel's spherical tip",
        ),
        CONTROL_POINT,
    ],
    family: None,
    positional: &[],
    exclusive: &[],
    doc: "a spherical grinding wheel (seed 001); its path is planned for its centre and programmed for its `control_point`",
};

/// A tool's checked parameters, read once (every tool kind; what a kind
/// lacks is `None`).
#[derive(Clone, Debug)]
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
    /// `control_point: tool_tip` (true) or `tool_centre` (false), where stated.
    pub control_point: Option<crate::value::Stated<bool>>,
    /// A round nose's measured edge: the file as written, relative to the
    /// job's file.
    pub edge_profile: Option<crate::value::Stated<String>>,
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
            control_point: r
                .stated_word("control_point")
                .map(|w| crate::value::Stated {
                    value: w.value == "tool_tip",
                    site: w.site,
                }),
            edge_profile: r.field("edge_profile").and_then(|f| match &f.value {
                crate::value::Value::Str(s) => Some(crate::value::Stated {
                    value: s.clone(),
                    site: (f.file, f.span),
                }),
                _ => None,
            }),
        };
        r.finish(o.kind.name, (o.file, o.head))?;
        Ok(t)
    }
}
