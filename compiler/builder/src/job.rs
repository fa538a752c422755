//! Lowering a checked job to its typed `JobSpec`: one variant per strategy,
//! each with typed fields (numbers in mm, rad and s, enums for choices, the
//! dialect resolved, the surface lowered, the parts' names for the
//! header). Arguments become typed values here, once; no builder looks a
//! parameter up by its name. Everything that can be known without
//! planning is checked here — a strategy on a machine or with a tool that
//! cannot run it, a dialect the machine does not offer or that cannot
//! print its resolution, a tool larger than the surface's smallest concave
//! radius of curvature, a knife's clearance below the slope along the
//! cut, a feed or spindle speed above the machine's limit, a simulation
//! window too fine (`window.rs`) — so `lensc check` reports it as `lensc
//! build` does. Every error found is returned together.

pub mod accept;
pub mod chords;
pub mod estimate;
pub mod interpolation;
pub mod tolerance;
pub mod travel;
pub mod window;

pub use estimate::{DEFAULT_MAX_PROGRAM_SIZE, Estimate, Limits, MAX_POINTS, refusals};

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::moves::{ControlOffset, Coolant, Rotation, Start};
use lensc_runtime::post::{Dialect, Setup};
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};

use crate::diagnostics::RuntimeError;
use lensc_lang::check::CheckedJob;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::surface::LoweredSurface;
use lensc_lang::schema::machines::MachineParams;
use lensc_lang::schema::strategies::PathParams;
use lensc_lang::schema::tools::ToolParams;
use lensc_lang::schema::{JobParams, Surface};
use lensc_lang::value::{self, Object};

/// The path tolerance a strategy that states none is held to: 10 nm, the
/// f64 a `.lens` file's `10 nm` reads as (10 × 1e-6 mm, one ulp under
/// 1e-5), so that a job leaving it out and one writing it are the same job
/// and the header's `10 nm` reads back to it.
pub const DEFAULT_PATH_TOLERANCE: f64 = 10.0 * 1e-6;

/// The path tolerance (mm) a strategy that states none is held to on a
/// machine of `resolution` (mm) printing `axes` length axes: 10 nm, or,
/// where the machine cannot hold that, the smallest tolerance it holds
/// (resolution × √axes, `tolerance::smallest_tolerance`) rounded up to a
/// whole nm, as a file's `N nm` reads (142 nm for a lathe at 0.1 µm, 174
/// nm for a 3-axis mill at 0.1 µm): every machine holds its default, so
/// a job that states none is never refused for it (E0180).
pub fn default_path_tolerance(resolution: f64, axes: u32) -> f64 {
    let smallest = tolerance::smallest_tolerance(resolution, axes);
    if smallest <= DEFAULT_PATH_TOLERANCE || !smallest.is_finite() {
        DEFAULT_PATH_TOLERANCE
    } else {
        (smallest * 1e6 - 1e-9).ceil() * 1e-6
    }
}

/// The path tolerance (mm) a machine of `resolution` (mm) holds for a
/// strategy printing `axes` length axes (`None`: one that plans to no
/// tolerance of its own, held to `DEFAULT_PATH_TOLERANCE`): its default
/// one.
pub fn holds(resolution: f64, axes: Option<u32>) -> f64 {
    axes.map_or(DEFAULT_PATH_TOLERANCE, |n| {
        default_path_tolerance(resolution, n)
    })
}

/// How lowering evaluates a surface for the checks that analyse it: the
/// build passes its JIT (with the interpreter behind it), so the figures
/// `check` reports are the ones `build` plans with.
pub type Evaluate<'e> = &'e dyn Fn(&SurfaceTape) -> Box<dyn SurfaceFn + Sync>;

/// What every lowered job carries, whatever its strategy.
pub struct JobHead {
    /// The job's name (the program's file name and `O`/`%` word).
    pub name: String,
    /// Where a job's own errors point: its name.
    pub site: (FileId, Span),
    /// The declared names of its parts, for the header and the report.
    pub names: PartNames,
    pub surface: SurfaceSpec,
    /// The dialect the program is written in.
    pub dialect: Dialect,
    /// The machine's resolution (mm).
    pub resolution: f64,
    /// The machine's travel in X, Y, Z and C, where it states one (mm, rad).
    pub travel: [Option<(f64, f64)>; 4],
    /// A fast tool servo the machine gives an axis of its own (its
    /// letter and limit, mm/min), as every reading of the program's text
    /// takes it (the tip is Z plus the servo).
    pub servo: Option<lensc_runtime::reader::ServoAxis>,
    /// The job's `simulate` window, if it states one.
    pub simulate: Option<Simulate>,
    /// What the simulated part must meet for the program to be written.
    pub accept: accept::Accept,
    /// The tool call, spindle direction, coolant and control point every
    /// program states.
    pub start: Start,
    /// What the tool's offsets are measured to, in words and as stated.
    pub control: ControlPoint,
    /// The program moves between planned points by the controller's
    /// spline (`interpolation: spline`), not lines and arcs.
    pub spline: bool,
    /// How programs reach the control, if the machine states it
    /// (`crate::delivery`).
    pub delivery: Option<lensc_lang::schema::machines::DeliveryParams>,
}

/// The tool's control point: what its length (and on a lathe its X)
/// offset is measured to, so the point the program's coordinates move.
/// The planners plan the tool's centre; the writer adds `Start::control`.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlPoint {
    /// `tip` (true) or `centre`.
    pub tip: bool,
    /// Whether the tool states it (else the machine kind's default).
    pub stated: bool,
    /// The machine's kind, whose default it is.
    pub machine_kind: &'static str,
    /// What each offset is measured to, in words (for the header and the
    /// set-up sheet).
    pub measured_to: String,
}

impl ControlPoint {
    /// The tool's control point, as `tool` states it or as the machine's
    /// kind defaults it: a mill's and a lathe's tools are set to their tip
    /// (a mill's tool length measured to the ball's or nose's lowest
    /// point; a lathe's X and Z to the imaginary tip, the nose's -X and -Z
    /// sides, as a diameter and a face are touched off), the servo lathes'
    /// and the grinder's to the centre of the nose or wheel (the diamond
    /// turning shop's tool set on centre; an assumption, stated in
    /// docs/language/machines-and-tools.md); and its offset from the
    /// tool's centre (mm).
    pub fn of(machine: &MachineParams, tool: &ToolParams) -> (ControlPoint, ControlOffset) {
        let lathe_like = machine.kind != "mill_3axis";
        let default_tip = matches!(machine.kind, "mill_3axis" | "lathe");
        let tip = tool.control_point.map_or(default_tip, |s| s.value);
        let radius = tool
            .nose_radius
            .or(tool.diameter.map(|d| d / 2.0))
            .filter(|r| r.is_finite())
            .unwrap_or(0.0);
        let (offset, measured_to) = match (tip, lathe_like) {
            (false, _) => (
                ControlOffset::CENTRE,
                "the centre of the ball, nose or wheel, the program moves it".to_string(),
            ),
            (true, false) => (
                ControlOffset {
                    x: 0.0,
                    y: 0.0,
                    z: -radius,
                },
                "the tip, the tool length to the lowest point of the ball or nose, the radius not applied (G40)".to_string(),
            ),
            (true, true) => (
                ControlOffset {
                    x: -radius,
                    y: 0.0,
                    z: -radius,
                },
                "the imaginary tip, tip direction 3, X to the nose -X side (a diameter touched off), Z to the nose -Z side (the face touched off), the nose radius not applied (G40)".to_string(),
            ),
        };
        let point = ControlPoint {
            tip,
            stated: tool.control_point.is_some(),
            machine_kind: machine.kind,
            measured_to,
        };
        (point, offset)
    }

    /// The header's line: the control point, whether stated or the
    /// default, what it is measured to, and its offset from the tool's
    /// centre in the words `reader::header_control_offset` reads back.
    pub fn header_line(&self, offset: ControlOffset) -> String {
        format!(
            "control point {} at X{:+} Y{:+} Z{:+} mm from the tool centre ({}): {}",
            self.name(),
            offset.x,
            offset.y,
            offset.z,
            self.whose(),
            self.measured_to
        )
    }

    /// `tip` or `centre`: the header's and the sheet's word for it (the
    /// tool's `control_point: tool_tip` or `tool_centre`).
    pub fn name(&self) -> &'static str {
        if self.tip { "tip" } else { "centre" }
    }

    /// "stated" or "the default on a `KIND`".
    pub fn whose(&self) -> String {
        if self.stated {
            "stated".to_string()
        } else {
            format!("the default on a {}", self.machine_kind)
        }
    }
}

impl JobHead {
    /// An error at the job's name, labelled "this job".
    pub fn error(&self, code: &'static str, msg: String) -> Diagnostic {
        site_error(self.site, code, msg)
    }
    /// The program's file name: the job's name and the dialect's extension.
    pub fn program_name(&self) -> String {
        format!("{}.{}", self.name, self.dialect.extension)
    }
}

/// The declared names of a job's four parts (a part written in place is
/// named by its kind).
pub struct PartNames {
    pub surface: String,
    /// The surface's declared name only ("" when it is written in place):
    /// what a profile-turning report names it.
    pub surface_declared: String,
    pub tool: String,
    pub machine: String,
    pub strategy: String,
}

/// The job's surface: its kind, its description in words (every
/// parameter, for the program header) and its lowered form.
pub struct SurfaceSpec {
    pub kind: &'static str,
    pub words: String,
    /// The surface the program cuts: the design, or with a `compensate`
    /// block the corrected surface.
    pub lowered: LoweredSurface,
    /// With a `compensate` block: the design itself (what a part is
    /// measured against) and the iteration for the report.
    pub design: Option<LoweredSurface>,
    pub compensation: Option<crate::compensate::Compensation>,
    /// With a `compensate` block: the correction `lowered` is the design
    /// less (a simulation takes it out of the design's heights itself:
    /// `height_map::DesignHeights`).
    pub correction: Option<crate::compensate::Applied>,
    /// An array's lenslets (also an array wrapped on a roller, in the
    /// design's coordinates), each judged on its own; none for other
    /// surfaces.
    pub lenslets: Option<lensc_runtime::verify::lenslets::Lenslets>,
}

impl SurfaceSpec {
    /// The design surface: what the part is to be, whatever is cut to
    /// make it.
    pub fn design(&self) -> &LoweredSurface {
        self.design.as_ref().unwrap_or(&self.lowered)
    }
}

/// A `simulate { x: …, y: …, spacing: … }` block: the window of the
/// height map (mm), checked non-empty, and where it was written; a range
/// left out is the whole part's (`window::simulated`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Simulate {
    pub x: Option<(f64, f64)>,
    pub y: Option<(f64, f64)>,
    pub spacing: Option<f64>,
    pub site: (FileId, Span),
}

/// A checked job's parts, as lowering reads them: each part as checked
/// (the surface is lowered from it, the strategy read by its own folder),
/// and the job's, the machine's and the tool's parameters read once.
pub struct Parts<'a> {
    pub job: &'a CheckedJob,
    pub surface: &'a Object,
    pub tool: &'a Object,
    pub machine: &'a Object,
    pub strategy: &'a Object,
    /// The job's own parameters (tool call, coolant, `simulate`).
    pub params: JobParams,
    pub machine_params: MachineParams,
    pub tool_params: ToolParams,
    /// The strategy's path tolerance and chord placement, as stated.
    pub path: PathParams,
    /// The surface's parameters (the surface itself is lowered from its
    /// checked object, `lowered`).
    pub surface_params: Surface,
    /// With a `compensate` block, once `lowered` has made the correction:
    /// the design and the iteration, for the head.
    compensated: std::cell::RefCell<Option<(LoweredSurface, crate::compensate::Compensation)>>,
    /// With a `compensate` block, once `lowered` has made it: the
    /// correction, for whatever else a strategy plans from the design.
    correction: std::cell::RefCell<Option<crate::compensate::Applied>>,
}

impl<'a> Parts<'a> {
    /// The job's parts and parameters, or E0121 for each part (or
    /// required parameter) missing: the checker refuses those, so only a
    /// job that did not check gets here.
    pub(crate) fn of(job: &'a CheckedJob) -> Result<Parts<'a>, Vec<Diagnostic>> {
        let r = value::Reader::new(&job.fields);
        let mut errors = Vec::new();
        let mut part = |name: &str| -> Option<&'a Object> {
            let o = r.object(name).map(|o| o.as_ref());
            if o.is_none() {
                errors.push(site_error(
                    (job.file, job.name.span),
                    codes::MISSING_PARAMETER,
                    format!("this job has no {name} that checked"),
                ));
            }
            o
        };
        let (surface, tool, machine, strategy) = (
            part("surface"),
            part("tool"),
            part("machine"),
            part("strategy"),
        );
        let (Some(surface), Some(tool), Some(machine), Some(strategy)) =
            (surface, tool, machine, strategy)
        else {
            return Err(errors);
        };
        let machine_params = MachineParams::read(machine).map_err(|d| vec![d]);
        let tool_params = ToolParams::read(tool).map_err(|d| vec![d]);
        let surface_params = Surface::read(surface).map_err(|d| vec![d]);
        let (machine_params, tool_params, surface_params) =
            match (machine_params, tool_params, surface_params) {
                (Ok(m), Ok(t), Ok(s)) => (m, t, s),
                (m, t, s) => {
                    return Err(m
                        .err()
                        .into_iter()
                        .chain(t.err())
                        .chain(s.err())
                        .flatten()
                        .collect());
                }
            };
        Ok(Parts {
            job,
            surface,
            tool,
            machine,
            strategy,
            params: JobParams::read(&job.fields),
            machine_params,
            tool_params,
            path: PathParams::read(strategy),
            surface_params,
            compensated: std::cell::RefCell::new(None),
            correction: std::cell::RefCell::new(None),
        })
    }
    pub fn site(&self) -> (FileId, Span) {
        (self.job.file, self.job.name.span)
    }
    pub fn error(&self, code: &'static str, msg: String) -> Diagnostic {
        site_error(self.site(), code, msg)
    }
    /// E0131 for the machine and for the tool unless each is of a kind
    /// `what` can use.
    pub fn needs_kinds(
        &self,
        what: &str,
        machines: &[&str],
        tools: &[&str],
    ) -> Result<(), Vec<Diagnostic>> {
        all_clear(
            [
                self.needs("machine", self.machine, machines, what),
                self.needs("tool", self.tool, tools, what),
            ]
            .into_iter()
            .flatten()
            .collect(),
        )
    }
    /// E0131 unless `o` is one of `kinds`.
    fn needs(&self, part: &str, o: &Object, kinds: &[&str], what: &str) -> Option<Diagnostic> {
        (!kinds.contains(&o.kind.name)).then(|| {
            self.error(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "{what} needs {}; this {part} is a `{}`",
                    kinds
                        .iter()
                        .map(|k| format!("`{k}`"))
                        .collect::<Vec<_>>()
                        .join(" or "),
                    o.kind.name
                ),
            )
            .with_help(stdlib_made_by(part, kinds))
        })
    }
    /// E0131 for a machine that is not a `lathe` (`note` follows its kind
    /// in the message) and for a tool that is not a round nose: what a
    /// servo lathe's strategy (`what`) needs.
    pub fn needs_servo_lathe(&self, what: &str, lathe: &str, note: &str) -> Vec<Diagnostic> {
        let mut errors = Vec::new();
        if self.machine.kind.name != lathe {
            errors.push(
                self.error(
                    codes::UNSUPPORTED_COMBINATION,
                    format!(
                        "{what} needs an `{lathe}`{note}; this machine is a `{}`",
                        self.machine.kind.name
                    ),
                )
                .with_help(stdlib_made_by("machine", &[lathe])),
            );
        }
        if self.tool.kind.name != "round_nose" {
            errors.push(
                self.error(
                    codes::UNSUPPORTED_COMBINATION,
                    format!(
                        "{what} needs a `round_nose` tool; this is a `{}`",
                        self.tool.kind.name
                    ),
                )
                .with_help(stdlib_made_by("tool", &["round_nose"])),
            );
        }
        errors
    }
    /// The surface the program is to cut, lowered to IR: the design, or
    /// with a `compensate` block the design corrected from its measurement
    /// (`crate::compensate`); E0131, or the correction's refusal.
    pub fn lowered(&self) -> Result<LoweredSurface, Diagnostic> {
        let design = lensc_lang::lower::surface::lower_surface(self.surface)
            .map_err(|e| RuntimeError::Surface(e).at(self.site()))?;
        let Some(c) = &self.params.compensate else {
            return Ok(design);
        };
        let of = crate::compensate::Of {
            job: self.job,
            surface_name: self
                .job
                .part_names
                .get("surface")
                .cloned()
                .unwrap_or_else(|| self.surface.kind.name.to_string()),
            strategy_kind: self.strategy.kind.name,
            tool_radius: self
                .tool_params
                .nose_radius
                .or(self.tool_params.diameter.map(|d| d / 2.0)),
            lenslets: lensc_lang::lower::surface::array_cells(self.surface).and_then(
                |(centres, aperture)| {
                    lensc_runtime::verify::lenslets::Lenslets::new(centres, aperture)
                },
            ),
        };
        let (corrected, report, applied) = crate::compensate::corrected(&of, &design, c)?;
        *self.compensated.borrow_mut() = Some((design, report));
        *self.correction.borrow_mut() = Some(applied);
        Ok(corrected)
    }
    /// The correction `lowered` made (none without a `compensate` block,
    /// or before `lowered`).
    pub fn correction(&self) -> Option<crate::compensate::Applied> {
        self.correction.borrow().clone()
    }
    /// The path tolerance (mm) the machine's class holds for a strategy
    /// printing `axes` length axes (`Strategy::LENGTH_AXES`; `None`: one
    /// that plans to no tolerance of its own): the default one
    /// (`default_path_tolerance`), 10 nm where the machine holds that. The
    /// default acceptance limits are never looser than it allows
    /// (`accept::default_limit`).
    pub fn holds(&self, axes: Option<u32>) -> f64 {
        holds(self.machine_params.resolution, axes)
    }
    /// The path tolerance the strategy states, or the default its machine
    /// holds on a path in `axes` length axes (`default_path_tolerance`,
    /// mm).
    pub fn chord_tolerance(&self, axes: u32) -> f64 {
        self.path.chord_tolerance.map_or_else(
            || default_path_tolerance(self.machine_params.resolution, axes),
            |t| t.value,
        )
    }
    /// A tool parameter the strategy needs, or E0121 naming it (the tool
    /// is of a kind that requires it: only a tool that did not check
    /// lacks it).
    pub fn tool_needs(&self, value: Option<f64>, name: &str) -> Result<f64, Vec<Diagnostic>> {
        value.ok_or_else(|| {
            vec![self.error(
                codes::MISSING_PARAMETER,
                format!(
                    "this job's tool (`{}`) has no `{name}`",
                    self.tool_params.kind
                ),
            )]
        })
    }
    /// The machine's spindle speed limit (rad/s); none (infinite) for a
    /// machine that states no spindle.
    pub fn max_spindle_speed(&self) -> f64 {
        self.machine_params
            .max_spindle_speed
            .unwrap_or(f64::INFINITY)
    }
    /// E0143 if `speed` (rad/s) is above the machine's spindle limit.
    pub fn spindle_limit(&self, speed: f64) -> Option<Diagnostic> {
        let max = self.max_spindle_speed();
        let rpm = |w: f64| lensc_lang::check::trim_num(w * 60.0 / (2.0 * std::f64::consts::PI));
        (speed > max).then(|| {
            self.error(
                codes::SPINDLE_TOO_FAST,
                format!(
                    "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                    rpm(speed),
                    rpm(max)
                ),
            )
            .with_help(format!("lower `spindle_speed` to at most {} rpm", rpm(max)))
        })
    }
    /// E0142 when the `what` feed (mm/s) is above the machine's maximum.
    pub fn feed_error(&self, what: &str, feed: f64) -> Option<Diagnostic> {
        let max_feed = self.machine_params.max_feed;
        (feed > max_feed).then(|| {
            self.error(
                codes::FEED_TOO_HIGH,
                format!(
                    "the {what} feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                    trim_num(feed * 60.0),
                    trim_num(max_feed * 60.0)
                ),
            )
        })
    }
    /// The job's head, once its surface is lowered and its dialect known.
    pub(crate) fn head(&self, dialect: Dialect, lowered: LoweredSurface) -> JobHead {
        let name = |p: &str, o: &Object| {
            self.job
                .part_names
                .get(p)
                .cloned()
                .unwrap_or_else(|| o.kind.name.to_string())
        };
        let spline = interpolation::spline(self, &dialect);
        JobHead {
            spline,
            name: self.job.name.name.clone(),
            site: self.site(),
            names: PartNames {
                surface: name("surface", self.surface),
                surface_declared: self
                    .job
                    .part_names
                    .get("surface")
                    .cloned()
                    .unwrap_or_default(),
                tool: name("tool", self.tool),
                machine: name("machine", self.machine),
                strategy: name("strategy", self.strategy),
            },
            surface: {
                let (design, compensation) = self.compensated.borrow_mut().take().unzip();
                SurfaceSpec {
                    kind: self.surface.kind.name,
                    words: lensc_lang::lower::describe(self.surface),
                    lowered,
                    design,
                    compensation,
                    correction: self.correction(),
                    lenslets: lensc_lang::lower::surface::array_cells(self.surface).and_then(
                        |(centres, aperture)| {
                            lensc_runtime::verify::lenslets::Lenslets::new(centres, aperture)
                        },
                    ),
                }
            },
            dialect,
            resolution: self.machine_params.resolution,
            travel: self.machine_params.travel,
            servo: self
                .machine_params
                .fast_axis
                .as_ref()
                .and_then(lensc_lang::lower::read_back::servo_axis),
            simulate: simulate(&self.params).ok().flatten(),
            accept: accept::lower(&self.params).unwrap_or_default(),
            start: Start {
                control: ControlPoint::of(&self.machine_params, &self.tool_params).1,
                ..program_start(&self.params)
            },
            control: ControlPoint::of(&self.machine_params, &self.tool_params).0,
            delivery: self.machine_params.delivery,
        }
    }
}

/// Nothing, if no error was found; else every error found.
pub(crate) fn all_clear(errors: Vec<Diagnostic>) -> Result<(), Vec<Diagnostic>> {
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

pub(crate) fn site_error(site: (FileId, Span), code: &'static str, msg: String) -> Diagnostic {
    Diagnostic::error(code, msg, site.0, site.1).with_label("this job")
}

/// The job's tool call, spindle direction and coolant (tool 1, its offset
/// the tool's number, clockwise, no coolant unless it says otherwise).
pub(crate) fn program_start(params: &JobParams) -> Start {
    let tool = params.tool_number.map_or(1, |n| n.value as u32);
    Start {
        tool,
        offset: params.tool_offset.map_or(tool, |n| n.value as u32),
        rotation: if params.spindle_ccw {
            Rotation::CounterClockwise
        } else {
            Rotation::Clockwise
        },
        coolant: match params.coolant.map(|c| c.value) {
            Some("flood") => Coolant::Flood,
            Some("mist") => Coolant::Mist,
            _ => Coolant::Off,
        },
        control: ControlOffset::CENTRE,
        blank: None,
    }
}

/// E0173 if the dialect cannot call the job's tool (its number does not
/// fit the T word) or give its coolant, at the field that asks for it.
pub(crate) fn start_error(
    job: &CheckedJob,
    params: &JobParams,
    dialect: &Dialect,
    setup: Setup,
) -> Option<Diagnostic> {
    use lensc_runtime::post::writer::{coolant_word, tool_call_lines};
    let start = program_start(params);
    let (e, site) = match tool_call_lines(dialect, setup, &start) {
        Err(e) => (e, params.tool_number.or(params.tool_offset).map(|s| s.site)),
        Ok(_) => (
            coolant_word(dialect, start.coolant).err()?,
            params.coolant.map(|c| c.site),
        ),
    };
    let (file, span) = site.unwrap_or((job.file, job.name.span));
    Some(
        Diagnostic::error(codes::CANNOT_CALL_TOOL, e.message(), file, span)
            .with_label(format!("not in `{}`", dialect.name))
            .with_help(
                "choose a tool number, offset or coolant the dialect can write, or another dialect",
            ),
    )
}

/// The job's `simulate` block, if any; an error if its window is empty.
pub(crate) fn simulate(params: &JobParams) -> Result<Option<Simulate>, Diagnostic> {
    let Some(stated) = params.simulate else {
        return Ok(None);
    };
    let b = stated.value;
    let s = Simulate {
        x: b.x,
        y: b.y,
        spacing: b.spacing,
        site: stated.site,
    };
    let low_to_high = |r: Option<(f64, f64)>| r.is_none_or(|r| r.1 > r.0);
    if !(low_to_high(s.x) && low_to_high(s.y)) {
        return Err(Diagnostic::error(
            codes::WRONG_VALUE,
            "the simulation window is empty: each range must run from low to high",
            stated.site.0,
            stated.site.1,
        )
        .with_label("this window"));
    }
    Ok(Some(s))
}

/// What to write instead of a part of the wrong kind: the standard
/// library's items of the kinds needed, with their `use`, or how to make
/// one.
fn stdlib_made_by(part: &str, kinds: &[&str]) -> String {
    let made: Vec<&lensc_lang::stdlib::StdItem> = lensc_lang::stdlib::items()
        .iter()
        .filter(|i| lensc_lang::stdlib::kind_of(i).is_some_and(|k| kinds.contains(&k)))
        .collect();
    match made.as_slice() {
        [] => format!(
            "make one: `{part} NAME = {} {{ … }}` (`lensc list` shows its parameters)",
            kinds[0]
        ),
        [one, ..] => format!(
            "the standard library's {} {}: add `{}` and write `{part}: {}`",
            made.iter()
                .map(|i| format!("`{}`", i.name))
                .collect::<Vec<_>>()
                .join(", "),
            if made.len() == 1 { "is one" } else { "are" },
            one.use_line(),
            one.name
        ),
    }
}
