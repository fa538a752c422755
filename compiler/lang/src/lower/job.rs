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
mod chords;
mod estimate;
mod mill;
mod roller;
mod spiral;
pub mod tolerance;
mod turning;
pub mod window;

pub use estimate::{DEFAULT_MAX_PROGRAM_SIZE, Estimate, Limits, MAX_POINTS, estimate, refusals};
pub use mill::{GrindingSpec, RasterSpec};
pub use roller::RollerSpec;
pub use spiral::{AtSpeed, Settling, SpiralSpec};
pub use turning::TurningSpec;

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::moves::{Coolant, Rotation, Start};
use lensc_runtime::post::{Dialect, Setup};
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};

use crate::check::CheckedJob;
use crate::codes;
use crate::lower::diagnostics::{NOT_PRINTABLE_HELP, RuntimeError};
use crate::lower::surface::LoweredSurface;
use crate::value::{self, Object};

/// The path tolerance a strategy that states none is held to: 10 nm, the
/// f64 a `.lens` file's `10 nm` reads as (10 × 1e-6 mm, one ulp under
/// 1e-5), so that a job leaving it out and one writing it are the same job
/// and the header's `10 nm` reads back to it.
pub const DEFAULT_PATH_TOLERANCE: f64 = 10.0 * 1e-6;

/// How lowering evaluates a surface for the checks that analyse it: the
/// build passes its JIT (with the interpreter behind it), so the figures
/// `check` reports are the ones `build` plans with.
pub type Evaluate<'e> = &'e dyn Fn(&SurfaceTape) -> Box<dyn SurfaceFn + Sync>;

/// A job, typed: one variant per strategy. (One is made per job and
/// moved rarely: the variants' sizes need not match.)
#[allow(clippy::large_enum_variant)]
pub enum JobSpec {
    /// Profile turning on a lathe (`profile_turning`).
    Turning(TurningSpec),
    /// A spiral with a fast tool servo (`fts_spiral`) or a slow one
    /// (`spiral_turning`).
    Spiral(SpiralSpec),
    /// Iso-plane raster on a 3-axis mill (`raster`).
    Raster(RasterSpec),
    /// Profile grinding with a spherical wheel (`profile_grinding`).
    Grinding(GrindingSpec),
    /// A design wrapped onto a roller, cut along a helix (`roller_helix`).
    Roller(RollerSpec),
}

impl JobSpec {
    /// The tolerance the strategy plans its path to (mm): its
    /// `chord_tolerance`, or `None` for a strategy that has none (a
    /// roller helix's fixed angle steps, a grinder's intervals).
    pub fn path_tolerance(&self) -> Option<f64> {
        match self {
            JobSpec::Turning(s) => Some(s.job.strategy.chord_tolerance),
            JobSpec::Spiral(s) => Some(s.spiral.chord_tolerance),
            JobSpec::Raster(s) => Some(s.raster.chord_tolerance),
            JobSpec::Grinding(_) | JobSpec::Roller(_) => None,
        }
    }
    /// What every job has: names, surface, dialect, machine limits.
    pub fn head(&self) -> &JobHead {
        match self {
            JobSpec::Turning(s) => &s.head,
            JobSpec::Spiral(s) => &s.head,
            JobSpec::Raster(s) => &s.head,
            JobSpec::Grinding(s) => &s.head,
            JobSpec::Roller(s) => &s.head,
        }
    }
}

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
    /// The job's `simulate` window, if it states one.
    pub simulate: Option<Simulate>,
    /// What the simulated part must meet for the program to be written.
    pub accept: accept::Accept,
    /// The tool call, spindle direction and coolant every program states.
    pub start: Start,
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
    pub lowered: LoweredSurface,
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

/// A checked job's parts, as lowering reads them.
pub(crate) struct Parts<'a> {
    pub job: &'a CheckedJob,
    pub surface: &'a Object,
    pub tool: &'a Object,
    pub machine: &'a Object,
    pub strategy: &'a Object,
}

impl<'a> Parts<'a> {
    fn of(job: &'a CheckedJob) -> Parts<'a> {
        let part = |name: &str| -> &'a Object {
            value::object(&job.fields, name).expect("checked job part")
        };
        Parts {
            job,
            surface: part("surface"),
            tool: part("tool"),
            machine: part("machine"),
            strategy: part("strategy"),
        }
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
    /// The surface lowered to IR, or E0131.
    pub fn lowered(&self) -> Result<LoweredSurface, Diagnostic> {
        crate::lower::surface::lower_surface(self.surface)
            .map_err(|e| RuntimeError::Surface(e).at(self.site()))
    }
    /// The machine's spindle speed limit (rad/s).
    pub fn max_spindle_speed(&self) -> f64 {
        let spindle = value::block(&self.machine.fields, "spindle").expect("required");
        value::num(spindle, "max_speed").expect("required")
    }
    /// E0143 if `speed` (rad/s) is above the machine's spindle limit.
    pub fn spindle_limit(&self, speed: f64) -> Option<Diagnostic> {
        let max = self.max_spindle_speed();
        let rpm = |w: f64| crate::check::trim_num(w * 60.0 / (2.0 * std::f64::consts::PI));
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
    /// The job's head, once its surface is lowered and its dialect known.
    fn head(&self, dialect: Dialect, lowered: LoweredSurface) -> JobHead {
        let name = |p: &str, o: &Object| {
            self.job
                .part_names
                .get(p)
                .cloned()
                .unwrap_or_else(|| o.kind.name.to_string())
        };
        let m = &self.machine.fields;
        let travel = value::block(m, "travel");
        JobHead {
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
            surface: SurfaceSpec {
                kind: self.surface.kind.name,
                words: crate::lower::describe(self.surface),
                lowered,
            },
            dialect,
            resolution: value::num(m, "resolution").expect("required"),
            travel: ["x", "y", "z", "c"].map(|a| travel.and_then(|t| value::range(t, a))),
            simulate: simulate(self.job).ok().flatten(),
            accept: accept::lower(self.job).unwrap_or_default(),
            start: program_start(self.job),
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

fn site_error(site: (FileId, Span), code: &'static str, msg: String) -> Diagnostic {
    Diagnostic::error(code, msg, site.0, site.1).with_label("this job")
}

/// Lowers one checked job to its `JobSpec`, in the dialect `requested` (by
/// `lensc build --dialect`) or the machine's own, or returns every reason
/// it cannot be built that is known before planning.
pub fn lower_job(
    job: &CheckedJob,
    requested: Option<&str>,
    evaluate: Evaluate,
) -> Result<JobSpec, Vec<Diagnostic>> {
    let p = Parts::of(job);
    let mut errors = Vec::new();
    let dialect = crate::lower::dialect(job, requested).map_err(|d| errors.push(d));
    let strategy = p.strategy.kind.name;
    // Profile jobs are simulated along their whole profile: a window
    // means nothing to them.
    if let ("profile_turning" | "profile_grinding", Some(f)) =
        (strategy, value::field(&job.fields, "simulate"))
    {
        errors.push(
            Diagnostic::error(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "`simulate` sets the window of a surface's height map; this `{strategy}` job is simulated along its whole profile"
                ),
                f.file,
                f.span,
            )
            .with_label("not for a profile job")
            .with_help("remove the `simulate` block"),
        );
    }
    if let Err(d) = simulate(job) {
        errors.push(d);
    }
    if let Err(d) = accept::lower(job) {
        errors.push(d);
    }
    // Until a dialect is known the strategy is lowered in LinuxCNC's: its
    // own errors are reported, the spec is not used.
    let d = dialect.clone().unwrap_or_else(|_| Dialect::linuxcnc());
    let (spec, setup) = match strategy {
        "fts_spiral" | "spiral_turning" => (
            spiral::lower(&p, d, evaluate).map(JobSpec::Spiral),
            Setup::Lathe,
        ),
        "raster" => (
            mill::lower_raster(&p, d, evaluate).map(JobSpec::Raster),
            Setup::Mill,
        ),
        "profile_grinding" => (
            mill::lower_grinding(&p, d, evaluate).map(JobSpec::Grinding),
            Setup::Lathe,
        ),
        "roller_helix" => (
            roller::lower(&p, d, evaluate).map(JobSpec::Roller),
            Setup::Lathe,
        ),
        _ => (
            turning::lower(&p, d, evaluate).map(JobSpec::Turning),
            Setup::Lathe,
        ),
    };
    errors.extend(tolerance::below_resolution(&p, strategy));
    if let Ok(d) = &dialect
        && let Some(resolution) = value::num(&p.machine.fields, "resolution")
    {
        if let Err(e) = lensc_runtime::post::check_dialect(d, setup, resolution) {
            errors.push(
                Diagnostic::error(codes::NOT_PRINTABLE, e.message(), job.file, job.name.span)
                    .with_label("no program was written for this job")
                    .with_help(NOT_PRINTABLE_HELP),
            );
        } else if let Some(e) = start_error(job, d, setup) {
            errors.push(e);
        }
    }
    match spec {
        Ok(spec) => {
            errors.extend(window::check_grid(&spec));
            if errors.is_empty() {
                Ok(spec)
            } else {
                Err(errors)
            }
        }
        Err(mut more) => {
            errors.append(&mut more);
            Err(errors)
        }
    }
}

/// The job's tool call, spindle direction and coolant (tool 1, its offset
/// the tool's number, clockwise, no coolant unless it says otherwise).
fn program_start(job: &CheckedJob) -> Start {
    let f = &job.fields;
    let tool = value::num(f, "tool_number").map_or(1, |n| n as u32);
    Start {
        tool,
        offset: value::num(f, "tool_offset").map_or(tool, |n| n as u32),
        rotation: match value::word(f, "spindle_direction") {
            Some("ccw") => Rotation::CounterClockwise,
            _ => Rotation::Clockwise,
        },
        coolant: match value::word(f, "coolant") {
            Some("flood") => Coolant::Flood,
            Some("mist") => Coolant::Mist,
            _ => Coolant::Off,
        },
    }
}

/// E0173 if the dialect cannot call the job's tool (its number does not
/// fit the T word) or give its coolant, at the field that asks for it.
fn start_error(job: &CheckedJob, dialect: &Dialect, setup: Setup) -> Option<Diagnostic> {
    use lensc_runtime::post::writer::{coolant_word, tool_call_lines};
    let start = program_start(job);
    let (e, field) = match tool_call_lines(dialect, setup, &start) {
        Err(e) => (
            e,
            value::field(&job.fields, "tool_number").or(value::field(&job.fields, "tool_offset")),
        ),
        Ok(_) => (
            coolant_word(dialect, start.coolant).err()?,
            value::field(&job.fields, "coolant"),
        ),
    };
    let (file, span) = field.map_or((job.file, job.name.span), |f| (f.file, f.span));
    Some(
        Diagnostic::error(codes::CANNOT_CALL_TOOL, e.message(), file, span)
            .with_label(format!("not in `{}`", dialect.name))
            .with_help(
                "choose a tool number, offset or coolant the dialect can write, or another dialect",
            ),
    )
}

/// The job's `simulate` block, if any; an error if its window is empty.
fn simulate(job: &CheckedJob) -> Result<Option<Simulate>, Diagnostic> {
    let Some(field) = value::field(&job.fields, "simulate") else {
        return Ok(None);
    };
    let b = value::block(&job.fields, "simulate").expect("checked block");
    let s = Simulate {
        x: value::range(b, "x"),
        y: value::range(b, "y"),
        spacing: value::num(b, "spacing"),
        site: (field.file, field.span),
    };
    let low_to_high = |r: Option<(f64, f64)>| r.is_none_or(|r| r.1 > r.0);
    if !(low_to_high(s.x) && low_to_high(s.y)) {
        return Err(Diagnostic::error(
            codes::WRONG_VALUE,
            "the simulation window is empty: each range must run from low to high",
            field.file,
            field.span,
        )
        .with_label("this window"));
    }
    Ok(Some(s))
}

/// What to write instead of a part of the wrong kind: the standard
/// library's items of the kinds needed, with their `use`, or how to make
/// one.
fn stdlib_made_by(part: &str, kinds: &[&str]) -> String {
    let made: Vec<&crate::stdlib::StdItem> = crate::stdlib::items()
        .iter()
        .filter(|i| crate::stdlib::kind_of(i).is_some_and(|k| kinds.contains(&k)))
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
