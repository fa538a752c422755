//! Building a profile-grinding job with a spherical wheel on a 2-axis
//! grinder (seed 001): the wheel centres planned along the profile (Kim et
//! al.), kept within the travel, the program written with each interval at
//! its own feed, and the cut simulated along the whole profile.

use super::GrindingSpec;
use lensc_grammar::Diagnostic;
use lensc_lang::lower::exact_in;
use lensc_runtime::plan::approach::Approach;
use lensc_runtime::surface::SectionAlongX;

use crate::context::{self as parts, BuildContext};
use crate::evaluate::evaluator;
use crate::output::{Built, ProgramText};
use crate::report;

/// Builds a `profile_grinding` job on a `grinder_2axis`.
pub(super) fn build(spec: &GrindingSpec, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
    let prov = cx.prov;
    let (head, grinding) = (&spec.head, &spec.grinding);
    let dialect = &head.dialect;
    let feed = grinding.feed;
    let lowered = &head.surface.lowered;
    let (kernel, _) = evaluator(&lowered.tape);
    let profile = SectionAlongX(kernel.as_ref());
    let path = lensc_runtime::plan::grinding::plan_profile_grinding(grinding, &profile)
        .map_err(|e| vec![super::errors::error(e, head.site)])?;
    let retract = spec.retract;
    let top = path
        .points
        .iter()
        .map(|q| q.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let safe_z = top + retract;
    // The wheel comes down at the cut's first point over the design
    // itself: a grinding pass takes µm from a pre-formed blank.
    let approach = path.points.first().map(|first| Approach {
        x: first.x,
        safe_z,
        top,
        material: first.z,
        start_z: first.z,
        cutting_speed: feed,
        max_feed: spec.max_feed,
        retract,
    });
    let stream =
        lensc_runtime::emit::grinding::grinding_moves(&path, feed, approach, spec.spindle_speed);
    if let Some(e) = parts::travel_error(head, &stream) {
        return Err(vec![e]);
    }
    let units = format!(
        "units mm; X is {}, Z along the spindle axis, +Z out of the material",
        lensc_runtime::emit::x_word(dialect)
    );
    let mut header = parts::header(head, prov, &units);
    header.push(format!(
        "tool {}: spherical wheel, diameter {} mm",
        head.names.tool,
        exact_in(grinding.wheel_diameter, "mm")
    ));
    header.push(format!(
        "strategy {}: profile grinding from x = {} to {} mm, interval {} um, feed {}, smoothness {}; {} intervals, each at its own feed",
        head.names.strategy,
        exact_in(grinding.start, "mm"),
        exact_in(grinding.end, "mm"),
        exact_in(grinding.interval, "um"),
        feed_as_stated(feed),
        exact_in(grinding.smoothness, ""),
        path.segments
    ));
    header.push(format!(
        "machine {}: {} 2-axis grinder",
        head.names.machine, dialect.name
    ));
    let resolution = head.resolution;
    let text = lensc_runtime::emit::grinding::emit_grinding(
        dialect,
        &head.name,
        &header,
        &stream,
        resolution,
        &head.start,
    )
    .map_err(|e| vec![parts::not_printable(head, e)])?;
    let toolpath = report::Toolpath::ProfileGrinding((&path).into());
    // What the wheel's section (a circle of its radius about the centre)
    // leaves along the programmed centres.
    use lensc_runtime::surface::Profile as _;
    let cut = parts::program_cut(
        head,
        &text,
        grinding.wheel_diameter / 2.0,
        &|x: f64| profile.point(x).z,
        (grinding.start, grinding.end),
    );
    let plots = crate::plots::PlotSeries {
        profile: Some(crate::plots::profile_series(
            &cut,
            &|x: f64| profile.point(x).z,
            &stream,
            ("wheel", grinding.wheel_diameter / 2.0),
            resolution,
            Vec::new(),
        )),
        ..Default::default()
    };
    let mut built = parts::built(
        head,
        prov,
        ProgramText::Memory(text),
        toolpath,
        report::Simulation::Profile((&cut).into()),
        plots,
        (path.points.len(), path.total_time),
    );
    built.warnings = crate::plausibility::air_warnings(head, &stream);
    Ok(built)
}

/// The feed in um/s (seed 001's unit) or mm/min (the program's F word),
/// whichever states it exactly in fewer digits: a job's `20 mm/min` is
/// 333.333… um/s, which no short decimal in um/s reads back to.
fn feed_as_stated(feed: f64) -> String {
    let [um_s, mm_min] = ["um/s", "mm/min"].map(|unit| format!("{} {unit}", exact_in(feed, unit)));
    if mm_min.len() < um_s.len() {
        mm_min
    } else {
        um_s
    }
}

#[cfg(test)]
mod tests {
    use super::feed_as_stated;

    #[test]
    fn a_feed_is_stated_in_the_unit_that_prints_it_exactly() {
        let per_min = 1.0 / 60.0;
        assert_eq!(feed_as_stated(20.0 * per_min), "20 mm/min");
        assert_eq!(feed_as_stated(20e-3), "20 um/s");
        assert_eq!(feed_as_stated(10e-3), "10 um/s");
    }
}
