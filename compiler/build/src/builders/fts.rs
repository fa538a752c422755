//! Building a spiral turning job, with a fast tool servo (`fts_spiral` on
//! an `fts_lathe`, seed 003) or a slow one (`spiral_turning` on an
//! `sts_lathe`, Z carrying the surface): the lowered spiral (its settling
//! offset and tool checks were made in lowering) planned and streamed into
//! the program, the servo's following and the cut simulated as it is
//! written, and the report of what it makes.

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::diagnostics::RuntimeError;
use lensc_lang::lower::job::SpiralSpec;
use lensc_runtime::emit::fts::FtsProgram;
use lensc_runtime::plan::fts::{Planner, SpindleSpeed};
use lensc_runtime::post::ProgramError;
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::Sweep;
use std::path::Path;

use crate::evaluate::evaluator;
use crate::height_map::{self, LatheFrame};
use crate::output::Built;
use crate::parts;
use crate::report;
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
    let window = height_map::window(head, height_map::lathe_centre(&lowered.domain, apertures));
    let grid = window.polar();
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
    let summary = planned.map_err(|error| {
        vec![
            RuntimeError::Spiral {
                error,
                speed: &p.spiral.speed,
                axis,
            }
            .at(site),
        ]
    })?;
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
    let spiral = report::Spiral::new(
        &summary,
        &p.spiral,
        p.settling.as_ref(),
        p.servo.as_ref(),
        p.nose_radius,
    );
    let toolpath = if p.slow {
        report::Toolpath::SpiralTurning(spiral)
    } else {
        report::Toolpath::FtsSpiral(spiral)
    };
    let mut plots = crate::plots::PlotSeries::default();
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
    let height_map = report::HeightMap::new(
        &map,
        &window,
        "columns at spindle angles (column step in rad), rows at radii",
        p.spiral.feed_per_rev,
    );
    let simulation = simulation(following, height_map, data_rate, p.slow, &mut plots);
    let mut report = parts::report(head, prov, &program_name, &text, toolpath, simulation);
    if let Some((name, table)) = beside.first() {
        report.program.fts_table = Some(report::FtsTable {
            file: name.clone(),
            rows: table.lines().saturating_sub(2),
        });
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

/// A spiral's simulation for its report: the fast axis's following where
/// it has a servo model (at `data_rate`, Hz; its series go into `plots`),
/// and the height map either way.
fn simulation(
    following: Option<lensc_runtime::verify::follow::FollowingSimulation>,
    height_map: report::HeightMap,
    data_rate: f64,
    slow: bool,
    plots: &mut crate::plots::PlotSeries,
) -> report::Simulation {
    let Some(sim) = following else {
        return report::Simulation::Skipped(report::Skipped {
            skipped: if slow {
                "slow tool servo: Z is a machine axis, with no servo model here"
            } else {
                "the fast axis has no servo model"
            },
            height_map: Some(height_map),
        });
    };
    let f = sim.finish();
    let following = report::Following::new(&f, data_rate, height_map);
    plots.following = Some(crate::plots::FollowingSeries {
        by_radius: f.by_radius,
        samples: f.samples,
        data_rate_hz: data_rate,
        max_error: (f.max_error, f.max_error_at),
    });
    report::Simulation::Following(following)
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
