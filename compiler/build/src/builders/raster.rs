//! Building an iso-plane raster job on a 3-axis mill (seed 000): the
//! raster planned over the surface, the knife's clearance checked against
//! the planner's steepest slope along the cut, the moves kept within the
//! travel, the program written, and the cut simulated as a height map.

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::job::{JobHead, RasterSpec};
use lensc_runtime::plan::raster::{Axis, RasterError, RasterTool};
use lensc_runtime::post::Provenance;
use lensc_runtime::verify::heightmap::Sweep;
use serde_json::json;

use crate::driver::{Built, ProgramText, evaluator};
use crate::height_map::{self, Window, domain_centre};
use crate::parts;

/// Builds a `raster` job on a `mill_3axis`.
pub fn build(spec: &RasterSpec, prov: &Provenance) -> Result<Built, Vec<Diagnostic>> {
    let (head, raster, tool) = (&spec.head, &spec.raster, spec.tool);
    let dialect = &head.dialect;
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    let path =
        lensc_runtime::plan::raster::plan_raster(raster, &tool, kernel.as_ref(), &lowered.domain)
            .map_err(|e| vec![raster_diagnostic(head, e)])?;
    let mut errors = Vec::new();
    // The knife's flank must clear the steepest slope along the cut.
    if let Some(clearance) = spec.clearance
        && clearance <= path.max_slope_along.value
    {
        errors.push(head.error(
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
    let feed = spec.feed;
    let moves = lensc_runtime::emit::raster::raster_moves(&path, feed);
    errors.extend(parts::travel_error(head, &moves));
    if !errors.is_empty() {
        return Err(errors);
    }
    let mut header = parts::header(
        head,
        prov,
        "units mm; X Y Z of the tool centre, +Z out of the material; no cutter compensation",
    );
    header.push(format!("tool {}: {}", head.names.tool, spec.tool_words));
    header.push(format!(
        "strategy {}: raster along {}, {}, stepover {} um, {}, {} passes, {} points",
        head.names.strategy,
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
        head.names.machine, dialect.name
    ));
    let resolution = head.resolution;
    let text = lensc_runtime::emit::raster::emit_mill(
        dialect,
        &head.name,
        &header,
        &moves,
        resolution,
        raster.chord_tolerance,
    )
    .map_err(|e| vec![parts::not_printable(head, e)])?;
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
    let program_name = head.program_name();
    let text = ProgramText::Memory(text);
    let mut report = parts::report(head, prov, &program_name, &text, toolpath);
    let mut plots = crate::plots::PlotSeries::default();
    report["simulation"] = match tool {
        RasterTool::Knife { nose_radius } => {
            let along_x = raster.along == Axis::X;
            let window = Window::of(head, domain_centre(&lowered.domain));
            let grid = window.cartesian(along_x);
            window.check_size(head, &grid).map_err(|d| vec![d])?;
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
        report_name: format!("{}.report.json", head.name),
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

fn raster_diagnostic(p: &JobHead, e: RasterError) -> Diagnostic {
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
