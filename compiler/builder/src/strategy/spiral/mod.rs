//! Lowering a spiral turning job, with a fast tool servo (`fts_spiral` on
//! an `fts_lathe`) or a slow one (`spiral_turning` on an `sts_lathe`, Z
//! carrying the surface): the servo model, the settling offset worked out
//! from it, the tool trajectory, the spiral and its bounds, and the checks
//! of the tool against the design (nose radius, clearance, included
//! angle), the spindle and the travel, all before the spiral is planned.

pub mod advice;
mod build;
pub(crate) mod errors;
pub mod report;
pub use build::Prepared;
mod estimate;
mod servo;

use lensc_grammar::Diagnostic;
use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::machine::tool::MeasuredEdge;
use lensc_runtime::plan::chords::ChordPlacement;
use lensc_runtime::plan::spiral::{FastAxis, FtsSpiral, SpindleSpeed, TrajectoryBounds};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::analysis::{Domain, SurfaceAnalysis};
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};

use crate::diagnostics::RuntimeError;
use crate::job::{Evaluate, JobHead, Parts, all_clear};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::surface::{LowerError, LoweredSurface};
use lensc_lang::schema::machines::{FastAxisParams, MachineParams, ZAxisParams};
use lensc_lang::schema::strategies::SpiralParams;
use lensc_lang::value::Object;

/// A spiral job, typed: what the spiral planner needs.
pub struct SpiralSpec {
    pub head: JobHead,
    /// Slow tool servo: Z itself carries the surface.
    pub slow: bool,
    pub spiral: FtsSpiral,
    pub bounds: TrajectoryBounds,
    pub nose_radius: f64,
    /// The nose's measured edge, if the tool names one (the planner
    /// clears the trajectory with it, the simulation sweeps it), and its
    /// section of the report.
    pub edge: Option<(MeasuredEdge, crate::edge::EdgeReport)>,
    pub fast_axis: FastAxis,
    /// The surface the nose centre follows: the design, or with a
    /// settling offset its lenslets continued and lifted over the land;
    /// with a `compensate` block, less the correction.
    pub trajectory: LoweredSurface,
    /// With a `compensate` block, the trajectory before the correction
    /// is taken out (the planner takes it out along each ray:
    /// `build::Prepared`).
    pub trajectory_declared: Option<LoweredSurface>,
    /// The correction of a `compensate` block, taken out of every
    /// trajectory made from `surface_object`.
    pub correction: Option<crate::compensate::Applied>,
    /// The fast axis's servo model (none for a slow tool servo).
    pub servo: Option<SecondOrderServo>,
    /// The fast axis's controller leads its servo by the servo's inverse
    /// model (`feed_forward: inverse_model`); otherwise the program does
    /// (`servo::Commands`).
    pub controller_leads: bool,
    pub settling: Option<Settling>,
    /// The fast axis's position (mm) clear of the part.
    pub safe_w: f64,
    /// The lenslets' own apertures (centre x, y and rim radius, mm), if
    /// the surface is an array.
    pub lenslets: Vec<(f64, f64, f64)>,
    /// The surface as declared: what the trajectory is made from again
    /// at another speed (`at_speed`).
    pub surface_object: Object,
    /// The machine's spindle limit (rad/s): no move of the program may
    /// turn C faster, as printed.
    pub max_spindle_speed: f64,
    /// The machine's fastest feed (mm/s): where the program writes the
    /// surface's axis as moves (no servo table), no move it writes, led or
    /// not, may be faster (`servo::Commands::fastest`).
    pub max_feed: f64,
    /// A fast tool servo the control programs as its own axis: its letter
    /// and velocity limit (mm/s). Where the program writes the fast axis
    /// as moves, the servo's motion goes on that letter, held to that
    /// limit, and the Z slide holds still (`servo::Commands`).
    pub servo_axis: Option<(char, f64)>,
    /// The job's estimate (`estimate`), made once: the build's check
    /// against the limits makes it, and a refused job's speed advice
    /// bounds its search by its servo samples (`advice::Budget`).
    pub estimated: std::sync::OnceLock<crate::job::Estimate>,
}

/// A spiral job at another speed: what a search for the highest speed
/// its fast axis allows plans.
pub struct AtSpeed {
    pub spiral: FtsSpiral,
    /// The trajectory and its bounds, where they change with speed (a
    /// settling offset); `None`: the job's own.
    pub trajectory: Option<(LoweredSurface, TrajectoryBounds)>,
}

impl SpiralSpec {
    /// The job were the strategy's speed `speed` instead: the settling
    /// offset follows the fastest surface speed, and with it the
    /// trajectory the nose centre follows.
    pub fn at_speed(&self, speed: SpindleSpeed, evaluate: Evaluate) -> Result<AtSpeed, LowerError> {
        let spiral = FtsSpiral {
            speed,
            ..self.spiral.clone()
        };
        let Some(settling) = self.settling else {
            return Ok(AtSpeed {
                spiral,
                trajectory: None,
            });
        };
        let v = fastest(speed, spiral.start_radius);
        let settling = settling_at(&self.surface_object, settling.time, settling.band, v)
            .ok_or(LowerError::Unsupported("no settling offset at this speed"))?;
        let (trajectory, bounds, _) = settled_trajectory(
            &self.surface_object,
            Some(&settling),
            self.correction.as_ref(),
            (&self.head.surface.lowered.domain, None),
            self.bounds.part_top,
            evaluate,
        )?;
        Ok(AtSpeed {
            spiral,
            trajectory: Some((trajectory, bounds)),
        })
    }
}

/// The settling offset and how it was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settling {
    /// The servo's settling time (s).
    pub time: f64,
    /// The band it settles into, when the time came from the model.
    pub band: Option<f64>,
    /// The fastest surface speed (mm/s) the job reaches.
    pub surface_speed: f64,
    /// The path covered while settling (mm).
    pub d_traj: f64,
    /// How far the tool is held above the land (mm).
    pub offset: f64,
}

impl crate::strategy::Strategy for SpiralSpec {
    const NAMES: &'static [&'static str] = &["fts_spiral", "spiral_turning"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Lathe;
    const WINDOWED: bool = true;
    const LENGTH_AXES: Option<u32> = Some(2);
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>> {
        lower(p, dialect, evaluate)
    }
    fn head(&self) -> &JobHead {
        &self.head
    }
    fn path_tolerance(&self) -> Option<f64> {
        Some(self.spiral.chord_tolerance)
    }
    fn estimate(&self, evaluate: Evaluate) -> crate::job::Estimate {
        *self
            .estimated
            .get_or_init(|| estimate::estimate(self, evaluate))
    }
    /// The disc the spiral sweeps from its start radius (`from:`, or
    /// the surface's farthest point from the axis) in to the axis, within
    /// the surface's domain.
    fn part_extent(&self) -> ((f64, f64), (f64, f64)) {
        let (x, y) = crate::job::window::domain_extent(&self.head.surface.lowered.domain);
        let r = self.spiral.start_radius;
        ((x.0.max(-r), x.1.min(r)), (y.0.max(-r), y.1.min(r)))
    }
    fn tiles(
        &self,
        window: &lensc_runtime::verify::window::Window,
    ) -> Option<Vec<lensc_runtime::verify::window::Tile>> {
        Some(window.polar_tiles(&self.lenslets))
    }
    fn build(
        &self,
        cx: &crate::context::BuildContext,
    ) -> Result<crate::output::Built, Vec<Diagnostic>> {
        build::build(self, cx)
    }
}

pub(crate) fn lower(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<SpiralSpec, Vec<Diagnostic>> {
    let (surface, strategy) = (p.surface, p.strategy);
    let slow = strategy.kind.name == "spiral_turning";
    let (lathe, what) = if slow {
        ("sts_lathe", "slow-tool-servo spiral turning")
    } else {
        ("fts_lathe", "fast-tool-servo turning")
    };
    all_clear(p.needs_servo_lathe(what, lathe, ""))?;
    let st = SpiralParams::read(strategy).map_err(|d| vec![d])?;
    let m = &p.machine_params;
    // The axis that carries the surface: the servo, or Z itself.
    let fast = carrier(p, slow)?;
    let rho = p.tool_needs(p.tool_params.nose_radius, "nose_radius")?;
    let servo = match fast {
        Carrier::SlowZ { .. } => None,
        Carrier::Servo(f) => servo_model(&f).map_err(|()| {
            vec![p.error(
                codes::MISSING_PARAMETER,
                "the fast axis's servo model needs either `resonance` and `resonant_peak`, or `natural_frequency` and `damping`".into(),
            )]
        })?,
    };
    let fast_axis = fast_axis(fast, m);
    let speed = spindle_speed(p, &st)?;
    let clearance = p.tool_needs(p.tool_params.clearance, "clearance")?;

    let lowered = p.lowered().map_err(|d| vec![d])?;
    let design_kernel = evaluate(&lowered.tape);
    let design =
        lensc_runtime::surface::analysis::analyse(design_kernel.as_ref(), &lowered.domain, 201);
    let correction = p.correction();
    // The settling offset and the trajectory with the spiral from `start`
    // (the settling offset follows the fastest surface speed).
    let trajectory_from = |start: f64| -> Result<_, Vec<Diagnostic>> {
        let settling = settling_offset(p, &st, servo, fast, fastest(speed, start))?;
        let (trajectory, bounds, declared) = settled_trajectory(
            surface,
            settling.as_ref(),
            correction.as_ref(),
            (&lowered.domain, Some((&lowered.tape, &design))),
            design.sag_max.value,
            evaluate,
        )
        .map_err(|e| vec![RuntimeError::Trajectory(e).at(p.site())])?;
        Ok((settling, trajectory, bounds, declared))
    };
    // The spiral starts where the user states (`from`), or by default far
    // enough out for its first revolution's contacts to lie a feed beyond
    // the aperture all round (`default_start`), never inside the
    // surface's farthest point from the axis.
    let outer = outer_radius(&lowered.domain);
    if let Some(e) = beyond_travel(p, outer, st.from) {
        return Err(vec![e]);
    }
    let (start, (settling, trajectory, bounds, trajectory_declared)) = match st.from {
        Some(from) => (from, trajectory_from(from)?),
        None => {
            let first = trajectory_from(outer)?;
            let start = default_start(
                evaluate(&first.1.tape).as_ref(),
                &first.2,
                (rho, st.feed * 2.0 * std::f64::consts::PI),
                &lowered.domain,
            )
            .max(outer);
            match first.0 {
                Some(_) if start > outer => (start, trajectory_from(start)?),
                _ => (start, first),
            }
        }
    };
    let mut errors = tool_checks(
        p,
        (rho, clearance),
        design_kernel.as_ref(),
        &lowered,
        &design,
    );
    let edge = crate::edge::measured_edge(p).map_err(|d| vec![d])?;

    // The spiral ends a revolution past the axis at least: ended on it,
    // the rays just past its last angle are cut by no pass nearer than a
    // feed on their own side and half a feed across the axis, a 1.5-feed
    // gap whose cusp (0.75 f)²/2ρ stands 2.25 times a scallop (a sphere
    // turned at 20 µm/rev under a 0.5 mm nose: 225 nm beside the axis
    // against 100 nm scallops); a revolution past, every line through the
    // axis has passes at most a feed apart on both sides of it.
    let feed_per_rev = st.feed * 2.0 * std::f64::consts::PI;
    let end = -past_axis(
        evaluate(&trajectory.tape).as_ref(),
        rho,
        start,
        p.machine_params.resolution,
    )
    .max(feed_per_rev.min(0.5 * start.max(0.0)));
    let mut spiral = FtsSpiral {
        feed_per_rev,
        speed,
        chord_tolerance: p
            .chord_tolerance(<SpiralSpec as crate::strategy::Strategy>::LENGTH_AXES.unwrap_or(2)),
        seed_arc: st.seed_arc.unwrap_or(0.1),
        min_interval: 1.0 / fast.data_rate(),
        start_radius: start,
        end_radius: end,
        chords: ChordPlacement::OnPath,
    };
    // W's chords stray from the path by up to their share of the tolerance.
    spiral.chords = crate::job::chords::placement(
        p,
        crate::job::chords::ChordPath {
            tolerance: Some(spiral.chord_tolerance),
            sag: spiral.chord_tolerance * lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE,
            fit: 0.0,
            long_chords: true,
            holds: p.holds(<SpiralSpec as crate::strategy::Strategy>::LENGTH_AXES),
        },
    );
    errors.extend(machine_limits(p, &spiral));
    if let Some((measured, _)) = &edge {
        let kernel = evaluate(&trajectory.tape);
        errors.extend(crate::edge::uncovered_spiral(
            p,
            &measured.profile,
            kernel.as_ref(),
            &lowered.domain,
            (spiral.end_radius, spiral.start_radius),
        ));
    }
    all_clear(errors)?;

    let retract = st.retract.unwrap_or(1.0);
    let safe_w = bounds.z_max + rho + retract;
    Ok(SpiralSpec {
        head: p.head(dialect, lowered),
        slow,
        spiral,
        bounds,
        nose_radius: rho,
        edge,
        fast_axis,
        trajectory,
        trajectory_declared,
        correction,
        servo,
        controller_leads: matches!(fast, Carrier::Servo(f) if f.controller_leads),
        settling,
        safe_w,
        lenslets: lenslets(surface),
        surface_object: surface.clone(),
        max_spindle_speed: p.max_spindle_speed(),
        max_feed: p.machine_params.max_feed,
        servo_axis: match fast {
            Carrier::Servo(f) => f.own_axis,
            Carrier::SlowZ(_) => None,
        },
        estimated: std::sync::OnceLock::new(),
    })
}

/// The fastest surface speed (mm/s) a spiral from `start` (mm) reaches:
/// what the settling path d_traj is made of.
fn fastest(speed: SpindleSpeed, start: f64) -> f64 {
    match speed {
        SpindleSpeed::SurfaceSpeed { speed, .. } => speed,
        SpindleSpeed::Constant(w) => w * start,
    }
}

/// The surface the nose centre follows (the design, or with a settling
/// offset its lenslets continued and lifted over the land; less a
/// `compensate` block's correction) and what the planner knows of it
/// beforehand; `part_top` is the design's highest.
/// How far (mm) the nose centre must go past the spindle axis for the
/// axis itself to be cut: where the trajectory slopes there (a lenslet
/// centred off the axis, over it), the contact along each uphill ray lies
/// ρ·sin(atan g) ahead of the centre, g the slope at the axis, so a spiral
/// ending at radius 0 never reaches the axis from those rays and leaves a
/// nub there (issue #29: 2.6 µm on a hex array's lenslet at x = −0.25 mm).
/// None (0) where the trajectory is level at the axis (or undefined
/// there), or the distance is below the machine's `resolution`; never
/// past the spiral's own start.
fn past_axis(trajectory: &dyn SurfaceFn, rho: f64, start: f64, resolution: f64) -> f64 {
    let at_axis = trajectory.eval(0.0, 0.0);
    let g = at_axis[1].hypot(at_axis[2]);
    let reach = rho * g / (1.0 + g * g).sqrt();
    if reach.is_finite() && reach >= resolution {
        reach.min(0.5 * start.max(0.0))
    } else {
        0.0
    }
}

/// `known`: a tape already analysed over `domain` (the surface lowered),
/// whose analysis stands for the trajectory's where the trajectory is
/// that very tape (no settling offset: the surface itself, corrected or
/// not), rather than analysing the same tape again.
fn settled_trajectory(
    surface: &Object,
    settling: Option<&Settling>,
    correction: Option<&crate::compensate::Applied>,
    (domain, known): (&Domain, Option<(&SurfaceTape, &SurfaceAnalysis)>),
    part_top: f64,
    evaluate: Evaluate,
) -> Result<(LoweredSurface, TrajectoryBounds, Option<LoweredSurface>), LowerError> {
    let mut trajectory = match settling {
        Some(s) => lensc_lang::lower::surface::lower_trajectory(surface, s.offset)?,
        None => lensc_lang::lower::surface::lower_surface(surface)?,
    };
    // The trajectory is made from the surface as declared: a correction
    // is taken out of it as out of the design (without, a compensated
    // spiral cut the design and only its header said otherwise).
    let mut declared = None;
    if let Some(c) = correction {
        declared = Some(LoweredSurface {
            tape: trajectory.tape.clone(),
            domain: trajectory.domain,
        });
        trajectory.tape = c.tape(&trajectory.tape);
    }
    let same = |t: &SurfaceTape| {
        t.outputs == trajectory.tape.outputs && t.graph.nodes() == trajectory.tape.graph.nodes()
    };
    let analysis = match known {
        Some((tape, analysis)) if same(tape) => analysis.clone(),
        _ => {
            let k = evaluate(&trajectory.tape);
            lensc_runtime::surface::analysis::analyse(k.as_ref(), domain, 201)
        }
    };
    let bounds = TrajectoryBounds {
        z_max: analysis.sag_max.value,
        // Margin over the sampled steepest slope: the contact search
        // window must contain the contact.
        max_slope: (analysis.max_slope.value * 1.1).min(1.5),
        features: settling.and_then(|s| settled_features(surface, s)),
        part_top,
    };
    Ok((trajectory, bounds, declared))
}

/// The axis that carries the surface: a fast tool servo, or a slow tool
/// servo lathe's Z itself.
#[derive(Clone, Copy)]
enum Carrier {
    Servo(FastAxisParams),
    SlowZ(ZAxisParams),
}

impl Carrier {
    /// The rate at which it takes positions (Hz): its own, or 20 kHz for
    /// a fast tool servo and 1 kHz for a slow one.
    fn data_rate(self) -> f64 {
        match self {
            Carrier::Servo(f) => f.data_rate.unwrap_or(20e3),
            Carrier::SlowZ(z) => z.data_rate.unwrap_or(1e3),
        }
    }
}

/// The machine's axis that carries the surface, or E0121 if the lathe
/// (of the kind `needs_servo_lathe` let through) states none.
fn carrier(p: &Parts, slow: bool) -> Result<Carrier, Vec<Diagnostic>> {
    let m = &p.machine_params;
    let (carrier, block) = if slow {
        (m.z_axis.map(Carrier::SlowZ), "z_axis")
    } else {
        (m.fast_axis.map(Carrier::Servo), "fast_axis")
    };
    carrier.ok_or_else(|| {
        vec![p.error(
            codes::MISSING_PARAMETER,
            format!("this job's machine (`{}`) has no `{block}`", m.kind),
        )]
    })
}

/// What the axis carrying the surface can do: the fast tool servo's
/// stroke, or a slow tool servo's Z travel, and its acceleration.
fn fast_axis(carrier: Carrier, m: &MachineParams) -> FastAxis {
    match carrier {
        Carrier::Servo(f) => FastAxis {
            stroke: f.stroke,
            max_acceleration: f.max_acceleration,
        },
        Carrier::SlowZ(z) => FastAxis {
            // A lathe's travel states Z (the checker requires it).
            stroke: m.travel[2].map_or(f64::INFINITY, |(lo, hi)| hi - lo),
            max_acceleration: z.max_acceleration,
        },
    }
}

/// The strategy's spindle speed: a constant surface speed capped (by the
/// strategy or the machine's limit, rad/s), or a constant spindle speed.
/// E0121 if the strategy states neither (the checker requires one).
fn spindle_speed(p: &Parts, st: &SpiralParams) -> Result<SpindleSpeed, Vec<Diagnostic>> {
    match (st.surface_speed, st.spindle_speed) {
        (Some(v), _) => Ok(SpindleSpeed::SurfaceSpeed {
            speed: v,
            max: st.spindle_cap.unwrap_or(p.max_spindle_speed()),
        }),
        (None, Some(w)) => Ok(SpindleSpeed::Constant(w)),
        (None, None) => Err(vec![p.error(
            codes::MISSING_PARAMETER,
            "this spiral states neither `spindle_speed` nor `surface_speed`".into(),
        )]),
    }
}

/// The lenslets' own apertures, if the surface is an array (the planner's
/// features reach on to where the trajectory meets the settling plateau).
fn lenslets(surface: &Object) -> Vec<(f64, f64, f64)> {
    lensc_lang::lower::surface::array_lenslet(surface)
        .zip(lensc_lang::lower::surface::array_centres(surface))
        .map(|((_, rim), centres)| centres.into_iter().map(|(x, y)| (x, y, rim)).collect())
        .unwrap_or_default()
}

/// The spiral's default start radius (mm): where its first revolution's
/// contacts lie a feed beyond the aperture at every spindle angle
/// (`plan::spiral::rim_start`), the nose being `(ρ, feed per revolution)`;
/// the surface's farthest point from the axis where no start puts every
/// contact on the trajectory (the nose centre on the edge, as before
/// issue #29).
fn default_start(
    trajectory: &dyn SurfaceFn,
    bounds: &TrajectoryBounds,
    (rho, feed): (f64, f64),
    domain: &Domain,
) -> f64 {
    let edge = |c: f64| edge_along(domain, c);
    lensc_runtime::plan::spiral::rim_start(trajectory, bounds, rho, feed, &edge)
        .unwrap_or_else(|| outer_radius(domain))
}

/// The aperture's farthest point (mm from the axis) along the ray at
/// angle `c` (rad), `None` if the ray misses it.
fn edge_along(domain: &Domain, c: f64) -> Option<f64> {
    match *domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => Some(radius),
        Domain::Rect { x, y } => {
            // The ray t·(cos c, sin c), t ≥ 0, within each slab.
            let slab = |(a, b): (f64, f64), d: f64| -> Option<(f64, f64)> {
                if d.abs() < 1e-15 {
                    (a <= 0.0 && 0.0 <= b).then_some((0.0, f64::INFINITY))
                } else {
                    let (t0, t1) = (a / d, b / d);
                    Some((t0.min(t1), t0.max(t1)))
                }
            };
            let (x0, x1) = slab(x, c.cos())?;
            let (y0, y1) = slab(y, c.sin())?;
            let (lo, hi) = (x0.max(y0).max(0.0), x1.min(y1));
            (hi >= lo && hi.is_finite()).then_some(hi)
        }
    }
}

/// How far from the spindle axis the surface's farthest point lies (mm).
fn outer_radius(domain: &Domain) -> f64 {
    match *domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => radius,
        Domain::Rect { x, y } => [x.0, x.1]
            .iter()
            .flat_map(|a| [y.0, y.1].map(|b| a.hypot(b)))
            .fold(0.0, f64::max),
    }
}

/// The settling offset, where the strategy asks for one (`settle`, not on
/// a slow tool servo) and the surface is an array of dimples; an error if
/// `settle: auto` finds none.
fn settling_offset(
    p: &Parts,
    st: &SpiralParams,
    servo: Option<SecondOrderServo>,
    carrier: Carrier,
    fastest: f64,
) -> Result<Option<Settling>, Vec<Diagnostic>> {
    let settle_word = st.settle;
    let settling = match carrier {
        Carrier::Servo(fast) if settle_word != Some("none") => {
            settling(p.surface, st, servo, &fast, fastest)
        }
        _ => None,
    };
    if settle_word == Some("auto") && settling.is_none() {
        return Err(vec![
            p.error(
                codes::UNSUPPORTED_COMBINATION,
                "`settle: auto` needs an array of concave lenslets with circular apertures, whose continuation rises above the land".into(),
            )
            .with_help("use `settle: none` to follow the surface as it is"),
        ]);
    }
    Ok(settling)
}

/// The planner's features with a settling offset: the trajectory is level
/// outside each lenslet's continuation, which meets the plateau d_traj
/// past the rim.
fn settled_features(surface: &Object, s: &Settling) -> Option<Vec<(f64, f64, f64)>> {
    let (_, rim) = lensc_lang::lower::surface::array_lenslet(surface)?;
    let centres = lensc_lang::lower::surface::array_centres(surface)?;
    Some(
        centres
            .into_iter()
            .map(|(x, y)| (x, y, rim + s.d_traj))
            .collect(),
    )
}

/// The spindle's speed and the X travel against the spiral: if it
/// turns faster than the machine allows (E0143), E0141 if it runs outside X.
fn machine_limits(p: &Parts, spiral: &FtsSpiral) -> Vec<Diagnostic> {
    let spin_max = match spiral.speed {
        SpindleSpeed::Constant(w) => w,
        // The spiral runs in to the axis, where the cap is reached.
        SpindleSpeed::SurfaceSpeed { max, .. } => max,
    };
    let start = spiral.start_radius;
    let mut errors: Vec<Diagnostic> = p.spindle_limit(spin_max).into_iter().collect();
    // A lathe's travel states X (the checker requires it).
    let (tx0, tx1) = p.machine_params.travel[0].unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    if start > tx1 || tx0 > 0.0 {
        errors.push(p.error(
            codes::OUT_OF_TRAVEL,
            format!(
                "the spiral moves X from {} mm to 0, outside the machine's travel {} .. {} mm",
                trim_num(start),
                trim_num(tx0),
                trim_num(tx1)
            ),
        ));
    }
    errors
}

/// E0141 when the spiral would start (at `from`, or the part's farthest
/// point from the axis, `outer`) beyond the machine's X travel: refused
/// before anything is planned, since the work of finding the start (the
/// rim's contacts) and the settling grows with the part's size (issue
/// #33: an array at a pitch of 4,294,967,297 mm hung `lensc check`).
fn beyond_travel(p: &Parts, outer: f64, from: Option<f64>) -> Option<Diagnostic> {
    // A lathe's travel states X (the checker requires it).
    let (tx0, tx1) = p.machine_params.travel[0]?;
    let start = from.unwrap_or(outer);
    if start <= tx1 {
        return None;
    }
    let what = match from {
        Some(_) => format!(
            "the spiral starts {} mm from the spindle axis",
            trim_num(start)
        ),
        None => format!(
            "the part reaches {} mm from the spindle axis (it is {} mm across)",
            trim_num(outer),
            trim_num(2.0 * outer)
        ),
    };
    Some(
        p.error(
            codes::OUT_OF_TRAVEL,
            format!(
                "{what}, beyond the machine's X travel {} .. {} mm",
                trim_num(tx0),
                trim_num(tx1)
            ),
        )
        .with_help("check the part's size and its units (`pitch: 4 mm`, not `4 m`); or use a machine with more travel"),
    )
}

/// The fast axis's second-order servo model, from its resonance and peak
/// or its natural frequency and damping (`None` if those make no servo);
/// an error if neither pair is given.
fn servo_model(fast: &FastAxisParams) -> Result<Option<SecondOrderServo>, ()> {
    match (
        fast.resonance,
        fast.resonant_peak,
        fast.natural_frequency,
        fast.damping,
    ) {
        (Some(f), Some(peak), None, None) => Ok(SecondOrderServo::from_resonance(f, peak)),
        (None, None, Some(f), Some(zeta)) => Ok(SecondOrderServo::from_natural(f, zeta)),
        _ => Err(()),
    }
}

/// The tool (its nose radius and clearance angle) against the design
/// surface: the nose radius against the
/// smallest concave radius of curvature; the flank follows the cut around
/// the spindle, so the clearance angle must exceed the steepest slope
/// around (circumferential); the edge meets the slope across (radial), so
/// half its included angle must exceed it.
fn tool_checks(
    p: &Parts,
    tool: (f64, f64),
    design_kernel: &dyn SurfaceFn,
    lowered: &LoweredSurface,
    design: &lensc_runtime::surface::analysis::SurfaceAnalysis,
) -> Vec<Diagnostic> {
    let (rho, clearance) = tool;
    let t = &p.tool_params;
    let err = |code: &'static str, msg: String| p.error(code, msg);
    let mut errors = Vec::new();
    if let Some(r) = [design.min_radius_concave_x, design.min_radius_concave_y]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.value.total_cmp(&b.value))
        && rho > r.value
    {
        errors.push(err(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at ({}, {}) mm): the tool would gouge",
                trim_num(rho * 1000.0),
                trim_num(r.value * 1000.0),
                trim_num(r.x),
                trim_num(r.y)
            ),
        ).with_help(format!("use a tool whose `nose_radius` is below {} um", trim_num(r.value * 1000.0))));
    }
    let (around, across) = polar_slopes(design_kernel, &lowered.domain, 201);
    if clearance <= around.0 {
        errors.push(err(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the surface's steepest slope in the cutting direction, around the spindle ({}°, at ({}, {}) mm): the flank would rub",
                trim_num(clearance.to_degrees()),
                trim_num(around.0.to_degrees()),
                trim_num(around.1),
                trim_num(around.2)
            ),
        ).with_help(format!("use a tool whose `clearance` is above {}°", trim_num(around.0.to_degrees()))));
    }
    if let Some(included) = t.included_angle
        && included / 2.0 <= across.0
    {
        errors.push(err(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "half the tool's included angle ({}°) is not above the surface's steepest slope across the cut, along the radius ({}°, at ({}, {}) mm): the edge's side would cut",
                trim_num(included.to_degrees() / 2.0),
                trim_num(across.0.to_degrees()),
                trim_num(across.1),
                trim_num(across.2)
            ),
        ).with_help(format!("use a tool whose `included_angle` is above {}°", trim_num(2.0 * across.0.to_degrees()))));
    }
    errors
}

/// The steepest slopes (rad) around the spindle axis and along the radius,
/// each with where (x, y), over an n × n grid of the domain.
fn polar_slopes(
    f: &dyn SurfaceFn,
    domain: &Domain,
    n: usize,
) -> ((f64, f64, f64), (f64, f64, f64)) {
    let (xs, ys, out) = lensc_runtime::surface::analysis::grid(f, domain, n);
    let mut around = (0.0, 0.0, 0.0);
    let mut across = (0.0, 0.0, 0.0);
    for (i, (&x, &y)) in xs.iter().zip(&ys).enumerate() {
        let r = x.hypot(y);
        let (zx, zy) = (out[6 * i + 1], out[6 * i + 2]);
        if r == 0.0 || !(zx.is_finite() && zy.is_finite()) {
            continue;
        }
        let tangential = ((x * zy - y * zx) / r).abs().atan();
        let radial = ((x * zx + y * zy) / r).abs().atan();
        if tangential > around.0 {
            around = (tangential, x, y);
        }
        if radial > across.0 {
            across = (radial, x, y);
        }
    }
    (around, across)
}

/// The settling offset for an array of concave lenslets: the servo's
/// settling time (the strategy's, or the model's at its band), the path
/// covered meanwhile at the fastest surface speed, and how far the
/// lenslet's own surface rises over that path past its rim.
fn settling(
    surface: &Object,
    st: &SpiralParams,
    servo: Option<SecondOrderServo>,
    fast: &FastAxisParams,
    surface_speed: f64,
) -> Option<Settling> {
    lensc_lang::lower::surface::array_lenslet(surface)?;
    let band = fast.settling_band.unwrap_or(0.002);
    let (time, band) = match st.settling_time {
        Some(t) => (t, None),
        None => (servo?.settling_time(band)?, Some(band)),
    };
    settling_at(surface, time, band, surface_speed)
}

/// The settling offset for an array of concave lenslets whose servo
/// settles in `time` (s; into `band`, when that came from its model) at
/// the surface speed `surface_speed` (mm/s).
fn settling_at(
    surface: &Object,
    time: f64,
    band: Option<f64>,
    surface_speed: f64,
) -> Option<Settling> {
    let (lenslet, rim) = lensc_lang::lower::surface::array_lenslet(surface)?;
    let f = lensc_runtime::surface::ir::Interpreter::new(&lenslet.tape);
    let along = |u: f64| f.eval(u, 0.0)[0];
    let offset = lensc_runtime::plan::spiral::settling_offset(along, rim, surface_speed, time);
    (offset.is_finite() && offset > 0.0).then_some(Settling {
        time,
        band,
        surface_speed,
        d_traj: surface_speed * time,
        offset,
    })
}

#[cfg(test)]
mod tests;
