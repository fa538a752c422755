//! The machining strategies, one folder each, behind one trait. A
//! strategy's folder holds everything that is its own: its typed job
//! (`Spec`) and the lowering that makes it from a checked job, its
//! up-front estimate (`estimate.rs`), the tiles its simulation window is
//! swept in, its builder (`build.rs`: plan with the runtime's planner,
//! emit, simulate, its report section and header) and the wording of its
//! planner's errors (`errors.rs`). The registry at the end of this file
//! lists every strategy once; it makes `JobSpec`, the one enum of lowered
//! jobs, and the one dispatch over it. A strategy name the registry does
//! not list is a coded error (E0135), never a fallback.
//!
//! The planners themselves stay in lensc-runtime (`plan/`, `emit/`): they
//! know no language and write no program text. Everything that turns the
//! language's checked values into a planner's typed input, and a
//! planner's output and errors into a program, a report and diagnostics,
//! is here, in lensc-build, the only crate that lowers jobs.

pub mod grinding;
pub mod raster;
pub mod roller;
pub mod spiral;
pub mod turning;

use lensc_grammar::Diagnostic;
use lensc_runtime::post::{Dialect, Setup};
use lensc_runtime::verify::window::{Tile, Window};

use lensc_lang::check::CheckedJob;
use lensc_lang::codes;

use crate::context::BuildContext;
use crate::job::estimate::Estimate;
use crate::job::{Evaluate, JobHead, Parts};
use crate::output::Built;

/// What every strategy provides: the contract between a strategy's folder
/// and the pipeline. `Self` is the strategy's lowered, typed job.
pub trait Strategy: Sized {
    /// The names a `.lens` file gives the strategy (`strategy s = raster
    /// { … }`); each is a kind in the schema's strategies.
    const NAMES: &'static [&'static str];
    /// What its programs are written for: a lathe or a mill (the dialect
    /// must be able to write that set-up).
    const SETUP: Setup;
    /// Whether its cut is judged on a height map in a window that a
    /// `simulate` block may set (false: along its whole profile).
    const WINDOWED: bool;
    /// The length axes its printed path moves in, which the path
    /// tolerance must allow the machine's rounding in
    /// (`job::tolerance`); `None` for a strategy that states no path
    /// tolerance.
    const LENGTH_AXES: Option<u32>;
    /// The checked job lowered to the strategy's typed job, with every
    /// check that needs no planning; every error found.
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>>;
    /// What every job has: names, surface, dialect, machine limits.
    fn head(&self) -> &JobHead;
    /// The tolerance the strategy plans its path to (mm), or `None` for a
    /// strategy that has none (fixed angle steps, a grinder's intervals).
    fn path_tolerance(&self) -> Option<f64>;
    /// Points, program size and servo samples, estimated before planning.
    fn estimate(&self, evaluate: Evaluate) -> Estimate;
    /// The extent (x, y ranges, mm) of what the job cuts.
    fn part_extent(&self) -> ((f64, f64), (f64, f64)) {
        crate::job::window::domain_extent(&self.head().surface.lowered.domain)
    }
    /// The tiles the builder simulates `window` in, or `None` where the
    /// strategy simulates no height map.
    fn tiles(&self, window: &Window) -> Option<Vec<Tile>>;
    /// The warnings the job earns before any planning (`lensc check`
    /// reports them too).
    fn warnings_before_planning(&self) -> Vec<Diagnostic> {
        Vec::new()
    }
    /// Plans, emits and simulates the job: its program, report and plots.
    fn build(&self, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>>;
}

/// The registry: `Variant(strategy::folder::Spec)`, one line a strategy.
/// It makes `JobSpec` and its dispatch; the names come from each
/// strategy's `Strategy::NAMES`.
macro_rules! registry {
    ($($variant:ident($spec:ty),)*) => {
        /// A job, lowered and typed: one variant per strategy. (One is
        /// made per job and moved rarely: the variants' sizes need not
        /// match.)
        #[allow(clippy::large_enum_variant)]
        pub enum JobSpec {
            $(
                #[doc = concat!("A job of `", stringify!($spec), "`.")]
                $variant($spec),
            )*
        }

        /// Every strategy name the registry lists, in its order.
        pub const NAMES: &[&[&str]] = &[$(<$spec as Strategy>::NAMES,)*];

        /// The strategy named `name` lowered from `p` in `dialect`, with
        /// the set-up its programs are written for, whether it is
        /// simulated in a window and the length axes of its path; `None`
        /// if the registry lists no strategy of that name.
        pub(crate) fn lower(
            name: &str,
            p: &Parts,
            dialect: Dialect,
            evaluate: Evaluate,
        ) -> Option<(Result<JobSpec, Vec<Diagnostic>>, Setup, bool, Option<u32>)> {
            $(
                if <$spec as Strategy>::NAMES.contains(&name) {
                    return Some((
                        <$spec as Strategy>::lower(p, dialect, evaluate).map(JobSpec::$variant),
                        <$spec as Strategy>::SETUP,
                        <$spec as Strategy>::WINDOWED,
                        <$spec as Strategy>::LENGTH_AXES,
                    ));
                }
            )*
            None
        }

        impl JobSpec {
            /// What every job has: names, surface, dialect, machine limits.
            pub fn head(&self) -> &JobHead {
                match self { $(JobSpec::$variant(s) => s.head(),)* }
            }
            /// The set-up its programs are written for: a lathe or a mill.
            pub fn setup(&self) -> Setup {
                match self { $(JobSpec::$variant(_) => <$spec as Strategy>::SETUP,)* }
            }
            /// The tolerance the strategy plans its path to (mm), if any.
            pub fn path_tolerance(&self) -> Option<f64> {
                match self { $(JobSpec::$variant(s) => s.path_tolerance(),)* }
            }
            /// The length axes its path is printed in, if it states a
            /// path tolerance (`Strategy::LENGTH_AXES`).
            pub fn length_axes(&self) -> Option<u32> {
                match self { $(JobSpec::$variant(_) => <$spec as Strategy>::LENGTH_AXES,)* }
            }
            /// Points, program size and servo samples, estimated before
            /// planning: the strategy's own, with the header's bytes.
            pub fn estimate(&self, evaluate: Evaluate) -> Estimate {
                let mut e = match self { $(JobSpec::$variant(s) => s.estimate(evaluate),)* };
                e.program_bytes += 900.0 + self.head().surface.words.len() as f64;
                e
            }
            /// The extent (x, y ranges, mm) of what the job cuts.
            pub fn part_extent(&self) -> ((f64, f64), (f64, f64)) {
                match self { $(JobSpec::$variant(s) => s.part_extent(),)* }
            }
            /// The tiles the job's builder simulates `window` in.
            pub fn tiles(&self, window: &Window) -> Option<Vec<Tile>> {
                match self { $(JobSpec::$variant(s) => s.tiles(window),)* }
            }
            /// The warnings the job earns before any planning.
            pub fn warnings_before_planning(&self) -> Vec<Diagnostic> {
                match self { $(JobSpec::$variant(s) => s.warnings_before_planning(),)* }
            }
            /// Plans, emits and simulates the job with its strategy.
            pub fn build(&self, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
                match self { $(JobSpec::$variant(s) => s.build(cx),)* }
            }
        }
    };
}

registry! {
    Turning(turning::TurningSpec),
    Spiral(spiral::SpiralSpec),
    Raster(raster::RasterSpec),
    Grinding(grinding::GrindingSpec),
    Roller(roller::RollerSpec),
}

/// Lowers one checked job to its `JobSpec`, in the dialect `requested` (by
/// `lensc build --dialect`) or the machine's own, or returns every reason
/// it cannot be built that is known before planning.
pub fn lower_job(
    job: &CheckedJob,
    requested: Option<&str>,
    evaluate: Evaluate,
) -> Result<JobSpec, Vec<Diagnostic>> {
    let p = Parts::of(job)?;
    let mut errors = Vec::new();
    let dialect = lensc_lang::lower::dialect(job, requested).map_err(|d| errors.push(d));
    let strategy = p.strategy.kind.name;
    // Until a dialect is known the strategy is lowered in LinuxCNC's: its
    // own errors are reported, the spec is not used.
    let d = dialect.clone().unwrap_or_else(|_| Dialect::linuxcnc());
    let Some((spec, setup, windowed, axes)) = lower(strategy, &p, d, evaluate) else {
        errors.push(no_such_strategy(&p));
        return Err(errors);
    };
    // Jobs simulated along their whole profile: a window means nothing
    // to them.
    if let (false, Some(f)) = (windowed, p.params.simulate) {
        errors.push(
            Diagnostic::error(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "`simulate` sets the window of a surface's height map; this `{strategy}` job is simulated along its whole profile"
                ),
                f.site.0,
                f.site.1,
            )
            .with_label("not for a profile job")
            .with_help("remove the `simulate` block"),
        );
    }
    if let Err(d) = crate::job::simulate(&p.params) {
        errors.push(d);
    }
    // Only profile, spiral and roller helix turning place the nose by a
    // measured edge (raster's ball ends and grinding's wheels take none).
    if !<turning::TurningSpec as Strategy>::NAMES.contains(&strategy)
        && !<spiral::SpiralSpec as Strategy>::NAMES.contains(&strategy)
        && !<roller::RollerSpec as Strategy>::NAMES.contains(&strategy)
    {
        errors.extend(crate::edge::not_compensated(&p, strategy));
    }
    if let Err(d) = crate::job::accept::lower(&p.params) {
        errors.push(d);
    }
    errors.extend(axes.and_then(|axes| crate::job::tolerance::below_resolution(&p, axes)));
    if let Ok(d) = &dialect {
        let resolution = p.machine_params.resolution;
        if let Err(e) = lensc_runtime::post::check_dialect(d, setup, resolution) {
            errors.push(
                Diagnostic::error(codes::NOT_PRINTABLE, e.message(), job.file, job.name.span)
                    .with_label("no program was written for this job")
                    .with_help(crate::diagnostics::NOT_PRINTABLE_HELP),
            );
        } else if let Some(e) = crate::job::start_error(job, &p.params, d, setup) {
            errors.push(e);
        }
        errors.extend(crate::job::interpolation::error(&p, d));
    }
    match spec {
        Ok(spec) => {
            errors.extend(crate::job::window::check_grid(
                spec.head(),
                spec.part_extent(),
                |w| spec.tiles(w),
            ));
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

/// E0135: the registry lists no strategy of the job's strategy's kind
/// (a kind the schema has and no folder builds).
fn no_such_strategy(p: &Parts) -> Diagnostic {
    let names: Vec<String> = NAMES
        .iter()
        .flat_map(|n| n.iter())
        .map(|n| format!("`{n}`"))
        .collect();
    p.error(
        codes::NO_SUCH_STRATEGY,
        format!(
            "lensc has no planner for the strategy `{}`",
            p.strategy.kind.name
        ),
    )
    .with_help(format!("the strategies lensc builds: {}", names.join(", ")))
}

#[cfg(test)]
mod tests {
    use lensc_lang::schema::{Category, KINDS};

    /// The registry builds exactly the strategies the language has: every
    /// strategy kind of the schema once, and no name the schema lacks (a
    /// strategy added to one and not the other fails here, not in a
    /// user's build).
    #[test]
    fn the_registry_names_every_strategy_of_the_schema_once() {
        let mut registered: Vec<&str> = super::NAMES
            .iter()
            .flat_map(|n| n.iter().copied())
            .collect();
        let mut schema: Vec<&str> = KINDS
            .iter()
            .filter(|k| k.category == Category::Strategy)
            .map(|k| k.name)
            .collect();
        registered.sort_unstable();
        schema.sort_unstable();
        let before = registered.len();
        registered.dedup();
        assert_eq!(
            before,
            registered.len(),
            "a strategy name is registered twice"
        );
        assert_eq!(registered, schema);
    }
}
