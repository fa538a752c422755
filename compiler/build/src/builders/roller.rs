//! Building a roller helix job (seed 002): a flat design wrapped onto a
//! roller, cut on a slow-tool-servo lathe along a helix (Liu et al. eq 5),
//! rough then finish, the nose centre exact in the cutting plane; the
//! section-4 tool checks; the program streamed like the spiral's.

use lensc_runtime::post::Dialect;
use std::path::Path;

use lensc_grammar::Diagnostic;
use lensc_runtime::emit::roller::RollerProgram;
use lensc_runtime::plan::roller::{
    DesignRegion, HelixPass, RollerError, RollerHelix, RollerTool, check_roller_tool,
    plan_roller_helix_into,
};
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::analysis::Domain;
use serde_json::json;

use crate::driver::{Built, evaluator};
use crate::fts_job::{Sink, cannot_spool};
use crate::height_map::{self, RollerFrame, Window};
use crate::parts::Parts;
use lensc_lang::check::{CheckedJob, trim_num};
use lensc_lang::codes;
use lensc_lang::value::{self, Object};
use lensc_runtime::verify::heightmap::Sweep;

/// Builds one `roller_helix` job, or says why it cannot be built.
pub fn build(
    job: &CheckedJob,
    prov: &Provenance,
    dialect: &Dialect,
    spool_dir: Option<&Path>,
) -> Result<Built, Vec<Diagnostic>> {
    let parts = Parts::of(job, dialect);
    let (surface, tool, machine, strategy) =
        (parts.surface, parts.tool, parts.machine, parts.strategy);
    let (file, span) = parts.site();
    let err = |code: &'static str, msg: String| parts.error(code, msg);
    let mut errors = Vec::new();
    if machine.kind.name != "sts_lathe" {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "roller helix turning needs an `sts_lathe` (C, Z, X); this machine is a `{}`",
                machine.kind.name
            ),
        ));
    }
    if tool.kind.name != "round_nose" {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "roller helix turning needs a `round_nose` tool; this is a `{}`",
                tool.kind.name
            ),
        ));
    }
    let roller = (surface.kind.name == "wrap")
        .then(|| value::object(&surface.fields, "onto"))
        .flatten()
        .and_then(|r| value::num(&r.fields, "radius"));
    if roller.is_none() {
        errors.push(
            err(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "roller helix turning needs a design wrapped onto a roller; this surface is a `{}`",
                    surface.kind.name
                ),
            )
            .with_help("write `wrap(design, onto: roller(radius: …))`"),
        );
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let roller_radius = roller.expect("checked above");
    let (m, t, st) = (&machine.fields, &tool.fields, &strategy.fields);
    let lowered = lensc_lang::lower::surface::lower_surface(surface).map_err(|e| {
        vec![err(
            codes::UNSUPPORTED_COMBINATION,
            format!("this surface cannot be evaluated yet: {e:?}"),
        )]
    })?;
    let Domain::Rect {
        x: design_x,
        y: design_y,
    } = lowered.domain
    else {
        return Err(vec![err(
            codes::UNSUPPORTED_COMBINATION,
            "a wrapped design needs a rectangular domain (x along the roller, y around it)".into(),
        )]);
    };
    let (kernel, _) = evaluator(&lowered.tape);
    let rho = value::num(t, "nose_radius").expect("required");
    let rt = RollerTool {
        nose_radius: rho,
        clearance_angle: value::num(t, "clearance").expect("required"),
        opening_angle: value::num(t, "included_angle").unwrap_or(std::f64::consts::PI),
    };
    let region = DesignRegion {
        x: design_x,
        y: design_y,
        samples: (401, 401),
    };
    let check = check_roller_tool(kernel.as_ref(), &region, roller_radius, &rt)
        .map_err(|e| vec![roller_diagnostic(e, job)])?;
    let deg = |a: f64| trim_num(a.to_degrees());
    if !check.radius_ok {
        errors.push(err(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} mm) is not below the design's smallest concave radius of curvature in the cutting plane ({} mm, at ({}, {}) mm; Liu et al. eq 12)",
                trim_num(rho),
                trim_num(check.min_radius_axial),
                trim_num(check.min_radius_axial_at.0),
                trim_num(check.min_radius_axial_at.1)
            ),
        ));
    }
    if !check.clearance_ok {
        errors.push(err(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the steepest slope in the cutting direction, around the roller ({}°)",
                deg(rt.clearance_angle),
                deg(check.max_slope_cutting_on_roller)
            ),
        ));
    }
    if !check.opening_ok {
        errors.push(err(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "half the tool's included angle ({}°) is not above the steepest axial slope ({}°)",
                deg(rt.opening_angle / 2.0),
                deg(check.max_slope_axial)
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let finish = value::block(st, "finish").expect("required");
    let mut passes = Vec::new();
    if let Some(rough) = value::block(st, "rough") {
        passes.push(HelixPass {
            c_step: value::num(rough, "c_step").expect("required"),
            pitch: value::num(rough, "pitch").expect("required"),
            finish_allowance: value::num(rough, "finish_allowance").expect("required"),
        });
    }
    passes.push(HelixPass {
        c_step: value::num(finish, "c_step").expect("required"),
        pitch: value::num(finish, "pitch").expect("required"),
        finish_allowance: 0.0,
    });
    let (z_start, z_end) = value::range(st, "z").unwrap_or(design_x);
    let spindle_speed = value::num(st, "spindle_speed").expect("required");
    let helix = RollerHelix {
        roller_radius,
        passes,
        z_start,
        z_end,
        // By default the blank just covers the design: its highest point,
        // found on the tool check's grid and by the refined analysis, or
        // the roller's own radius (an array's land, z = 0, around it).
        blank_radius: value::num(st, "blank_radius").unwrap_or_else(|| {
            let top =
                lensc_runtime::surface::analysis::analyse(kernel.as_ref(), &lowered.domain, 201)
                    .sag_max
                    .value;
            roller_radius + check.z_max.max(top).max(0.0) + 1e-6
        }),
        depth_of_cut: None,
        design_length_around: Some(design_y.1 - design_y.0),
        spindle_speed: Some(spindle_speed),
    };
    let max_spindle =
        value::num(value::block(m, "spindle").expect("required"), "max_speed").expect("required");
    if spindle_speed > max_spindle {
        let rpm = |w: f64| trim_num(w * 60.0 / (2.0 * std::f64::consts::PI));
        return Err(vec![err(
            codes::SPINDLE_TOO_FAST,
            format!(
                "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                rpm(spindle_speed),
                rpm(max_spindle)
            ),
        )]);
    }
    let retract = value::num(st, "retract").unwrap_or(1.0);
    let safe_x = helix.blank_radius + rho + retract;
    let names = |p: &str, o: &Object| parts.name(p, o);
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
        format!("lensc {}: job {}", prov.lensc_version, job.name.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        format!(
            "units mm; X is {} of the nose centre about the roller axis, Z along the roller, C the spindle angle in degrees counted on from the start",
            lensc_runtime::emit::x_word(dialect)
        ),
        format!(
            "coordinates are the centre of the tool nose; {}",
            parts.inverse_time_words()
        ),
        format!(
            "surface {}: {}",
            names("surface", surface),
            lensc_lang::lower::describe(surface)
        ),
        format!(
            "tool {}: round nose, nose radius {} mm",
            names("tool", tool),
            trim_num(rho)
        ),
        format!(
            "strategy {}: roller helix from z = {} to {} mm at {} rpm; passes: {}",
            names("strategy", strategy),
            trim_num(z_start),
            trim_num(z_end),
            trim_num(spindle_speed * 60.0 / (2.0 * std::f64::consts::PI)),
            pass_words.join("; ")
        ),
        format!(
            "machine {}: {} slow-tool-servo lathe",
            names("machine", machine),
            dialect.name
        ),
    ];
    let resolution = value::num(m, "resolution").expect("required");
    let mut program = RollerProgram::new(
        dialect,
        &job.name.name,
        &header,
        resolution,
        safe_x,
        spindle_speed,
    )
    .map_err(|e| vec![parts.not_printable(e)])?;
    let mut sink = Sink::new(spool_dir).map_err(|e| vec![cannot_spool(&e, file, span)])?;
    // The height map over the window, from the printed points of every
    // pass (the finish pass's envelope lies below the rough one's).
    let window = Window::of(
        job,
        ((z_start + z_end) / 2.0, (design_y.0 + design_y.1) / 2.0),
    )
    .map_err(|d| vec![d])?;
    let grid = window.roller(roller_radius);
    window.check_size(job, &grid).map_err(|d| vec![d])?;
    let mut sweep = Sweep::new(grid, rho);
    let mut current_pass = usize::MAX;
    let mut write_error: Option<ProgramError> = None;
    let planned = plan_roller_helix_into(&helix, rho, kernel.as_ref(), |pass, pts| {
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
    let path = planned.map_err(|e| vec![roller_diagnostic(e, job)])?;
    if let Some(e) = write_error {
        return Err(vec![parts.not_printable(e)]);
    }
    let rest = program.finish().map_err(|e| vec![parts.not_printable(e)])?;
    sink.push(rest);
    let text = sink
        .finish()
        .map_err(|e| vec![cannot_spool(&e, file, span)])?;
    let points: usize = path.passes.iter().map(|p| p.points).sum();
    let time: f64 = path.passes.iter().filter_map(|p| p.time).sum();
    let program_name = parts.program_name();
    let toolpath = json!({
        "strategy": "roller_helix",
        "cut_points": points,
        "cutting_time_s": time,
        "roller_radius_mm": roller_radius,
        "passes": path.passes.iter().map(|p| json!({
            "c_step_deg": p.c_step.to_degrees(),
            "pitch_mm": p.pitch,
            "finish_allowance_mm": p.finish_allowance,
            "points": p.points,
            "revolutions": p.revolutions,
            "x_min_mm": p.x_min,
            "x_max_mm": p.x_max,
            "cutting_time_s": p.time,
            "fingerprint_fnv1a64": format!("{:016x}", p.fingerprint),
        })).collect::<Vec<_>>(),
        "tool_check": {
            "min_radius_of_curvature_cutting_plane_mm": check.min_radius_axial,
            "min_radius_of_curvature_mm": check.min_radius_overall,
            "max_slope_cutting_deg": check.max_slope_cutting.to_degrees(),
            "max_slope_cutting_on_roller_deg": check.max_slope_cutting_on_roller.to_degrees(),
            "max_slope_axial_deg": check.max_slope_axial.to_degrees(),
            "nose_radius_mm": rho,
            "clearance_deg": rt.clearance_angle.to_degrees(),
            "half_included_angle_deg": rt.opening_angle.to_degrees() / 2.0,
        },
        "wrap_gap_mm": path.wrap.map(|w| w.gap),
    });
    let mut report = parts.report(prov, &program_name, &text, toolpath, &lowered);
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
    report["simulation"] = json!({
        "height_map": height_map::json(
            &map,
            &window,
            "columns at spindle angles (column step in rad; design y = roller radius × angle), rows along the roller axis (design x)",
            finish_pitch,
        )
    });
    Ok(Built {
        report_name: format!("{}.report.json", job.name.name),
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

fn roller_diagnostic(e: RollerError, job: &CheckedJob) -> Diagnostic {
    let d = |code, msg: String| {
        Diagnostic::error(code, msg, job.file, job.name.span).with_label("this job")
    };
    match e {
        RollerError::NoseTooLarge {
            nose_radius,
            min_radius,
            x,
            y,
        } => d(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} mm) is not below the design's smallest concave radius of curvature ({} mm, at ({}, {}) mm)",
                trim_num(nose_radius),
                trim_num(min_radius),
                trim_num(x),
                trim_num(y)
            ),
        ),
        RollerError::Overlap {
            circumference,
            design_length,
        } => d(
            codes::WRAP_OVERLAP,
            format!(
                "the design is {} mm around, longer than the roller's {} mm circumference",
                trim_num(design_length),
                trim_num(circumference)
            ),
        ),
        RollerError::Undefined { c, z, .. } => d(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the design is undefined where the nose must go (z = {} mm, C = {}°)",
                trim_num(z),
                trim_num(c.to_degrees() % 360.0)
            ),
        ),
        RollerError::BlankBelowDesign {
            blank_radius,
            design_top,
        } => d(
            codes::OUT_OF_RANGE,
            format!(
                "the blank's radius ({} mm) is below the top of the design ({} mm)",
                trim_num(blank_radius),
                trim_num(design_top)
            ),
        ),
        other => d(codes::UNSUPPORTED_COMBINATION, format!("{other:?}")),
    }
}
