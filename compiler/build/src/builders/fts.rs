//! Building a spiral turning job, with a fast tool servo (`fts_spiral` on
//! an `fts_lathe`, seed 003) or a slow one (`spiral_turning` on an
//! `sts_lathe`, Z carrying the surface): the lowered spiral (its settling
//! offset and tool checks were made in lowering) planned and streamed into
//! the program, the servo's following and the cut simulated as it is
//! written, and the report of what it makes.

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::job::{Settling, SpiralSpec};
use lensc_runtime::emit::fts::FtsProgram;
use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::plan::fts::{FtsError, FtsSpiral, FtsSummary, Planner, SpindleSpeed};
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::Sweep;
use serde_json::json;
use std::path::Path;

use crate::driver::{Built, evaluator};
use crate::height_map::{self, LatheFrame, Window};
use crate::parts;
use crate::spool::{Sink, cannot_spool};

/// A spiral job ready to plan: its spec and the trajectory's kernel.
pub struct Prepared<'s> {
    pub spec: &'s SpiralSpec,
    pub kernel: Box<dyn SurfaceFn + Sync>,
}

impl<'s> Prepared<'s> {
    /// Compiles the trajectory the nose centre follows.
    pub fn of(spec: &'s SpiralSpec) -> Prepared<'s> {
        Prepared {
            spec,
            kernel: evaluator(&spec.trajectory.tape).0,
        }
    }
    pub fn planner(&self) -> Planner<'_> {
        Planner {
            spiral: &self.spec.spiral,
            surface: self.kernel.as_ref(),
            nose_radius: self.spec.nose_radius,
            bounds: self.spec.bounds.clone(),
        }
    }
}

/// Builds one `fts_spiral` job, or says why it cannot be built. With a
/// `spool_dir` the program goes to a temporary file there as it is
/// written, so memory stays bounded however long it is.
pub fn build(
    spec: &SpiralSpec,
    prov: &Provenance,
    spool_dir: Option<&Path>,
) -> Result<Built, Vec<Diagnostic>> {
    let prepared = Prepared::of(spec);
    let (p, head) = (spec, &spec.head);
    let dialect = &head.dialect;
    let site = head.site;
    let not_printable = |e| vec![parts::not_printable(head, e)];
    // A fast tool servo whose controller takes a table: its motion goes
    // there, and the program moves X and C a revolution a block.
    let table_name = match &dialect.fts_table {
        Some(ext) if !p.slow => Some(format!("{}.{ext}", head.name)),
        _ => None,
    };
    let header = header_lines(spec, prov, table_name.as_deref());
    let mut program = FtsProgram::new(
        dialect,
        &head.name,
        &header,
        head.resolution,
        p.spiral.chord_tolerance,
        p.safe_w,
        table_name.as_deref(),
    )
    .map_err(not_printable)?;
    let mut sink = Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, site)])?;
    let mut table_sink = match table_name {
        Some(_) => Some(Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, site)])?),
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
    let lowered = &head.surface.lowered;
    let design = evaluator(&lowered.tape).0;
    let apertures = &p.lenslets;
    let window = Window::of(head, height_map::lathe_centre(&lowered.domain, apertures));
    let grid = window.polar();
    window.check_size(head, &grid).map_err(|d| vec![d])?;
    let mut sweep = Sweep::new(grid, p.nose_radius);
    let mut printed = Vec::new();
    let mut write_error: Option<ProgramError> = None;
    let planned = prepared.planner().plan(&p.fast_axis, |pts| {
        let as_printed = |v: f64| lensc_runtime::verify::simulate::as_printed(v, head.resolution);
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
    let summary = planned.map_err(|e| vec![fts_diagnostic(e, &p.spiral.speed, axis, site)])?;
    if let Some(e) = write_error {
        return Err(not_printable(e));
    }
    if let Some(t) = table_sink.as_mut() {
        t.push(program.take_table_text());
    }
    let rest = program.finish().map_err(not_printable)?;
    sink.push(rest);
    let mut beside = Vec::new();
    if let (Some(name), Some(t)) = (table_name, table_sink) {
        let table = t.finish().map_err(|e| vec![cannot_spool(&e, site)])?;
        beside.push((name, table));
    }
    let text = sink.finish().map_err(|e| vec![cannot_spool(&e, site)])?;
    let program_name = head.program_name();
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
    let mut report = parts::report(head, prov, &program_name, &text, toolpath);
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
    let frame = LatheFrame::new(design.as_ref(), window, lowered.domain, apertures);
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
                site.0,
                site.1,
            )
            .with_label("this job")
            .with_help("lower the spindle or surface speed, or give the axis a higher `data_rate`; the report's `chords_over_tolerance` says how many and where")
        })
        .into_iter()
        .collect();
    Ok(Built {
        report_name: format!("{}.report.json", head.name),
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

fn rpm(w: f64) -> f64 {
    w * 60.0 / (2.0 * std::f64::consts::PI)
}

/// The program's header: provenance, units, the surface, tool, spiral
/// and machine in words, and the settling offset.
fn header_lines(spec: &SpiralSpec, prov: &Provenance, table: Option<&str>) -> Vec<String> {
    let (head, spiral, slow, rho) = (&spec.head, &spec.spiral, spec.slow, spec.nose_radius);
    let settling = spec.settling.as_ref();
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
        format!("lensc {}: job {}", prov.lensc_version, head.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        format!(
            "units mm; X is {}, C the spindle angle in degrees counted on from the start, {axis_words}, +Z out of the material",
            lensc_runtime::emit::x_word(&head.dialect)
        ),
        format!(
            "coordinates are the centre of the tool nose; {}",
            parts::inverse_time_words(head)
        ),
        format!("surface {}: {}", head.names.surface, head.surface.words),
        format!(
            "tool {}: round nose, nose radius {} mm",
            head.names.tool,
            trim_num(rho)
        ),
        format!(
            "strategy {}: {servo_words} spiral from r = {} mm, feed {} um/rev, {speed}, path tolerance {} nm [chords {}, blending {} nm]",
            head.names.strategy,
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
            "machine {}: {} {servo_words} lathe",
            head.names.machine, head.dialect.name
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
    (file, span): (FileId, Span),
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
