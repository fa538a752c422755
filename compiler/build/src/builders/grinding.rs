//! Building a profile-grinding job with a spherical wheel on a 2-axis
//! grinder (seed 001): the wheel centres planned along the profile (Kim et
//! al.), kept within the travel, the program written with each interval at
//! its own feed, and the cut simulated along the whole profile.

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::job::{GrindingSpec, JobHead};
use lensc_runtime::plan::grinding::GrindingError;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::SectionAlongX;
use serde_json::json;

use crate::driver::{Built, ProgramText, evaluator};
use crate::parts;

/// Builds a `profile_grinding` job on a `grinder_2axis`.
pub fn build(spec: &GrindingSpec, prov: &Provenance) -> Result<Built, Vec<Diagnostic>> {
    let (head, grinding) = (&spec.head, &spec.grinding);
    let dialect = &head.dialect;
    let feed = grinding.feed;
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    let profile = SectionAlongX(kernel.as_ref());
    let path = lensc_runtime::plan::grinding::plan_profile_grinding(grinding, &profile)
        .map_err(|e| vec![grinding_diagnostic(head, e)])?;
    let retract = spec.retract;
    let top = path
        .points
        .iter()
        .map(|q| q.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let safe_z = top + retract;
    if let Some(e) = parts::travel_error(
        head,
        &lensc_runtime::emit::grinding::grinding_moves(&path, feed, safe_z),
    ) {
        return Err(vec![e]);
    }
    let units = format!(
        "units mm; X is {}, Z along the spindle axis, +Z out of the material",
        lensc_runtime::emit::x_word(dialect)
    );
    let mut header = parts::header(head, prov, &units);
    header.push(format!(
        "tool {}: spherical wheel, diameter {} mm; coordinates are the wheel centre",
        head.names.tool,
        trim_num(grinding.wheel_diameter)
    ));
    header.push(format!(
        "strategy {}: profile grinding from x = {} to {} mm, interval {} um, feed {} um/s, smoothness {}; {} intervals, each at its own feed",
        head.names.strategy,
        trim_num(grinding.start),
        trim_num(grinding.end),
        trim_num(grinding.interval * 1000.0),
        trim_num(feed * 1000.0),
        trim_num(grinding.smoothness),
        path.segments
    ));
    header.push(format!(
        "machine {}: {} 2-axis grinder",
        head.names.machine, dialect.name
    ));
    let resolution = head.resolution;
    let text = lensc_runtime::emit::grinding::emit_grinding(
        dialect, &head.name, &header, &path, feed, safe_z, resolution,
    )
    .map_err(|e| vec![parts::not_printable(head, e)])?;
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
    let program_name = head.program_name();
    let text = ProgramText::Memory(text);
    let mut report = parts::report(head, prov, &program_name, &text, toolpath);
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
        report_name: format!("{}.report.json", head.name),
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

fn grinding_diagnostic(p: &JobHead, e: GrindingError) -> Diagnostic {
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
