//! Building a roller helix job (seed 002): a flat design wrapped onto a
//! roller, cut on a slow-tool-servo lathe along a helix (Liu et al. eq 5),
//! rough then finish, the nose centre exact in the cutting plane (the
//! section-4 tool checks were made in lowering); the program streamed like
//! the spiral's, the cut simulated as a height map.

use std::path::Path;

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::lower::diagnostics::RuntimeError;
use lensc_lang::lower::job::RollerSpec;
use lensc_runtime::emit::roller::RollerProgram;
use lensc_runtime::plan::roller::plan_roller_helix_into;
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;
use lensc_runtime::verify::heightmap::Sweep;

use crate::evaluate::evaluator;
use crate::height_map::{self, RollerFrame};
use crate::output::Built;
use crate::parts;
use crate::report;
use crate::spool::{Sink, cannot_spool};

/// Builds one `roller_helix` job, or says why it cannot be built.
pub fn build(
    spec: &RollerSpec,
    prov: &Provenance,
    spool_dir: Option<&Path>,
) -> Result<Built, Vec<Diagnostic>> {
    let (head, helix, rt, check) = (&spec.head, &spec.helix, &spec.tool, &spec.check);
    let dialect = &head.dialect;
    let site = head.site;
    let not_printable = |e| vec![parts::not_printable(head, e)];
    let deg = |a: f64| trim_num(a.to_degrees());
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    let (rho, roller_radius, spindle_speed) =
        (rt.nose_radius, helix.roller_radius, spec.spindle_speed);
    let (z_start, z_end, design_y) = (helix.z_start, helix.z_end, spec.design_y);
    let pass_words: Vec<String> = helix
        .passes
        .iter()
        .map(|p| {
            format!(
                "c step {}°, pitch {} um, allowance {} um",
                deg(p.c_step),
                trim_num(p.pitch * 1000.0),
                trim_num(p.finish_allowance * 1000.0)
            )
        })
        .collect();
    let header = vec![
        format!("lensc {}: job {}", prov.lensc_version, head.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        format!(
            "units mm; X is {} of the nose centre about the roller axis, Z along the roller, C the spindle angle in degrees counted on from the start",
            lensc_runtime::emit::x_word(dialect)
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
            "strategy {}: roller helix from z = {} to {} mm at {} rpm; passes: {}",
            head.names.strategy,
            trim_num(z_start),
            trim_num(z_end),
            trim_num(spindle_speed * 60.0 / (2.0 * std::f64::consts::PI)),
            pass_words.join("; ")
        ),
        format!(
            "machine {}: {} slow-tool-servo lathe",
            head.names.machine, dialect.name
        ),
    ];
    let resolution = head.resolution;
    let mut program = RollerProgram::new(
        dialect,
        &head.name,
        &header,
        resolution,
        spec.safe_x,
        spindle_speed,
    )
    .map_err(not_printable)?;
    let mut sink = Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, site)])?;
    // The height map over the window, from the printed points of every
    // pass (the finish pass's envelope lies below the rough one's).
    let window = height_map::window(
        head,
        ((z_start + z_end) / 2.0, (design_y.0 + design_y.1) / 2.0),
    );
    let grid = window.roller(roller_radius);
    let mut sweep = Sweep::new(grid, rho);
    let mut current_pass = usize::MAX;
    let mut write_error: Option<ProgramError> = None;
    let planned = plan_roller_helix_into(helix, rho, kernel.as_ref(), |pass, pts| {
        if pass != current_pass {
            sweep.lift();
            current_pass = pass;
        }
        let printed = |v: f64| lensc_runtime::verify::simulate::as_printed(v, resolution);
        for q in pts {
            sweep.point(q.c, printed(q.z), printed(q.x));
        }
        if write_error.is_none()
            && let Err(e) = program.extend(pass, pts)
        {
            write_error = Some(e);
        }
        match program.take_text() {
            Ok(t) => sink.push(t),
            Err(e) => write_error = write_error.take().or(Some(e)),
        }
    });
    let path = planned.map_err(|e| vec![RuntimeError::Roller(e).at(site)])?;
    if let Some(e) = write_error {
        return Err(not_printable(e));
    }
    let rest = program.finish().map_err(not_printable)?;
    sink.push(rest);
    let text = sink.finish().map_err(|e| vec![cannot_spool(&e, site)])?;
    let program_name = head.program_name();
    let section = report::RollerHelix::new(&path, check, rt, roller_radius);
    let (points, time) = (section.cut_points, section.cutting_time_s);
    let toolpath = report::Toolpath::RollerHelix(section);
    let frame = RollerFrame {
        kernel: kernel.as_ref(),
        window,
        roller_radius,
        domain: lowered.domain,
    };
    let map = sweep.finish(&frame);
    let plots = crate::plots::PlotSeries {
        form_error: Some(height_map::form_error_series(
            &map,
            &frame,
            &window,
            window.spacing,
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
        "columns at spindle angles (column step in rad; design y = roller radius × angle), rows along the roller axis (design x)",
        finish_pitch,
    );
    let report = parts::report(
        head,
        prov,
        &program_name,
        &text,
        toolpath,
        report::Simulation::HeightMap(report::HeightMapOnly { height_map }),
    );
    Ok(Built {
        report_name: format!("{}.report.json", head.name),
        program_name,
        program: text,
        report,
        beside: Vec::new(),
        cut_points: points,
        cutting_time: time,
        plots,
        warnings: Vec::new(),
    })
}
