//! The spiral planner's errors in the words a user reads: the help names
//! speeds in the kind the job gives them, and a refused acceleration
//! carries what a search over the real check found (`advice`); a lead
//! the program cannot give its servo is refused (`lead_refused`).
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::diagnostics::{Coded, coded, rpm, um};
use lensc_runtime::plan::spiral::{FtsError, SpeedAdvice, SpindleSpeed};

/// A spiral planner error as its diagnostic at `site`. `speed` is how the
/// job gives its spindle speed, `axis` names the axis that carries the
/// surface, `advice` what a search for a speed that passes found.
pub(crate) fn error(
    e: FtsError,
    speed: &SpindleSpeed,
    axis: &str,
    advice: Option<SpeedAdvice>,
    site: (FileId, Span),
) -> Diagnostic {
    coded_error(e, speed, axis, advice).at(site)
}

fn coded_error(
    e: FtsError,
    speed: &SpindleSpeed,
    axis: &str,
    advice: Option<SpeedAdvice>,
) -> Coded {
    match e {
        FtsError::Undefined { x, c } => coded(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface is undefined where the nose must go (r = {} mm, C = {}°)",
                trim_num(x),
                trim_num(c.to_degrees() % 360.0)
            ),
        ),
        FtsError::StrokeExceeded { range, stroke } => coded(
            codes::STROKE_EXCEEDED,
            format!(
                "{axis} must travel {} um, more than its {} um stroke",
                um(range),
                um(stroke)
            ),
        )
        .help("use a fast axis with a longer `stroke`, or a surface whose height varies less around each turn"),
        FtsError::AccelerationExceeded {
            acceleration,
            max,
            at_radius,
        } => {
            let help = advice_help(speed, advice, "the acceleration");
            coded(
                codes::ACCELERATION_EXCEEDED,
                format!(
                    "{axis} would accelerate at {} m/s² (at r = {} mm), above its {} m/s² limit",
                    trim_num(acceleration / 1000.0),
                    trim_num(at_radius),
                    trim_num(max / 1000.0)
                ),
            )
            .help(help)
        }
        FtsError::Invalid(why) => coded(codes::UNSUPPORTED_COMBINATION, why.to_string()),
    }
}

/// Where the program leads the servo itself (`servo::program_leads`):
/// E0192 if the commands it writes (lowest and highest, `range`, mm) span
/// more than the servo's stroke, or drive the servo (as simulated,
/// `followed`) beyond its acceleration limit.
pub(crate) fn lead_refused(
    spec: &super::SpiralSpec,
    range: (f64, f64),
    followed: Option<&lensc_runtime::verify::follow::Following>,
) -> Option<Coded> {
    let axis = &spec.fast_axis;
    let help = "the servo has no feed-forward (`feed_forward: none`), so lensc writes the command that leads it, the path plus its velocity and acceleration through the servo's inverse model; that command is larger and faster than the path wherever the path's content nears the servo's natural frequency: lower the spindle or surface speed, or give the machine a servo its controller leads (`feed_forward: inverse_model`) if it has one";
    let spread = range.1 - range.0;
    if spread > axis.stroke {
        return Some(
            coded(
                codes::LEAD_REFUSED,
                format!(
                    "the command that leads the fast axis spans {} um, more than its {} um stroke",
                    um(spread),
                    um(axis.stroke)
                ),
            )
            .help(help),
        );
    }
    let f = followed?;
    (f.max_acceleration > axis.max_acceleration).then(|| {
        coded(
            codes::LEAD_REFUSED,
            format!(
                "the command that leads the fast axis drives it at {} m/s² (at r = {} mm), above its {} m/s² limit",
                trim_num(f.max_acceleration / 1000.0),
                trim_num(f.max_acceleration_at),
                trim_num(axis.max_acceleration / 1000.0)
            ),
        )
        .help(help)
    })
}

/// The help of a refusal a slower spindle cures: the speed a search
/// found (`advice`), in the kind the job gives (`speed`); `what` is
/// the figure over its limit.
fn advice_help(speed: &SpindleSpeed, advice: Option<SpeedAdvice>, what: &str) -> String {
    let words = |v: f64| match speed {
        SpindleSpeed::Constant(_) => format!("{} rpm", rpm(v)),
        SpindleSpeed::SurfaceSpeed { .. } => format!("{} m/min", trim_num(v * 0.06)),
    };
    let kind = match speed {
        SpindleSpeed::Constant(_) => "spindle speed",
        SpindleSpeed::SurfaceSpeed { .. } => "surface speed",
    };
    match advice {
        Some(SpeedAdvice::Found {
            passes,
            fails,
            lag: None,
        }) => format!(
            "the highest speed found that respects it is a {kind} of {} (planned and checked; {} is refused)",
            words(passes),
            words(fails)
        ),
        Some(SpeedAdvice::Found {
            passes,
            fails,
            lag: Some(l),
        }) => format!(
            "the highest speed found that respects it is a {kind} of {} (planned and checked; {} is refused); there the servo lags {} nm, over the job's {} nm `max_following_error`: state `max_following_error: {} nm` to accept the lag, or lower the speed further (the lag falls about in proportion)",
            words(passes),
            words(fails),
            trim_num((l.lag * 1e7).round() / 10.0),
            trim_num(l.limit * 1e6),
            trim_num(super::advice::accepted_lag_nm(l.lag))
        ),
        Some(SpeedAdvice::NotFound {
            lowest_tried,
            budget: false,
        }) => format!(
            "no {kind} tried respects it, down to {}: {what} does not fall with the speed there (a spindle cap, or the path itself)",
            words(lowest_tried)
        ),
        Some(SpeedAdvice::NotFound {
            lowest_tried,
            budget: true,
        }) => format!(
            "no {kind} tried respects it, down to {}: a slower trial would simulate the servo over more samples than the search allows (its cutting time grows as the speed falls); try a lower {kind} yourself",
            words(lowest_tried)
        ),
        None => format!("lower the {kind}"),
    }
}

/// E0192 where the program writes the surface's axis as moves
/// (`servo::writes_moves`) and the fastest of them (`fastest`: its feed,
/// mm/s, and radius, mm) feeds above the machine's `max_feed`: the
/// controller holds every move to the axis's velocity limit, so that move
/// would run slower than planned, late against the spindle. `advice`:
/// the speed a search found at which every move fits.
pub(crate) fn feed_refused(
    spec: &super::SpiralSpec,
    fastest: (f64, f64),
    advice: SpeedAdvice,
) -> Coded {
    let (feed, at) = fastest;
    let led = if super::servo::program_leads(spec) {
        "the command that leads the fast axis (the path through the servo's inverse model, `feed_forward: none`)"
    } else {
        "the surface's axis"
    };
    let axis = if spec.slow {
        "Z"
    } else {
        "the fast axis, written on Z,"
    };
    coded(
        codes::LEAD_REFUSED,
        format!(
            "{led} moves {axis} at {} mm/min (at r = {} mm), above the machine's `max_feed` of {} mm/min",
            trim_num((feed * 60.0 * 10.0).round() / 10.0),
            trim_num((at * 1e4).round() / 1e4),
            trim_num(spec.max_feed * 60.0)
        ),
    )
    .help(format!(
        "the controller holds every move to the axis's velocity limit, so this move would run late against the spindle; {}",
        advice_help(&spec.spiral.speed, Some(advice), "the feed")
    ))
}

/// E0192 where the servo is written on its own letter
/// (`servo::servo_letter`) and its fastest move (`fastest`: its velocity,
/// mm/s, and radius, mm) drives it above its `max_velocity`: the
/// controller slows the whole move, C with it, to hold the servo's axis
/// to its limit, so the move runs later than the lead it carries was
/// worked out for. `advice`: the speed a search found at which every
/// servo move fits.
pub(crate) fn servo_velocity_refused(
    spec: &super::SpiralSpec,
    fastest: (f64, f64),
    advice: SpeedAdvice,
) -> Coded {
    let (velocity, at) = fastest;
    let (letter, most) = spec.servo_axis.unwrap_or(('W', f64::INFINITY));
    let led = if super::servo::program_leads(spec) {
        "the command that leads the fast axis (the path through the servo's inverse model, `feed_forward: none`)"
    } else {
        "the fast axis's path"
    };
    coded(
        codes::LEAD_REFUSED,
        format!(
            "{led} drives the servo, written on {letter}, at {} mm/min (at r = {} mm), above its `max_velocity` of {} mm/min",
            trim_num((velocity * 60.0 * 10.0).round() / 10.0),
            trim_num((at * 1e4).round() / 1e4),
            trim_num(most * 60.0)
        ),
    )
    .help(format!(
        "the controller holds the servo's axis to its velocity limit by slowing the whole move, the spindle with it, so this move would run late against the timing its lead was worked out for; {}",
        advice_help(&spec.spiral.speed, Some(advice), "the servo's velocity")
    ))
}
