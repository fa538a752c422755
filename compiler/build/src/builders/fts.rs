//! Building a spiral turning job, with a fast tool servo (`fts_spiral` on
//! an `fts_lathe`, seed 003) or a slow one (`spiral_turning` on an
//! `sts_lathe`, Z carrying the surface): the checked job's
//! parts read into the runtime's planner, the settling offset worked out
//! from the servo model, the spiral planned and streamed into a LinuxCNC
//! program, and the report of what it makes.

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::emit::fts::FtsProgram;
use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::plan::fts::{
    FastAxis, FtsError, FtsSpiral, FtsSummary, Planner, SpindleSpeed, TrajectoryBounds,
};
use lensc_runtime::post::Dialect;
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::SurfaceFn;
use serde_json::json;

use lensc_lang::check::{CheckedJob, trim_num};
use lensc_lang::codes;
use std::path::Path;

use crate::driver::{Built, ProgramText, evaluator};
use crate::height_map::{self, LatheFrame, Window};
use crate::parts::Parts;
use lensc_lang::value::{self, Object};
use lensc_runtime::verify::heightmap::Sweep;

/// The settling offset and how it was found.
struct Settling {
    time: f64,
    band: Option<f64>,
    surface_speed: f64,
    d_traj: f64,
    offset: f64,
}

/// Everything the spiral planner needs, read from a checked job.
pub struct Prepared {
    pub kernel: Box<dyn SurfaceFn + Sync>,
    pub spiral: FtsSpiral,
    pub bounds: TrajectoryBounds,
    pub nose_radius: f64,
    pub fast_axis: FastAxis,
    lowered: lensc_lang::lower::surface::LoweredSurface,
    servo: Option<SecondOrderServo>,
    settling: Option<Settling>,
    safe_w: f64,
    resolution: f64,
    /// Slow tool servo: Z itself carries the surface.
    slow: bool,
}

impl Prepared {
    pub fn planner(&self) -> Planner<'_> {
        Planner {
            spiral: &self.spiral,
            surface: self.kernel.as_ref(),
            nose_radius: self.nose_radius,
            bounds: self.bounds.clone(),
        }
    }
}

/// Builds one `fts_spiral` job, or says why it cannot be built. With a
/// `spool_dir` the program goes to a temporary file there as it is
/// written, so memory stays bounded however long it is.
pub fn build(
    job: &CheckedJob,
    prov: &Provenance,
    dialect: &Dialect,
    spool_dir: Option<&Path>,
) -> Result<Built, Vec<Diagnostic>> {
    let p = prepare(job)?;
    let parts = Parts::of(job, dialect);
    let (surface, tool, machine, strategy) =
        (parts.surface, parts.tool, parts.machine, parts.strategy);
    let (file, span) = parts.site();
    let names = |p: &str, o: &Object| parts.name(p, o);
    // A fast tool servo whose controller takes a table: its motion goes
    // there, and the program moves X and C a revolution a block.
    let table_name = match &dialect.fts_table {
        Some(ext) if !p.slow => Some(format!("{}.{ext}", job.name.name)),
        _ => None,
    };
    let header = header_lines(
        job,
        prov,
        &names("surface", surface),
        &lensc_lang::lower::describe(surface),
        &names("tool", tool),
        &names("machine", machine),
        &names("strategy", strategy),
        p.nose_radius,
        &p.spiral,
        p.settling.as_ref(),
        p.slow,
        table_name.as_deref(),
        &parts,
    );
    let mut program = FtsProgram::new(
        dialect,
        &job.name.name,
        &header,
        p.resolution,
        p.spiral.chord_tolerance,
        p.safe_w,
        table_name.as_deref(),
    )
    .map_err(|e| vec![parts.not_printable(e)])?;
    let mut sink = Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, file, span)])?;
    let mut table_sink = match table_name {
        Some(_) => Some(Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, file, span)])?),
        None => None,
    };
    // The fast axis's servo, run on the commands as printed as they are
    // planned (a slow tool servo's Z has no servo model here).
    let data_rate = 1.0 / p.spiral.min_interval;
    let features = p.bounds.features.clone().unwrap_or_default();
    let mut following = match (&p.servo, p.slow) {
        (Some(servo), false) => lensc_runtime::verify::follow::FollowingSimulation::new(
            servo,
            data_rate,
            &features,
            lensc_runtime::verify::follow::RadialBins::new(
                p.spiral.start_radius.abs().min(p.spiral.end_radius.abs()),
                p.spiral.start_radius.abs().max(p.spiral.end_radius.abs()),
                crate::plots::FOLLOWING_BINS,
            ),
        ),
        _ => None,
    };
    // The height map over the window, from the same printed points.
    let design = evaluator(&p.lowered.tape).0;
    // The lenslets' own apertures (the planner's features reach on to
    // where the trajectory meets the settling plateau).
    let apertures: Vec<(f64, f64, f64)> = lensc_lang::lower::surface::array_lenslet(surface)
        .zip(lensc_lang::lower::surface::array_centres(surface))
        .map(|((_, rim), centres)| centres.into_iter().map(|(x, y)| (x, y, rim)).collect())
        .unwrap_or_default();
    let window = Window::of(job, height_map::lathe_centre(&p.lowered.domain, &apertures))
        .map_err(|d| vec![d])?;
    let grid = window.polar();
    window.check_size(job, &grid).map_err(|d| vec![d])?;
    let mut sweep = Sweep::new(grid, p.nose_radius);
    let mut printed = Vec::new();
    let mut write_error: Option<ProgramError> = None;
    let planned = p.planner().plan(&p.fast_axis, |pts| {
        let as_printed = |v: f64| lensc_runtime::verify::simulate::as_printed(v, p.resolution);
        printed.clear();
        printed.extend(pts.iter().map(|q| lensc_runtime::plan::fts::SpiralPoint {
            x: as_printed(q.x),
            w: as_printed(q.w),
            ..*q
        }));
        for q in &printed {
            sweep.point(q.c, q.x, q.w);
        }
        if let Some(sim) = following.as_mut() {
            sim.extend(&printed);
        }
        if write_error.is_none()
            && let Err(e) = program.extend(pts)
        {
            write_error = Some(e);
        }
        match program.take_text() {
            Ok(t) => sink.push(t),
            Err(e) => write_error = write_error.take().or(Some(e)),
        }
        if let Some(t) = table_sink.as_mut() {
            t.push(program.take_table_text());
        }
    });
    let axis = if p.slow { "Z" } else { "the fast axis" };
    let summary =
        planned.map_err(|e| vec![fts_diagnostic(e, &p.spiral.speed, axis, file, span)])?;
    if let Some(e) = write_error {
        return Err(vec![parts.not_printable(e)]);
    }
    if let Some(t) = table_sink.as_mut() {
        t.push(program.take_table_text());
    }
    let rest = program.finish().map_err(|e| vec![parts.not_printable(e)])?;
    sink.push(rest);
    let mut beside = Vec::new();
    if let (Some(name), Some(t)) = (table_name, table_sink) {
        let table = t.finish().map_err(|e| vec![cannot_spool(&e, file, span)])?;
        beside.push((name, table));
    }
    let text = sink
        .finish()
        .map_err(|e| vec![cannot_spool(&e, file, span)])?;
    let program_name = parts.program_name();
    let mut toolpath = toolpath_json(
        &summary,
        &p.spiral,
        p.settling.as_ref(),
        &p.servo,
        p.nose_radius,
    );
    if p.slow {
        toolpath["strategy"] = json!("spiral_turning");
    }
    let mut report = parts.report(prov, &program_name, &text, toolpath, &p.lowered);
    let mut plots = crate::plots::PlotSeries::default();
    report["simulation"] = match following {
        Some(sim) => {
            let f = sim.finish();
            let j = following_json(&f, data_rate);
            plots.following = Some(crate::plots::FollowingSeries {
                by_radius: f.by_radius,
                samples: f.samples,
                data_rate_hz: data_rate,
                max_error: (f.max_error, f.max_error_at),
            });
            j
        }
        None if p.slow => {
            json!({ "skipped": "slow tool servo: Z is a machine axis, with no servo model here" })
        }
        None => json!({ "skipped": "the fast axis has no servo model" }),
    };
    let frame = LatheFrame::new(design.as_ref(), window, p.lowered.domain, &apertures);
    let map = sweep.finish(&frame);
    plots.form_error = Some(height_map::form_error_series(
        &map,
        &frame,
        &window,
        // A polar grid's cells lie askew to the raster's blocks: √2 times
        // the spacing puts a cell in every block (1.5 for margin).
        1.5 * window.spacing,
        ("x (mm)", "y (mm)"),
    ));
    report["simulation"]["height_map"] = height_map::json(
        &map,
        &window,
        "columns at spindle angles (column step in rad), rows at radii",
        p.spiral.feed_per_rev,
    );
    if let Some((name, table)) = beside.first() {
        report["program"]["fts_table"] =
            json!({ "file": name, "rows": table.lines().saturating_sub(2) });
    }
    // Chords the data period kept from their share of the tolerance.
    let share = p.spiral.chord_tolerance * lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE;
    let warnings = summary
        .chords_over_tolerance
        .map(|o| {
            Diagnostic::warning(
                codes::CHORDS_OVER_TOLERANCE,
                format!(
                    "{} chords of the spiral stray up to {} nm from the exact path (their share of the tolerance is {} nm), the worst at r = {} mm: {} may not be commanded faster than its data rate ({} Hz) allows",
                    o.count,
                    trim_num(o.deviation * 1e6),
                    trim_num(share * 1e6),
                    trim_num(o.at_radius),
                    axis,
                    trim_num(data_rate)
                ),
                file,
                span,
            )
            .with_label("this job")
            .with_help("lower the spindle or surface speed, or give the axis a higher `data_rate`; the report's `chords_over_tolerance` says how many and where")
        })
        .into_iter()
        .collect();
    Ok(Built {
        report_name: format!("{}.report.json", job.name.name),
        program_name,
        program: text,
        report,
        beside,
        cut_points: summary.points,
        cutting_time: summary.time,
        plots,
        warnings,
    })
}

/// The fast axis's following, for the report: over the whole spiral and
/// per lenslet (in the planner's feature order), errors in nm and the
/// waviness (RMS slope of the error along the cut) in µrad.
fn following_json(
    f: &lensc_runtime::verify::follow::Following,
    data_rate: f64,
) -> serde_json::Value {
    json!({
        "kind": "fast-tool-servo following: the machine's servo model driven by the commanded positions, as printed, at its data rate",
        "data_rate_hz": data_rate,
        "servo_samples": f.samples,
        "max_following_error_nm": { "value": f.max_error * 1e6, "at_radius_mm": f.max_error_at },
        "lenslets": f.lenslets.iter().map(|l| json!({
            "centre_mm": [l.centre.0, l.centre.1],
            "radius_mm": l.radius,
            "samples": l.samples,
            "max_error_nm": l.max_error * 1e6,
            "rms_error_nm": l.rms_error * 1e6,
            "waviness_urad": l.waviness * 1e6,
        })).collect::<Vec<_>>(),
    })
}

/// Reads and checks a job's parts into what the planner needs.
pub fn prepare(job: &CheckedJob) -> Result<Prepared, Vec<Diagnostic>> {
    let part = |name: &str| value::object(&job.fields, name).expect("checked job part");
    let (surface, tool, machine, strategy) = (
        part("surface"),
        part("tool"),
        part("machine"),
        part("strategy"),
    );
    let (file, span) = (job.file, job.name.span);
    let err = |code: &'static str, msg: String| {
        Diagnostic::error(code, msg, file, span).with_label("this job")
    };
    let mut errors = Vec::new();
    let slow = strategy.kind.name == "spiral_turning";
    let (want, what) = if slow {
        ("sts_lathe", "slow-tool-servo spiral turning")
    } else {
        ("fts_lathe", "fast-tool-servo turning")
    };
    if machine.kind.name != want {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "{what} needs an `{want}`; this machine is a `{}`",
                machine.kind.name
            ),
        ));
    }
    if tool.kind.name != "round_nose" {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "{what} needs a `round_nose` tool; this is a `{}`",
                tool.kind.name
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let (m, t, st) = (&machine.fields, &tool.fields, &strategy.fields);
    let travel = value::block(m, "travel").expect("required");
    // The axis that carries the surface: the servo, or Z itself.
    let fast = value::block(m, if slow { "z_axis" } else { "fast_axis" }).expect("required");
    let spindle = value::block(m, "spindle").expect("required");
    let max_spindle = value::num(spindle, "max_speed").expect("required");
    let rho = value::num(t, "nose_radius").expect("required");
    let clearance = value::num(t, "clearance").expect("required");
    let servo = if slow {
        None
    } else {
        let num = |k: &str| value::num(fast, k);
        match (
            num("resonance"),
            num("resonant_peak"),
            num("natural_frequency"),
            num("damping"),
        ) {
            (Some(f), Some(peak), None, None) => SecondOrderServo::from_resonance(f, peak),
            (None, None, Some(f), Some(zeta)) => SecondOrderServo::from_natural(f, zeta),
            _ => {
                return Err(vec![err(
                    codes::MISSING_PARAMETER,
                    "the fast axis's servo model needs either `resonance` and `resonant_peak`, or `natural_frequency` and `damping`".into(),
                )]);
            }
        }
    };
    let fast_axis = FastAxis {
        stroke: if slow {
            let (lo, hi) = value::range(travel, "z").expect("required");
            hi - lo
        } else {
            value::num(fast, "stroke").expect("required")
        },
        max_acceleration: value::num(fast, "max_acceleration").expect("required"),
    };
    let speed = match value::num(st, "surface_speed") {
        Some(v) => SpindleSpeed::SurfaceSpeed {
            speed: v,
            max: value::num(st, "spindle_cap").unwrap_or(max_spindle),
        },
        None => SpindleSpeed::Constant(value::num(st, "spindle_speed").expect("one of them")),
    };

    let lowered = lensc_lang::lower::surface::lower_surface(surface).map_err(|e| {
        vec![err(
            codes::UNSUPPORTED_COMBINATION,
            format!("this surface cannot be evaluated yet: {e:?}"),
        )]
    })?;
    // The spiral starts where the surface's farthest point from the axis is.
    let outer = match lowered.domain {
        lensc_runtime::surface::analysis::Domain::Circle { radius }
        | lensc_runtime::surface::analysis::Domain::Annulus { outer: radius, .. } => radius,
        lensc_runtime::surface::analysis::Domain::Rect { x, y } => [x.0, x.1]
            .iter()
            .flat_map(|a| [y.0, y.1].map(|b| a.hypot(b)))
            .fold(0.0, f64::max),
    };
    let start = value::num(st, "from").unwrap_or(outer);
    // The fastest surface speed the job reaches: what d_traj is made of.
    let fastest = match speed {
        SpindleSpeed::SurfaceSpeed { speed, .. } => speed,
        SpindleSpeed::Constant(w) => w * start,
    };

    // The settling offset, where the surface is an array of dimples.
    let settle_word = value::word(st, "settle");
    let settling = if slow || settle_word == Some("none") {
        None
    } else {
        settling(surface, st, servo, fast, fastest)
    };
    if settle_word == Some("auto") && settling.is_none() {
        errors.push(
            err(
                codes::UNSUPPORTED_COMBINATION,
                "`settle: auto` needs an array of concave lenslets with circular apertures, whose continuation rises above the land".into(),
            )
            .with_help("use `settle: none` to follow the surface as it is"),
        );
        return Err(errors);
    }
    let trajectory = match &settling {
        Some(s) => {
            lensc_lang::lower::surface::lower_trajectory(surface, s.offset).map_err(|e| {
                vec![err(
                    codes::UNSUPPORTED_COMBINATION,
                    format!("the tool trajectory cannot be built: {e:?}"),
                )]
            })?
        }
        None => lensc_lang::lower::surface::lower_surface(surface).expect("lowered above"),
    };
    let (kernel, _) = evaluator(&trajectory.tape);
    let analysis = lensc_runtime::surface::analysis::analyse(kernel.as_ref(), &lowered.domain, 201);
    let design = {
        let (k, _) = evaluator(&lowered.tape);
        lensc_runtime::surface::analysis::analyse(k.as_ref(), &lowered.domain, 201)
    };

    // Tool checks on the design surface.
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
        ));
    }
    // The flank follows the cut around the spindle: the clearance angle
    // must exceed the steepest slope around (circumferential); the edge
    // meets the slope across (radial): half its included angle must exceed it.
    let (around, across) = {
        let (k, _) = evaluator(&lowered.tape);
        polar_slopes(k.as_ref(), &lowered.domain, 201)
    };
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
        ));
    }
    if let Some(included) = value::num(t, "included_angle")
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
        ));
    }

    let spiral = FtsSpiral {
        feed_per_rev: value::num(st, "feed").expect("required") * 2.0 * std::f64::consts::PI,
        speed,
        chord_tolerance: value::num(st, "chord_tolerance").unwrap_or(10e-6),
        seed_arc: value::num(st, "seed_arc").unwrap_or(0.1),
        min_interval: 1.0 / value::num(fast, "data_rate").unwrap_or(if slow { 1e3 } else { 20e3 }),
        start_radius: start,
        end_radius: 0.0,
    };
    // With a settling offset, the trajectory is level outside each
    // lenslet's continuation, which meets the plateau d_traj past the rim.
    let features = settling.as_ref().and_then(|s| {
        let (_, rim) = lensc_lang::lower::surface::array_lenslet(surface)?;
        let centres = lensc_lang::lower::surface::array_centres(surface)?;
        Some(
            centres
                .into_iter()
                .map(|(x, y)| (x, y, rim + s.d_traj))
                .collect(),
        )
    });
    let bounds = TrajectoryBounds {
        z_max: analysis.sag_max.value,
        // Margin over the sampled steepest slope: the contact search
        // window must contain the contact.
        max_slope: (analysis.max_slope.value * 1.1).min(1.5),
        features,
        part_top: design.sag_max.value,
    };
    let spin_max = match speed {
        SpindleSpeed::Constant(w) => w,
        // The spiral runs in to the axis, where the cap is reached.
        SpindleSpeed::SurfaceSpeed { max, .. } => max,
    };
    if spin_max > max_spindle {
        errors.push(err(
            codes::SPINDLE_TOO_FAST,
            format!(
                "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                trim_num(rpm(spin_max)),
                trim_num(rpm(max_spindle))
            ),
        ));
    }
    let (tx0, tx1) = value::range(travel, "x").expect("required");
    if start > tx1 || tx0 > 0.0 {
        errors.push(err(
            codes::OUT_OF_TRAVEL,
            format!(
                "the spiral moves X from {} mm to 0, outside the machine's travel {} .. {} mm",
                trim_num(start),
                trim_num(tx0),
                trim_num(tx1)
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }

    let retract = value::num(st, "retract").unwrap_or(1.0);
    Ok(Prepared {
        kernel,
        spiral,
        bounds,
        nose_radius: rho,
        fast_axis,
        safe_w: analysis.sag_max.value + rho + retract,
        resolution: value::num(m, "resolution").expect("required"),
        lowered,
        servo,
        settling,
        slow,
    })
}

/// The steepest slopes (rad) around the spindle axis and along the radius,
/// each with where (x, y), over an n × n grid of the domain.
fn polar_slopes(
    f: &dyn SurfaceFn,
    domain: &lensc_runtime::surface::analysis::Domain,
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

/// Where the program text goes as it is written: memory, or a spool file.
pub(crate) enum Sink {
    Memory(String),
    File {
        writer: std::io::BufWriter<tempfile::NamedTempFile>,
        lines: usize,
        bytes: u64,
        error: Option<std::io::Error>,
    },
}

impl Sink {
    pub(crate) fn new(spool_dir: Option<&Path>) -> std::io::Result<Sink> {
        Ok(match spool_dir {
            None => Sink::Memory(String::new()),
            Some(dir) => {
                std::fs::create_dir_all(dir)?;
                let file = tempfile::Builder::new()
                    .prefix(".lensc-")
                    .suffix(".tmp")
                    .tempfile_in(dir)?;
                Sink::File {
                    writer: std::io::BufWriter::with_capacity(1 << 20, file),
                    lines: 0,
                    bytes: 0,
                    error: None,
                }
            }
        })
    }

    pub(crate) fn push(&mut self, text: String) {
        match self {
            Sink::Memory(all) => all.push_str(&text),
            Sink::File {
                writer,
                lines,
                bytes,
                error,
            } => {
                if error.is_none() {
                    use std::io::Write;
                    *lines += text.bytes().filter(|&b| b == b'\n').count();
                    *bytes += text.len() as u64;
                    if let Err(e) = writer.write_all(text.as_bytes()) {
                        *error = Some(e);
                    }
                }
            }
        }
    }

    pub(crate) fn finish(self) -> std::io::Result<ProgramText> {
        match self {
            Sink::Memory(text) => Ok(ProgramText::Memory(text)),
            Sink::File {
                writer,
                lines,
                bytes,
                error,
            } => {
                if let Some(e) = error {
                    return Err(e);
                }
                let file = writer.into_inner().map_err(|e| e.into_error())?;
                Ok(ProgramText::Spooled { file, lines, bytes })
            }
        }
    }
}

pub(crate) fn cannot_spool(e: &std::io::Error, file: FileId, span: Span) -> Diagnostic {
    Diagnostic::error(
        codes::CANNOT_WRITE,
        format!("cannot write the program: {e}"),
        file,
        span,
    )
    .with_label("this job")
}

fn rpm(w: f64) -> f64 {
    w * 60.0 / (2.0 * std::f64::consts::PI)
}

/// The settling offset for an array of concave lenslets: the servo's
/// settling time (the strategy's, or the model's at its band), the path
/// covered meanwhile at the fastest surface speed, and how far the
/// lenslet's own surface rises over that path past its rim.
fn settling(
    surface: &Object,
    st: &[value::Field],
    servo: Option<SecondOrderServo>,
    fast: &[value::Field],
    surface_speed: f64,
) -> Option<Settling> {
    let (lenslet, rim) = lensc_lang::lower::surface::array_lenslet(surface)?;
    let band = value::num(fast, "settling_band").unwrap_or(0.002);
    let (time, band) = match value::num(st, "settling_time") {
        Some(t) => (t, None),
        None => (servo?.settling_time(band)?, Some(band)),
    };
    let f = lensc_runtime::surface::ir::Interpreter::new(&lenslet.tape);
    let along = |u: f64| f.eval(u, 0.0)[0];
    let offset = lensc_runtime::plan::fts::settling_offset(along, rim, surface_speed, time);
    (offset.is_finite() && offset > 0.0).then_some(Settling {
        time,
        band,
        surface_speed,
        d_traj: surface_speed * time,
        offset,
    })
}

#[allow(clippy::too_many_arguments)]
fn header_lines(
    job: &CheckedJob,
    prov: &Provenance,
    surface: &str,
    surface_words: &str,
    tool: &str,
    machine: &str,
    strategy: &str,
    rho: f64,
    spiral: &FtsSpiral,
    settling: Option<&Settling>,
    slow: bool,
    table: Option<&str>,
    parts: &Parts,
) -> Vec<String> {
    let table_words;
    let (servo_words, axis_words) = if slow {
        ("slow-tool-servo", "Z carries the surface")
    } else if let Some(table) = table {
        table_words = format!(
            "Z held at 0 while the fast tool servo follows the table {table} [rows C X W, one per point]"
        );
        ("fast-tool-servo", table_words.as_str())
    } else {
        ("fast-tool-servo", "Z the fast tool servo's axis")
    };
    let speed = match spiral.speed {
        SpindleSpeed::Constant(w) => format!("constant spindle speed {} rpm", trim_num(rpm(w))),
        SpindleSpeed::SurfaceSpeed { speed, max } => format!(
            "constant surface speed {} m/min capped at {} rpm",
            trim_num(speed * 60.0 / 1000.0),
            trim_num(rpm(max))
        ),
    };
    let mut lines = vec![
        format!("lensc {}: job {}", prov.lensc_version, job.name.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        format!(
            "units mm; X is {}, C the spindle angle in degrees counted on from the start, {axis_words}, +Z out of the material",
            lensc_runtime::emit::x_word(parts.dialect)
        ),
        format!(
            "coordinates are the centre of the tool nose; {}",
            parts.inverse_time_words()
        ),
        format!("surface {surface}: {surface_words}"),
        format!("tool {tool}: round nose, nose radius {} mm", trim_num(rho)),
        format!(
            "strategy {strategy}: {servo_words} spiral from r = {} mm, feed {} um/rev, {speed}, path tolerance {} nm [chords {}, blending {} nm]",
            trim_num(spiral.start_radius),
            trim_num(spiral.feed_per_rev * 1000.0),
            trim_num(spiral.chord_tolerance * 1e6),
            trim_num(
                spiral.chord_tolerance
                    * lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE
                    * 1e6
            ),
            trim_num(spiral.chord_tolerance * lensc_runtime::plan::optimise::BLEND_SHARE * 1e6)
        ),
        format!(
            "machine {machine}: {} {servo_words} lathe",
            parts.dialect.name
        ),
    ];
    match settling {
        None if slow => {}
        Some(s) => lines.push(format!(
            "settling: tool held {} um above the land, lenslets continued {} um past their rims [settling time {} ms at {} m/min]",
            trim_num(s.offset * 1000.0),
            trim_num(s.d_traj * 1000.0),
            trim_num(s.time * 1000.0),
            trim_num(s.surface_speed * 0.06)
        )),
        None => lines.push("settling: none, the tool follows the surface".into()),
    }
    lines
}

fn toolpath_json(
    s: &FtsSummary,
    spiral: &FtsSpiral,
    settling: Option<&Settling>,
    servo: &Option<SecondOrderServo>,
    rho: f64,
) -> serde_json::Value {
    let (speed_kind, allowed) = match spiral.speed {
        SpindleSpeed::Constant(_) => ("spindle_rpm", rpm(s.highest_allowed_speed)),
        SpindleSpeed::SurfaceSpeed { .. } => ("surface_m_per_min", s.highest_allowed_speed * 0.06),
    };
    json!({
        "strategy": "fts_spiral",
        "revolutions": s.revolutions,
        "cut_points": s.points,
        "cutting_time_s": s.time,
        "chord_tolerance_mm": spiral.chord_tolerance,
        "chords_over_tolerance": s.chords_over_tolerance.map(|o| json!({
            "count": o.count,
            "max_deviation_nm": o.deviation * 1e6,
            "at_radius_mm": o.at_radius,
        })),
        "nose_radius_mm": rho,
        "fast_axis": {
            "w_min_mm": s.w_min,
            "w_max_mm": s.w_max,
            "stroke_used_mm": s.w_max - s.w_min,
            "max_acceleration_m_per_s2": s.max_acceleration / 1000.0,
            "max_acceleration_at_radius_mm": s.max_acceleration_at,
            "highest_allowed_speed": { "unit": speed_kind, "value": allowed },
        },
        "max_spindle_rpm": rpm(s.max_spindle_speed),
        "servo": servo.map(|m| json!({
            "natural_frequency_hz": m.natural_frequency_hz,
            "damping": m.damping,
            "overshoot": m.overshoot(),
            "settling_time_0_2_percent_s": m.settling_time(0.002),
        })),
        "settling": settling.map(|st| json!({
            "settling_time_s": st.time,
            "band": st.band,
            "surface_speed_m_per_min": st.surface_speed * 0.06,
            "d_traj_mm": st.d_traj,
            "h_offset_mm": st.offset,
        })),
        "fingerprint_fnv1a64": format!("{:016x}", s.fingerprint),
    })
}

fn fts_diagnostic(
    e: FtsError,
    speed: &SpindleSpeed,
    axis: &str,
    file: FileId,
    span: Span,
) -> Diagnostic {
    let d = |code, msg: String| Diagnostic::error(code, msg, file, span).with_label("this job");
    match e {
        FtsError::Undefined { x, c } => d(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface is undefined where the nose must go (r = {} mm, C = {}°)",
                trim_num(x),
                trim_num(c.to_degrees() % 360.0)
            ),
        ),
        FtsError::StrokeExceeded { range, stroke } => d(
            codes::STROKE_EXCEEDED,
            format!(
                "{axis} must travel {} um, more than its {} um stroke",
                trim_num(range * 1000.0),
                trim_num(stroke * 1000.0)
            ),
        ),
        FtsError::AccelerationExceeded {
            acceleration,
            max,
            at_radius,
            highest_allowed_speed,
        } => {
            let allowed = match speed {
                SpindleSpeed::Constant(_) => {
                    format!(
                        "a spindle speed of {} rpm",
                        trim_num(rpm(highest_allowed_speed))
                    )
                }
                SpindleSpeed::SurfaceSpeed { .. } => format!(
                    "a surface speed of {} m/min",
                    trim_num(highest_allowed_speed * 0.06)
                ),
            };
            d(
                codes::ACCELERATION_EXCEEDED,
                format!(
                    "{axis} would accelerate at {} m/s² (at r = {} mm), above its {} m/s² limit",
                    trim_num(acceleration / 1000.0),
                    trim_num(at_radius),
                    trim_num(max / 1000.0)
                ),
            )
            .with_help(format!("the highest speed that respects it is {allowed}"))
        }
        FtsError::Invalid(why) => d(codes::UNSUPPORTED_COMBINATION, why.to_string()),
    }
}
