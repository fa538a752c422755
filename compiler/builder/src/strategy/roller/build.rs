//! Building a roller helix job (seed 002): a flat design wrapped onto a
//! roller, cut on a slow-tool-servo lathe along a helix (Liu et al. eq 5),
//! rough then finish, the nose centre exact in the cutting plane (the
//! section-4 tool checks were made in lowering), placed by the tool's
//! measured edge where it names one; the program streamed like the
//! spiral's, the cut simulated as a height map swept by the same edge.

use super::RollerSpec;
use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::exact_in;
use lensc_runtime::emit::roller::{RollerLimits, RollerProgram};
use lensc_runtime::machine::edge::Nose;
use lensc_runtime::plan::roller::plan_roller_helix_edged;
use lensc_runtime::post::Provenance;
use lensc_runtime::verify::heightmap::Cutter;
use lensc_runtime::verify::heightmap::NosePath;

use crate::context::{self as parts, BuildContext};
use crate::evaluate::evaluator;
use crate::height_map::{self, RollerFrame, Simulation};
use crate::output::Built;
use crate::report;
use lensc_runtime::verify::window::split;

/// Builds one `roller_helix` job, or says why it cannot be built; its
/// program spooled (`to`) is read back (`read`) as it is spooled.
pub(super) fn build(spec: &RollerSpec, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
    let (prov, _to) = (cx.prov, cx.to);
    let (head, helix, rho) = (&spec.head, &spec.helix, spec.tool.nose_radius);
    let site = head.site;
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    // The contact searches need z, ∂z/∂x and ∂²z/∂x² only.
    let (section, _) = evaluator(&lowered.tape.axial_section());
    let resolution = head.resolution;
    let printed_at = lensc_runtime::verify::simulate::Printed::new(resolution);
    // The header's time, at the spindle's pace, from the design's survey.
    let pace = lensc_runtime::plan::roller::spindle_time(helix, rho, kernel.as_ref())
        .map_err(|e| vec![super::errors::error(e, site)])?;
    let mut program = RollerProgram::new(
        &head.dialect,
        &head.name,
        &header_lines(spec, prov, pace),
        RollerLimits {
            resolution,
            max_feed: spec.max_feed,
        },
        spec.safe_x,
        spec.spindle_speed,
    )
    .map_err(|e| vec![parts::not_printable(head, e)])?;
    program
        .call_tool(&head.start)
        .map_err(|e| vec![parts::not_printable(head, e)])?;
    let mut sink = cx.sink(head)?;
    // The height map over the window, from the printed points of every
    // pass (the finish pass's envelope lies below the rough one's).
    let (design_y, z) = (spec.design_y, (helix.z_start, helix.z_end));
    let window = height_map::window(
        head,
        height_map::roller_extent(&lowered.domain, z, design_y),
        height_map::WHOLE_CELLS_NOSE,
        |w| split(&w.roller(helix.roller_radius, helix.y_start), None),
    );
    let grid = window.roller(helix.roller_radius, helix.y_start);
    // The nose as measured, where the tool names its edge: the planner
    // places each centre by it and the simulation sweeps it.
    let edge = spec.edge.as_ref().map(|(m, _)| &m.profile);
    let cutter = Cutter::Nose {
        radius: rho,
        edge: edge.map(|e| std::sync::Arc::new(e.clone())),
    };
    let mut sweep = Simulation::of(grid, split(&grid, None), cutter);
    let mut current_pass = usize::MAX;
    let planned = plan_roller_helix_edged(
        helix,
        &Nose { radius: rho, edge },
        kernel.as_ref(),
        section.as_ref(),
        |pass, pts| {
            if pass != current_pass {
                sweep.path().lift();
                current_pass = pass;
            }
            let printed = |v: f64| printed_at.round(v);
            for q in pts {
                sweep.path().point(q.c, printed(q.z), printed(q.x));
            }
            sink.extend(|| program.extend(pass, pts));
            sink.push(program.take_text());
            sink.planned(pts.len());
        },
    );
    let mut path =
        planned.map_err(|e| vec![super::errors::planned_error(e, site, spec.edge_site)])?;
    let limited = program.feed_limited().to_vec();
    let mut sink = sink.written(head)?;
    sink.push(
        program
            .finish()
            .map_err(|e| vec![parts::not_printable(head, e)])?,
    );
    let text = sink.finish(site)?;
    // The moves the feed limit slowed take longer than the spindle's pace.
    for (pass, l) in path.passes.iter_mut().zip(&limited) {
        pass.time = pass
            .time
            .map(|t| t + l.added_time * pass.cycle_offsets.len() as f64);
    }
    let mut section = report::RollerHelix::new(&path, &limited, &spec.check, &spec.tool, helix);
    section.edge_profile = spec.edge.as_ref().map(|(_, r)| r.clone());
    let cut = (section.cut_points, section.cutting_time_s);
    // The height alone: the frame asks nothing else of the design.
    let heights = crate::height_map::DesignHeights::of(&head.surface);
    let frame = RollerFrame {
        kernel: heights.kernel.as_ref(),
        correction: heights.correction.as_ref(),
        window,
        roller_radius: helix.roller_radius,
        y_start: helix.y_start,
        domain: lowered.domain,
        lenslets: head.surface.lenslets.as_ref(),
    };
    let (map, raster) = sweep.finish(&frame, &window, window.spacing);
    let plots = crate::plots::PlotSeries {
        form_error: Some(height_map::form_error_series(
            raster,
            &window,
            (
                "along the roller axis, design x (mm)",
                "around the roller, design y (mm)",
            ),
        )),
        ..Default::default()
    };
    let finish_pitch = helix.passes.last().map_or(0.0, |p| p.pitch);
    let height_map = report::HeightMap::new(
        &map,
        &window,
        "columns at spindle angles (column step in rad; design y = the design's first y + roller radius × angle), rows along the roller axis (design x)",
        finish_pitch,
    );
    let mut built = parts::built(
        head,
        prov,
        text,
        report::Toolpath::RollerHelix(section),
        report::Simulation::HeightMap(report::HeightMapOnly { height_map }),
        plots,
        cut,
    );
    built.warnings.extend(seam_warning(spec, kernel.as_ref()));
    Ok(built)
}

/// W0006: where the roller closes, the design's last row meets its first
/// (design y = y_start + 2πR against y_start); a step there higher than
/// the machine's resolution is cut as a step, all along the helix.
pub fn seam_warning(
    spec: &RollerSpec,
    design: &dyn lensc_runtime::surface::ir::SurfaceFn,
) -> Option<Diagnostic> {
    let (head, helix) = (&spec.head, &spec.helix);
    let (step, _) = lensc_runtime::plan::roller::seam_step(
        design,
        helix.roller_radius,
        helix.y_start,
        (helix.z_start, helix.z_end),
        401,
    );
    if step.is_nan() || step <= head.resolution {
        return None;
    }
    let (file, span) = head.site;
    let ends = (
        helix.y_start,
        helix.y_start + std::f64::consts::TAU * helix.roller_radius,
    );
    Some(
        Diagnostic::warning(
            codes::SEAM_STEP,
            format!(
                "the design does not close around the roller: its ends (design y = {} and {} mm) differ in height by up to {} um, so a step is cut where the roller closes",
                trim_num(ends.0),
                trim_num(ends.1),
                trim_num(step * 1000.0)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("make the design periodic over its y extent L around the roller (the same height at its first y and at its first y + L), for instance a whole number of periods"),
    )
}

/// The program's header: provenance, units, the surface and tool, the
/// helix and its passes, and the machine in words.
fn header_lines(spec: &RollerSpec, prov: &Provenance, pace: Option<f64>) -> Vec<String> {
    let (head, helix) = (&spec.head, &spec.helix);
    let deg = |a: f64| exact_in(a, "°");
    let pass_words: Vec<String> = helix
        .passes
        .iter()
        .map(|p| {
            format!(
                "c step {}°, pitch {} um, allowance {} um",
                deg(p.c_step),
                exact_in(p.pitch, "um"),
                exact_in(p.finish_allowance, "um")
            )
        })
        .collect();
    let units = format!(
        "units mm; X is {} of the nose centre about the roller axis, Z along the roller, C the spindle angle in degrees counted on from the start",
        lensc_runtime::emit::x_word(&head.dialect)
    );
    let mut lines = parts::nose_centre_header(head, prov, &units, spec.tool.nose_radius);
    if let Some((m, _)) = &spec.edge
        && let Some(tool) = lines.last_mut()
    {
        tool.push_str(&format!(
            ", edge profile {}: each centre clears the design with the measured edge at its angle of contact (+ towards +Z)",
            m.source
        ));
    }
    lines.push(format!(
        "strategy {}: roller helix from z = {} to {} mm at {} rpm, C 0 at design y = {} mm; passes: {}",
        head.names.strategy,
        exact_in(helix.z_start, "mm"),
        exact_in(helix.z_end, "mm"),
        exact_in(spec.spindle_speed, "rpm"),
        exact_in(helix.y_start, "mm"),
        pass_words.join("; ")
    ));
    lines.push(format!(
        "machine {}: {} slow-tool-servo lathe",
        head.names.machine, head.dialect.name
    ));
    if let Some(t) = pace {
        lines.push(format!(
            "estimated cutting time {} at the spindle's pace (a move slowed to the feed limit adds to it)",
            lensc_runtime::post::header::duration(t)
        ));
    }
    lines
}
