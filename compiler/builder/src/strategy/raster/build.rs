//! Building an iso-plane raster job on a 3-axis mill (seed 000): the
//! raster planned over the surface, the knife's clearance checked against
//! the planner's steepest slope along the cut, the moves kept within the
//! travel, the program written, and the cut simulated as a height map.

use super::RasterSpec;
use lensc_grammar::Diagnostic;
use lensc_lang::lower::exact_in;
use lensc_runtime::plan::optimise::Summary;
use lensc_runtime::plan::raster::{Axis, RasterPath, RasterTool, check_clearance};
use lensc_runtime::post::Provenance;
use lensc_runtime::verify::heightmap::Cutter;

use crate::context::{self as parts, BuildContext};
use crate::evaluate::evaluator;
use crate::height_map::{self, Simulation};
use crate::output::{Built, ProgramText};
use crate::report;
use lensc_runtime::verify::window::split;

/// Builds a `raster` job on a `mill_3axis`.
pub(super) fn build(spec: &RasterSpec, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
    let prov = cx.prov;
    let (head, raster, tool) = (&spec.head, &spec.raster, spec.tool);
    let dialect = &head.dialect;
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    let path =
        lensc_runtime::plan::raster::plan_raster(raster, &tool, kernel.as_ref(), &lowered.domain)
            .map_err(|e| vec![super::errors::error(e, head.site)])?;
    let mut errors = Vec::new();
    // The knife's flank must clear the steepest slope along the cut, as
    // lowering found it on the planes and now on every planned contact.
    if let Some(clearance) = spec.clearance
        && let Err(e) = check_clearance(clearance, path.max_slope_along)
    {
        errors.push(super::errors::error(e, head.site));
    }
    let feed = spec.feed;
    let moves = lensc_runtime::emit::raster::raster_moves(
        &path,
        lensc_runtime::emit::raster::RasterCut {
            feed,
            spindle_speed: spec.spindle_speed,
            zigzag: raster.zigzag,
        },
    );
    errors.extend(parts::travel_error(head, &moves));
    if !errors.is_empty() {
        return Err(errors);
    }
    let resolution = head.resolution;
    let fit_share = raster.chord_tolerance * lensc_runtime::plan::optimise::FIT_SHARE;
    let (moves, optimised, text) = if head.spline {
        // The planned moves fitted with the controller's splines; the
        // moves themselves stay the path the fit is measured against.
        let decimals = lensc_runtime::post::check_dialect(
            dialect,
            lensc_runtime::post::Setup::Mill,
            resolution,
        )
        .map_err(|e| vec![parts::not_printable(head, e)])?;
        let fit = lensc_runtime::plan::spline::SplineFit {
            tolerance: fit_share,
            decimals,
            control: head.start.control,
            knots: lensc_runtime::plan::spline::KnotSpacing::of(dialect),
        };
        // Each run as a spline, or as the optimiser's lines and arcs where
        // those take fewer blocks (points placed clear of the material are
        // not fitted back into it).
        let otherwise = lensc_runtime::plan::spline::Otherwise {
            arc_planes: &dialect.arc_planes,
            above: matches!(
                raster.chords,
                lensc_runtime::plan::chords::ChordPlacement::Clear { .. }
            ),
        };
        let (steps, fitted) =
            lensc_runtime::plan::spline::fit_splines(&moves, &fit, Some(otherwise));
        let optimised = Summary {
            moves_before: fitted.blocks_before,
            moves_after: fitted.blocks_after,
            arcs: 0,
            merged_lines: 0,
            max_deviation: fitted.max_deviation,
            tolerance: fitted.limit,
        };
        let start = lensc_runtime::moves::Start {
            blank: blank(&moves, tool),
            ..head.start
        };
        let mut header = header_lines(spec, prov, &path, &optimised);
        header.retain(|l| !l.starts_with("optimised "));
        let at = header
            .iter()
            .position(|l| l.starts_with("machine "))
            .unwrap_or(header.len());
        header.insert(at, lensc_runtime::emit::spline_words(dialect, &fitted));
        let text = lensc_runtime::emit::raster::emit_mill_steps(
            dialect,
            &head.name,
            &header,
            &steps,
            (resolution, raster.chord_tolerance),
            &start,
        )
        .map_err(|e| vec![parts::not_printable(head, e)])?;
        (moves, optimised, text)
    } else {
        // Points placed clear of the material are not fitted back into it.
        let (moves, optimised) = lensc_runtime::plan::optimise::optimise_within(
            &moves,
            fit_share,
            &dialect.arc_planes,
            matches!(
                raster.chords,
                lensc_runtime::plan::chords::ChordPlacement::Clear { .. }
            ),
        );
        let start = lensc_runtime::moves::Start {
            blank: blank(&moves, tool),
            ..head.start
        };
        let text = lensc_runtime::emit::raster::emit_mill(
            dialect,
            &head.name,
            &header_lines(spec, prov, &path, &optimised),
            &moves,
            (resolution, raster.chord_tolerance),
            &start,
        )
        .map_err(|e| vec![parts::not_printable(head, e)])?;
        (moves, optimised, text)
    };
    let section = report::Raster::new(&path, raster, feed, &optimised);
    let time = section.cutting_time_s;
    let toolpath = report::Toolpath::Raster(section);
    let mut plots = crate::plots::PlotSeries::default();
    // The knife's edge lies across the cut; a ball reaches its radius
    // along the path too (see lensc_runtime::verify::heightmap).
    let (cutter, edge) = match tool {
        RasterTool::Knife { nose_radius } => (
            Cutter::nose(nose_radius),
            "the knife's edge in its rake face, across the cut, as the planner places it",
        ),
        RasterTool::Ball { radius } => (
            Cutter::Ball { radius },
            "the ball swept along the path: every point within its radius of the centre's printed path",
        ),
    };
    let along_x = raster.along == Axis::X;
    // The whole part by default, as fine as its cutter's budget allows.
    let budget = match &cutter {
        Cutter::Nose { .. } => height_map::WHOLE_CELLS_NOSE,
        Cutter::Ball { .. } => height_map::WHOLE_CELLS_BALL,
    };
    let window = height_map::window(
        head,
        height_map::domain_extent(&lowered.domain),
        budget,
        |w| split(&w.cartesian(along_x), None),
    );
    let grid = window.cartesian(along_x);
    let mut sweep = Simulation::of(grid, split(&grid, None), cutter.clone());
    // The program as written: its text read as the controller reads it,
    // once, for the read-back too.
    let (findings, executed) = parts::read_program(head, &text, false, cx.read);
    height_map::sweep_mill_program(sweep.path(), &executed, along_x);
    // The height alone: the frame asks nothing else of the design.
    let heights = height_map::DesignHeights::of(&head.surface);
    let frame = height_map::RasterFrame {
        kernel: heights.kernel.as_ref(),
        correction: heights.correction.as_ref(),
        along_x,
        window,
        domain: lowered.domain,
        lenslets: head.surface.lenslets.as_ref(),
    };
    let (map, errors) = sweep.finish(&frame, &window, window.spacing);
    plots.form_error = Some(height_map::form_error_series(
        errors,
        &window,
        ("x (mm)", "y (mm)"),
    ));
    let coordinates = if along_x {
        "columns along x, rows along y"
    } else {
        "columns along y, rows along x"
    };
    let mut height_map = report::HeightMap::new(&map, &window, coordinates, raster.stepover);
    // The path's own error apart from the machine's resolution: the
    // same moves swept as computed (rounded to a picometre only).
    let mut unrounded = Simulation::of(grid, split(&grid, None), cutter);
    height_map::sweep_mill_moves(unrounded.path(), &moves, along_x, 1e-9);
    height_map.raster = Some(report::RasterEdge {
        edge,
        contact_unrounded: unrounded
            .finish(&frame, &window, window.spacing)
            .0
            .contact
            .as_ref()
            .map(report::Figures::from),
    });
    let simulation = report::Simulation::HeightMap(report::HeightMapOnly { height_map });
    let text = ProgramText::Memory(text);
    let cut = (path.point_count, time);
    let mut built = parts::built(head, prov, text, toolpath, simulation, plots, cut);
    built.warnings = crate::plausibility::air_warnings(head, &moves);
    built.read_findings = findings;
    Ok(built)
}

/// The blank the program states for the control's graphic test run
/// (Klartext's `BLK FORM`): a box holding every cutting move's contact
/// (the tool centre less the ball's or nose's radius in Z) where it ends,
/// where it starts in X and Y, and the top of every arc in the ZX or YZ
/// plane that passes over its centre and the bottom of every one that
/// passes under it (a bowl's arcs: their ends are their highest); 1 mm
/// deeper than the lowest contact.
/// None without a cut.
fn blank(
    moves: &[lensc_runtime::moves::Move],
    tool: RasterTool,
) -> Option<lensc_runtime::moves::Blank> {
    use lensc_runtime::moves::{Move, Plane, Position};
    let r = match tool {
        RasterTool::Knife { nose_radius } => nose_radius,
        RasterTool::Ball { radius } => radius,
    };
    let (mut min, mut max) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut take = |p: [f64; 3]| {
        for i in 0..3 {
            if p[i].is_finite() {
                min[i] = min[i].min(p[i]);
                max[i] = max[i].max(p[i]);
            }
        }
    };
    let mut at = [f64::NAN; 3];
    let moved = |to: &Position, at: &mut [f64; 3]| {
        for (a, v) in at.iter_mut().zip([to.x, to.y, to.z]) {
            if !v.is_nan() {
                *a = v;
            }
        }
    };
    for m in moves {
        match m {
            Move::Rapid(to) => moved(to, &mut at),
            Move::Linear { to, .. } | Move::Arc { to, .. } => {
                // Where it starts in X and Y (in Z it may start in the
                // air: a plunge's start is the safe height).
                take([at[0], at[1], f64::NAN]);
                let from = at;
                moved(to, &mut at);
                take([at[0], at[1], at[2] - r]);
                if let Move::Arc {
                    centre,
                    plane: plane @ (Plane::Zx | Plane::Yz),
                    ..
                } = m
                {
                    // The arc in its plane as (across, z): a minor arc,
                    // as the simulation and the read-back take it.
                    let (i, o) = match plane {
                        Plane::Zx => (0, centre.x),
                        _ => (1, centre.y),
                    };
                    let (a, b) = (
                        (from[i] - o, from[2] - centre.z),
                        (at[i] - o, at[2] - centre.z),
                    );
                    let radius = b.0.hypot(b.1);
                    if passes_straight(a, b, 1.0) {
                        take([f64::NAN, f64::NAN, centre.z + radius - r]);
                    }
                    if passes_straight(a, b, -1.0) {
                        take([f64::NAN, f64::NAN, centre.z - radius - r]);
                    }
                }
            }
            _ => {}
        }
    }
    min[2] -= 1.0;
    (0..3)
        .all(|i| min[i] <= max[i])
        .then_some(lensc_runtime::moves::Blank { min, max })
}

/// Whether the minor arc from `a` to `b` (each from the centre, as
/// (across, z)) passes straight over its centre (`up` 1) or straight
/// under it (`up` -1): that point of the circle lies between the ends, on
/// the arc's side of the turn.
fn passes_straight(a: (f64, f64), b: (f64, f64), up: f64) -> bool {
    let cross = |p: (f64, f64), q: (f64, f64)| p.0 * q.1 - p.1 * q.0;
    let top = (0.0, up);
    let turn = cross(a, b);
    let (first, second) = (cross(a, top), cross(top, b));
    if turn >= 0.0 {
        first >= 0.0 && second >= 0.0
    } else {
        first <= 0.0 && second <= 0.0
    }
}

/// The program's header: provenance, units, surface, the tool, the raster
/// and its optimisation, and the machine in words.
fn header_lines(
    spec: &RasterSpec,
    prov: &Provenance,
    path: &RasterPath,
    optimised: &Summary,
) -> Vec<String> {
    let (head, raster) = (&spec.head, &spec.raster);
    let mut header = parts::header(
        head,
        prov,
        "units mm; X Y Z of the control point, +Z out of the material; no cutter compensation",
    );
    header.push(format!("tool {}: {}", head.names.tool, spec.tool_words));
    header.push(format!(
        "strategy {}: raster along {}, {}, stepover {} um, {}, {} passes, {} points",
        head.names.strategy,
        if raster.along == Axis::X { "x" } else { "y" },
        if raster.zigzag { "zigzag" } else { "one way" },
        exact_in(raster.stepover, "um"),
        lensc_runtime::emit::tolerance_words(raster.chord_tolerance),
        path.pass_count,
        path.point_count
    ));
    header.push(lensc_runtime::emit::optimisation_words(optimised));
    header.push(format!(
        "machine {}: {} 3-axis mill",
        head.names.machine, head.dialect.name
    ));
    // As the report's `cutting_time_s`: the cut's length at the feed.
    header.push(format!(
        "estimated cutting time {}",
        lensc_runtime::post::header::duration(path.cut_length / spec.feed)
    ));
    header
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::moves::{Move, Plane, Position};

    /// One pass across a circle of radius 10 mm about (0, 0, `centre_z`),
    /// from x = -1 to 1 mm, as a Klartext raster writes it.
    fn pass(centre_z: f64, z_ends: f64) -> Vec<Move> {
        let at = |x: f64, z: f64| Position {
            x,
            y: 0.0,
            z,
            c: f64::NAN,
        };
        vec![
            Move::Rapid(at(-1.0, z_ends)),
            Move::Arc {
                to: at(1.0, z_ends),
                centre: at(0.0, centre_z),
                plane: Plane::Zx,
                ccw: centre_z > z_ends,
                feed: None,
            },
        ]
    }

    #[test]
    fn a_bowls_blank_tops_at_its_arcs_ends_and_a_domes_at_its_crown() {
        let ball = RasterTool::Ball { radius: 0.5 };
        let end = 99f64.sqrt();
        // A bowl: the arc passes under its centre, its ends are its top
        // (this blank was 19.5 mm tall: the circle's top, not the arc's).
        let bowl = blank(&pass(10.0, 10.0 - end), ball).unwrap();
        assert!((bowl.max[2] - (10.0 - end - 0.5)).abs() < 1e-12, "{bowl:?}");
        assert!((bowl.min[2] - (0.0 - 0.5 - 1.0)).abs() < 1e-12, "{bowl:?}");
        // A dome: the arc passes over its centre, its crown is its top.
        let dome = blank(&pass(-10.0, end - 10.0), ball).unwrap();
        assert!((dome.max[2] - (0.0 - 0.5)).abs() < 1e-12, "{dome:?}");
        assert!(
            (dome.min[2] - (end - 10.0 - 0.5 - 1.0)).abs() < 1e-12,
            "{dome:?}"
        );
    }
}
