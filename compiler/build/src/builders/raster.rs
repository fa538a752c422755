//! Building the jobs of 2- and 3-axis machines beyond the lathe: iso-plane
//! raster on a mill (seed 000) and profile grinding with a spherical wheel
//! (seed 001). Each reads the checked job into its runtime planner, checks
//! the tool against the surface, and writes a LinuxCNC program and report.

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::grinding::{GrindingError, ProfileGrinding};
use lensc_runtime::plan::raster::{Axis, Raster, RasterError, RasterTool};
use lensc_runtime::post::Dialect;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::SectionAlongX;
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::verify::heightmap::Sweep;
use serde_json::json;

use crate::driver::{Built, ProgramText, evaluator};
use crate::height_map::{self, Window, domain_centre};
use crate::parts::Parts;
use lensc_lang::check::{CheckedJob, trim_num};
use lensc_lang::codes;
use lensc_lang::value;

/// Builds a `raster` job on a `mill_3axis`.
pub fn build_raster(
    job: &CheckedJob,
    prov: &Provenance,
    dialect: &Dialect,
) -> Result<Built, Vec<Diagnostic>> {
    let p = Parts::of(job, dialect);
    let errors: Vec<Diagnostic> = [
        p.needs("machine", p.machine, &["mill_3axis"], "raster"),
        p.needs("tool", p.tool, &["microshaper", "ball_end"], "raster"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let (st, t, m) = (&p.strategy.fields, &p.tool.fields, &p.machine.fields);
    let raster = Raster {
        along: if value::word(st, "along") == Some("y") {
            Axis::Y
        } else {
            Axis::X
        },
        zigzag: value::word(st, "direction") == Some("zigzag"),
        stepover: value::num(st, "stepover").expect("required"),
        chord_tolerance: value::num(st, "chord_tolerance").unwrap_or(10e-6),
        max_step: value::num(st, "max_step"),
        lin_angle: value::num(st, "lin_angle"),
        retract: value::num(st, "retract").unwrap_or(1.0),
    };
    let (tool, tool_words) = match p.tool.kind.name {
        "ball_end" => {
            let d = value::num(t, "diameter").expect("required");
            (
                RasterTool::Ball { radius: d / 2.0 },
                format!(
                    "ball-end mill, diameter {} mm, referenced at the ball centre",
                    trim_num(d)
                ),
            )
        }
        _ => {
            let r = value::num(t, "nose_radius").expect("required");
            (
                RasterTool::Knife { nose_radius: r },
                format!(
                    "microshaper knife, nose radius {} mm, its edge across the cut, referenced at the nose centre",
                    trim_num(r)
                ),
            )
        }
    };
    let lowered = p.lowered()?;
    let (kernel, _) = evaluator(&lowered.tape);
    let path =
        lensc_runtime::plan::raster::plan_raster(&raster, &tool, kernel.as_ref(), &lowered.domain)
            .map_err(|e| vec![raster_diagnostic(&p, e)])?;
    let mut errors = Vec::new();
    // The knife's flank must clear the steepest slope along the cut.
    if let Some(clearance) = value::num(t, "clearance")
        && clearance <= path.max_slope_along.value
    {
        errors.push(p.error(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the surface's steepest slope along the cut ({}°, at ({}, {}) mm): the flank would rub",
                trim_num(clearance.to_degrees()),
                trim_num(path.max_slope_along.value.to_degrees()),
                trim_num(path.max_slope_along.x),
                trim_num(path.max_slope_along.y)
            ),
        ));
    }
    let feed = value::num(st, "feed").expect("required");
    let max_feed = value::num(m, "max_feed").expect("required");
    if feed > max_feed {
        errors.push(p.error(
            codes::FEED_TOO_HIGH,
            format!(
                "the cutting feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                trim_num(feed * 60.0),
                trim_num(max_feed * 60.0)
            ),
        ));
    }
    let moves = lensc_runtime::emit::raster::raster_moves(&path, feed);
    errors.extend(p.travel_error(&moves));
    if !errors.is_empty() {
        return Err(errors);
    }
    let mut header = p.header(
        prov,
        "units mm; X Y Z of the tool centre, +Z out of the material; no cutter compensation",
    );
    header.push(format!("tool {}: {tool_words}", p.name("tool", p.tool)));
    header.push(format!(
        "strategy {}: raster along {}, {}, stepover {} um, {}, {} passes, {} points",
        p.name("strategy", p.strategy),
        if raster.along == Axis::X { "x" } else { "y" },
        if raster.zigzag { "zigzag" } else { "one way" },
        trim_num(raster.stepover * 1000.0),
        lensc_runtime::emit::tolerance_words(raster.chord_tolerance),
        path.pass_count,
        path.point_count
    ));
    let (moves, optimised) = lensc_runtime::plan::optimise::optimise(
        &moves,
        raster.chord_tolerance * lensc_runtime::plan::optimise::FIT_SHARE,
        &dialect.arc_planes,
    );
    header.push(lensc_runtime::emit::optimisation_words(&optimised));
    header.push(format!(
        "machine {}: {} 3-axis mill",
        p.name("machine", p.machine),
        dialect.name
    ));
    let resolution = value::num(m, "resolution").expect("required");
    let text = lensc_runtime::emit::raster::emit_mill(
        dialect,
        &job.name.name,
        &header,
        &moves,
        resolution,
        raster.chord_tolerance,
    )
    .map_err(|e| vec![p.not_printable(e)])?;
    let deg = 180.0 / std::f64::consts::PI;
    let at = |e: &lensc_runtime::surface::analysis::Extremum, s: f64| json!({ "value": e.value * s, "x_mm": e.x, "y_mm": e.y });
    let time = path.cut_length / feed;
    let toolpath = json!({
        "strategy": "raster",
        "passes": path.pass_count,
        "cut_points": path.point_count,
        "cut_length_mm": path.cut_length,
        "feed_mm_per_min": feed * 60.0,
        "cutting_time_s": time,
        "pass_cutting_times_s": path.pass_lengths.iter().map(|l| l / feed).collect::<Vec<_>>(),
        "chord_tolerance_mm": raster.chord_tolerance,
        "stepover_mm": raster.stepover,
        "optimisation": crate::driver::optimisation_json(&optimised),
        "max_slope_along_deg": at(&path.max_slope_along, deg),
        "max_slope_across_deg": at(&path.max_slope_across, deg),
        "min_concave_radius_along_mm": path.min_concave_radius_along.as_ref().map(|e| at(e, 1.0)),
    });
    let program_name = p.program_name();
    let text = ProgramText::Memory(text);
    let mut report = p.report(prov, &program_name, &text, toolpath, &lowered);
    let mut plots = crate::plots::PlotSeries::default();
    report["simulation"] = match tool {
        RasterTool::Knife { nose_radius } => {
            let along_x = raster.along == Axis::X;
            let window = Window::of(job, domain_centre(&lowered.domain)).map_err(|d| vec![d])?;
            let grid = window.cartesian(along_x);
            window.check_size(job, &grid).map_err(|d| vec![d])?;
            let mut sweep = Sweep::new(grid, nose_radius);
            height_map::sweep_mill_moves(&mut sweep, &moves, along_x, resolution);
            let frame = height_map::RasterFrame {
                kernel: kernel.as_ref(),
                along_x,
                window,
                domain: lowered.domain,
            };
            let map = sweep.finish(&frame);
            plots.form_error = Some(height_map::form_error_series(
                &map,
                &frame,
                &window,
                window.spacing,
                ("x (mm)", "y (mm)"),
            ));
            let coordinates = if along_x {
                "columns along x, rows along y"
            } else {
                "columns along y, rows along x"
            };
            let mut j = height_map::json(&map, &window, coordinates, raster.stepover);
            j["edge"] = json!(
                "the knife's edge in its rake face, across the cut, as the planner places it"
            );
            // The path's own error apart from the machine's resolution: the
            // same moves swept as computed (rounded to a picometre only).
            let mut unrounded = Sweep::new(grid, nose_radius);
            height_map::sweep_mill_moves(&mut unrounded, &moves, along_x, 1e-9);
            j["contact_unrounded"] = height_map::figures_json(&unrounded.finish(&frame).contact);
            json!({ "height_map": j })
        }
        RasterTool::Ball { .. } => json!({
            "skipped": "a ball's cut reaches a radius along the path as well as across it; the height map sweeps edges that lie across the cut"
        }),
    };
    Ok(Built {
        report_name: format!("{}.report.json", job.name.name),
        program_name,
        program: text,
        report,
        beside: Vec::new(),
        cut_points: path.point_count,
        cutting_time: time,
        plots,
        warnings: Vec::new(),
    })
}

fn raster_diagnostic(p: &Parts, e: RasterError) -> Diagnostic {
    match e {
        RasterError::ToolTooLarge {
            tool_radius,
            min_radius,
            x,
            y,
        } => p
            .error(
                codes::NOSE_TOO_LARGE,
                format!(
                    "the tool's radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at ({}, {}) mm): the tool would gouge",
                    trim_num(tool_radius * 1000.0),
                    trim_num(min_radius * 1000.0),
                    trim_num(x),
                    trim_num(y)
                ),
            )
            .with_help("use a tool whose radius is below the smallest concave radius of curvature"),
        RasterError::Undefined { x, y } | RasterError::NoContact { x, y } => p.error(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface or the tool path is undefined at ({}, {}) mm",
                trim_num(x),
                trim_num(y)
            ),
        ),
        other => p.error(codes::UNSUPPORTED_COMBINATION, other.to_string()),
    }
}

/// Builds a `profile_grinding` job on a `grinder_2axis`.
pub fn build_grinding(
    job: &CheckedJob,
    prov: &Provenance,
    dialect: &Dialect,
) -> Result<Built, Vec<Diagnostic>> {
    let p = Parts::of(job, dialect);
    let errors: Vec<Diagnostic> = [
        p.needs("machine", p.machine, &["grinder_2axis"], "profile grinding"),
        p.needs("tool", p.tool, &["spherical_wheel"], "profile grinding"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let (st, t, m) = (&p.strategy.fields, &p.tool.fields, &p.machine.fields);
    let lowered = p.lowered()?;
    let edge = match lowered.domain {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => radius,
        Domain::Rect { x, .. } => x.1,
    };
    let feed = value::num(st, "feed").expect("required");
    let grinding = ProfileGrinding {
        wheel_diameter: value::num(t, "diameter").expect("required"),
        interval: value::num(st, "interval").expect("required"),
        feed,
        smoothness: value::num(st, "smoothness").expect("required"),
        start: value::num(st, "from").unwrap_or(0.0),
        end: value::num(st, "to").unwrap_or(edge),
    };
    let (kernel, _) = evaluator(&lowered.tape);
    let profile = SectionAlongX(kernel.as_ref());
    let path = lensc_runtime::plan::grinding::plan_profile_grinding(&grinding, &profile)
        .map_err(|e| vec![grinding_diagnostic(&p, e)])?;
    let mut errors = Vec::new();
    let retract = value::num(st, "retract").unwrap_or(1.0);
    let top = path
        .points
        .iter()
        .map(|q| q.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let safe_z = top + retract;
    errors.extend(
        p.travel_error(&lensc_runtime::emit::grinding::grinding_moves(
            &path, feed, safe_z,
        )),
    );
    let max_feed = value::num(m, "max_feed").expect("required");
    if feed > max_feed {
        errors.push(p.error(
            codes::FEED_TOO_HIGH,
            format!(
                "the grinding feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                trim_num(feed * 60.0),
                trim_num(max_feed * 60.0)
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let units = format!(
        "units mm; X is {}, Z along the spindle axis, +Z out of the material",
        lensc_runtime::emit::x_word(dialect)
    );
    let mut header = p.header(prov, &units);
    header.push(format!(
        "tool {}: spherical wheel, diameter {} mm; coordinates are the wheel centre",
        p.name("tool", p.tool),
        trim_num(grinding.wheel_diameter)
    ));
    header.push(format!(
        "strategy {}: profile grinding from x = {} to {} mm, interval {} um, feed {} um/s, smoothness {}; {} intervals, each at its own feed",
        p.name("strategy", p.strategy),
        trim_num(grinding.start),
        trim_num(grinding.end),
        trim_num(grinding.interval * 1000.0),
        trim_num(feed * 1000.0),
        trim_num(grinding.smoothness),
        path.segments
    ));
    header.push(format!(
        "machine {}: {} 2-axis grinder",
        p.name("machine", p.machine),
        dialect.name
    ));
    let resolution = value::num(m, "resolution").expect("required");
    let text = lensc_runtime::emit::grinding::emit_grinding(
        dialect,
        &job.name.name,
        &header,
        &path,
        feed,
        safe_z,
        resolution,
    )
    .map_err(|e| vec![p.not_printable(e)])?;
    // The table of eqs 18-19: every interval's commanded z velocity and
    // acceleration, as the paper's position-based interpolation gives them.
    let table: Vec<serde_json::Value> = path
        .points
        .iter()
        .skip(1)
        .map(|q| json!([q.contact_x, q.x, q.z, q.velocity, q.acceleration]))
        .collect();
    let toolpath = json!({
        "strategy": "profile_grinding",
        "segments": path.segments,
        "cut_points": path.points.len(),
        "interval_time_s": path.interval_time,
        "cutting_time_s": path.total_time,
        "max_z_speed_mm_per_s": path.max_speed,
        "max_z_acceleration_mm_per_s2": path.max_acceleration,
        "open_loop_drift_mm": path.open_loop_drift,
        "min_concave_radius_mm": path.min_concave_radius.map(|(r, x)| json!({ "value": r, "at_x_mm": x })),
        "intervals": {
            "columns": ["contact_x_mm", "wheel_x_mm", "wheel_z_mm", "v_mm_per_s", "a_mm_per_s2"],
            "rows": table,
        },
    });
    let program_name = p.program_name();
    let text = ProgramText::Memory(text);
    let mut report = p.report(prov, &program_name, &text, toolpath, &lowered);
    // What the wheel's section (a circle of its radius about the centre)
    // leaves along the programmed centres.
    use lensc_runtime::surface::Profile as _;
    let stream = lensc_runtime::emit::grinding::grinding_moves(&path, feed, safe_z);
    let cut = lensc_runtime::verify::simulate::profile_cut(
        &stream,
        grinding.wheel_diameter / 2.0,
        resolution,
        &|x: f64| profile.point(x).z,
        (grinding.start, grinding.end),
        crate::driver::PROFILE_SAMPLES,
    );
    report["simulation"] = crate::driver::profile_cut_json(&cut);
    let plots = crate::plots::PlotSeries {
        profile: Some(crate::driver::profile_series(
            &cut,
            &|x: f64| profile.point(x).z,
            &stream,
            ("wheel", grinding.wheel_diameter / 2.0),
            resolution,
            Vec::new(),
        )),
        ..Default::default()
    };
    Ok(Built {
        report_name: format!("{}.report.json", job.name.name),
        program_name,
        program: text,
        report,
        beside: Vec::new(),
        cut_points: path.points.len(),
        cutting_time: path.total_time,
        plots,
        warnings: Vec::new(),
    })
}

fn grinding_diagnostic(p: &Parts, e: GrindingError) -> Diagnostic {
    match e {
        GrindingError::WheelTooLarge {
            x,
            wheel_radius,
            curvature_radius,
        } => p
            .error(
                codes::NOSE_TOO_LARGE,
                format!(
                    "the wheel's radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at x = {} mm): the wheel would gouge",
                    trim_num(wheel_radius * 1000.0),
                    trim_num(curvature_radius * 1000.0),
                    trim_num(x)
                ),
            )
            .with_help("use a smaller wheel"),
        GrindingError::NonFiniteSurface { x } => p.error(
            codes::UNDEFINED_ON_PATH,
            format!("the surface is undefined at x = {} mm", trim_num(x)),
        ),
        other => p.error(codes::UNSUPPORTED_COMBINATION, other.to_string()),
    }
}
