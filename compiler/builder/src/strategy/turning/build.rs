//! Building a profile-turning job: the profile planned along the surface's
//! section as the JIT evaluates it, the seams and the centre the nose
//! cannot reach reported, the program emitted, and the cut simulated along
//! the whole profile for the report.

use super::TurningSpec;
use crate::diagnostics::RuntimeError;
use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_runtime::moves::Move;
use lensc_runtime::plan::turning::Toolpath;
use lensc_runtime::surface::SectionAlongX;

use crate::context::BuildContext;
use crate::evaluate::evaluator;
use crate::output::{Built, ProgramText};
use crate::plots::profile_series;
use crate::report;

/// Builds one profile-turning job, or says why it cannot be built.
pub(super) fn build(spec: &TurningSpec, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
    let prov = cx.prov;
    let (head, job) = (&spec.head, &spec.job);
    let lowered = &head.surface.lowered;
    // The planner follows the surface as the JIT evaluates it.
    let (kernel, _) = evaluator(&lowered.tape);
    let profile = SectionAlongX(kernel.as_ref());
    let path =
        lensc_runtime::plan::turning::plan_profile_turning(job, &profile).map_err(|errs| {
            errs.into_iter()
                .map(|e| super::errors::error(e, head.site))
                .collect::<Vec<_>>()
        })?;
    let warnings = warnings(spec, &path);
    let emitted = match lensc_runtime::emit::turning::emit(
        job,
        &path,
        prov,
        &head.start,
        &head.control.header_line(head.start.control),
        head.spline,
    ) {
        Ok(e) => e,
        Err(e) => {
            let mut all = warnings;
            all.push(RuntimeError::Program(e).at(head.site));
            return Err(all);
        }
    };
    let lensc_runtime::emit::Emitted {
        text,
        stream,
        optimised,
    } = emitted;
    let mut plots = crate::plots::PlotSeries::default();
    let simulation = if job.tool.centre_height == 0.0 {
        use lensc_runtime::surface::Profile as _;
        let design = |x: f64| profile.point(x).z;
        let range = (
            job.strategy.end_radius,
            job.strategy
                .start_radius
                .unwrap_or(job.surface.aperture_radius),
        );
        // The real tool: its measured edge when it names one.
        let cut = crate::context::program_cut_by(head, &text, &job.tool.nose(), &design, range);
        plots.profile = Some(profile_series(
            &cut,
            &design,
            &stream,
            ("nose", job.tool.nose_radius),
            job.machine.resolution,
            path.seams.iter().map(|s| s.at_radius).collect(),
        ));
        report::Simulation::Profile((&cut).into())
    } else {
        report::Simulation::Skipped(report::Skipped {
            skipped: "the edge is set off the spindle axis: the program's X is not the nose centre's radius",
            height_map: None,
        })
    };
    let mut toolpath = report::ProfileTurning::new(job, &path, &optimised);
    toolpath.edge_profile = spec.edge.clone();
    let mut built = crate::context::built(
        head,
        prov,
        ProgramText::Memory(text),
        report::Toolpath::ProfileTurning(toolpath),
        simulation,
        plots,
        (path.cut_points, path.cutting_time()),
    );
    // A profile-turning report names a surface written in place "" (the
    // other strategies give its kind), as it always has.
    built.report.surface.surface = head.names.surface_declared.clone();
    built.warnings = warnings;
    built
        .warnings
        .extend(crate::plausibility::air_warnings(head, &stream));
    Ok(built)
}

/// What the path leaves uncut: the centre, when the edge is set off the
/// spindle axis (W0004), and the concave corners the nose cannot reach
/// (W0003).
fn warnings(spec: &TurningSpec, path: &Toolpath) -> Vec<Diagnostic> {
    let (head, job) = (&spec.head, &spec.job);
    let (file, span) = head.site;
    let mut out = Vec::new();
    let h = job.tool.centre_height.abs();
    let inmost = path
        .moves
        .iter()
        .filter_map(|m| match *m {
            Move::Linear { to, .. } => Some(to.x.abs()),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    if h > 0.0 && inmost < h {
        out.push(
            Diagnostic::warning(
                codes::CENTRE_LEFT_UNCUT,
                format!(
                    "the tool's edge is {} mm off the spindle axis: it cannot reach radii below that, and a pip is left at the centre",
                    trim_num(h)
                ),
                file,
                span,
            )
            .with_label("this job")
            .with_help("set the tool on centre; the program corrects X for the height given"),
        );
    }
    if let Some(deepest) = path.seams.iter().max_by(|a, b| a.depth.total_cmp(&b.depth)) {
        let (first, last) = (&path.seams[0], &path.seams[path.seams.len() - 1]);
        let where_ = if path.seams.len() == 1 {
            format!("the concave corner at r = {} mm", trim_num(first.at_radius))
        } else {
            format!(
                "{} concave corners between r = {} and {} mm",
                path.seams.len(),
                trim_num(first.at_radius),
                trim_num(last.at_radius)
            )
        };
        out.push(
            Diagnostic::warning(
                codes::SEAM_LEFT_UNCUT,
                format!(
                    "the {} mm nose cannot reach into {where_}: up to {} um of material is left above the design (at r = {} mm)",
                    trim_num(job.tool.nose_radius),
                    trim_num(deepest.depth * 1000.0),
                    trim_num(deepest.at_radius)
                ),
                file,
                span,
            )
            .with_label("this job")
            .with_help("the program cuts the gouge-free envelope; the report lists every corner and its depth; a smaller nose follows them closer"),
        );
    }
    out
}
