//! Building a spiral turning job, with a fast tool servo (`fts_spiral` on
//! an `fts_lathe`, seed 003) or a slow one (`spiral_turning` on an
//! `sts_lathe`, Z carrying the surface): the lowered spiral (its settling
//! offset and tool checks were made in lowering) planned and streamed into
//! the program, the servo's following and the cut simulated as it is
//! written, and the report of what it makes.

use super::SpiralSpec;
use super::servo::{Commands, as_printed, following, program_leads};
use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::{derived_in, exact_in};
use lensc_runtime::emit::spiral::FtsProgram;
use lensc_runtime::plan::spiral::{FtsError, FtsSummary, Planner, SpindleSpeed, SpiralPoint};
use lensc_runtime::post::Provenance;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::{Cutter, NosePath};

use crate::context::{self as parts, BuildContext};
use crate::evaluate::evaluator;
use crate::height_map::{self, LatheFrame, Simulation, Window};
use crate::output::Built;
use crate::report;
use crate::spool::Sink;

/// A spiral job ready to plan: its spec and the trajectory's kernel (for
/// a compensated job, the trajectory as declared, the correction taken
/// out along each ray: `less`).
pub struct Prepared<'s> {
    pub spec: &'s SpiralSpec,
    pub kernel: Box<dyn SurfaceFn + Sync>,
    pub less: Option<crate::compensate::AlongRays>,
}

impl<'s> Prepared<'s> {
    /// Compiles the trajectory the nose centre follows.
    pub fn of(spec: &'s SpiralSpec) -> Prepared<'s> {
        let along_rays = match (&spec.trajectory_declared, &spec.correction) {
            (Some(declared), Some(c)) => c.along_rays().map(|r| (declared, r)),
            _ => None,
        };
        match along_rays {
            Some((declared, rays)) => Prepared {
                spec,
                kernel: evaluator(&declared.tape).0,
                less: Some(rays),
            },
            None => Prepared {
                spec,
                kernel: evaluator(&spec.trajectory.tape).0,
                less: None,
            },
        }
    }
    pub fn planner(&self) -> Planner<'_> {
        Planner {
            spiral: &self.spec.spiral,
            surface: self.kernel.as_ref(),
            less: self
                .less
                .as_ref()
                .map(|l| l as &dyn lensc_runtime::plan::spiral::RayCorrection),
            nose_radius: self.spec.nose_radius,
            edge: self.spec.edge.as_ref().map(|(m, _)| &m.profile),
            bounds: self.spec.bounds.clone(),
        }
    }
}

/// Builds one `fts_spiral` job, or says why it cannot be built. Spooled
/// (`to`), the program goes to a temporary file as it is written, so
/// memory stays bounded however long it is, and is read back (`read`) on
/// a thread of its own as it goes.
pub(super) fn build(spec: &SpiralSpec, cx: &BuildContext) -> Result<Built, Vec<Diagnostic>> {
    let (prov, to) = (cx.prov, cx.to);
    let (p, head) = (spec, &spec.head);
    let site = head.site;
    let not_printable = |e| vec![parts::not_printable(head, e)];
    let table_name = table_name(spec);
    let header = header_lines(spec, prov, table_name.as_deref());
    let mut program = FtsProgram::new(
        &head.dialect,
        &head.name,
        &header,
        head.resolution,
        p.spiral.chord_tolerance,
        p.safe_w,
        table_name.as_deref(),
    )
    .map_err(not_printable)?;
    if let Some(letter) = super::servo::servo_letter(spec) {
        program.servo_on(letter);
    }
    program.hold_spindle_under(spec.max_spindle_speed);
    program.call_tool(&head.start).map_err(not_printable)?;
    let mut sink = cx.sink(head)?;
    let mut table_sink = match table_name {
        Some(_) => Some(Sink::new(to, site)?),
        None => None,
    };
    // The fast axis's servo, run on the commands as printed as they are
    // planned (a slow tool servo's Z has no servo model here).
    let data_rate = 1.0 / p.spiral.min_interval;
    let mut following = following(spec, &p.spiral, &p.bounds, data_rate);
    // The height map over the window (by default the whole of what the
    // spiral cuts), from the same printed points.
    let window = height_map::window(
        head,
        crate::strategy::Strategy::part_extent(spec),
        height_map::WHOLE_CELLS_NOSE,
        |w| w.polar_tiles(&p.lenslets),
    );
    // The nose as measured, where the tool names its edge.
    let mut sweep = Simulation::of(
        window.polar(),
        window.polar_tiles(&p.lenslets),
        Cutter::Nose {
            radius: p.nose_radius,
            edge: p
                .edge
                .as_ref()
                .map(|(m, _)| std::sync::Arc::new(m.profile.clone())),
        },
    );
    let mut printed = Vec::new();
    // The points within a nose radius of the axis, swept again on the
    // opposite ray (`across_axis`).
    let mut near_axis = Vec::new();
    let rho = p.nose_radius;
    let prepared = Prepared::of(spec);
    // The disc the spiral cuts: out to its start where that lies at or
    // beyond the aperture's farthest point (the whole part, its rim
    // included, is this job's); a partial spiral's (a `from` inside it) out
    // to its first revolution's nearest contact, beyond which its nose's
    // flank passes over what the operation outside it leaves.
    let disc = if spec.spiral.start_radius < super::outer_radius(&spec.head.surface.lowered.domain)
    {
        prepared.planner().first_contacts_least()
    } else {
        spec.spiral.start_radius
    };
    // What the program prints: the path, or the path led by the servo's
    // inverse model where the controller does not lead it.
    let mut commands = Commands::of(spec, data_rate);
    let mut write = |commands: &mut Commands, planned: usize| {
        // The nose cuts the path; the servo is driven by the commands.
        as_printed(&commands.path, head.resolution, &mut printed);
        for q in &printed {
            sweep.path().point(q.c, q.x, q.w);
        }
        near_axis.extend(printed.iter().filter(|q| q.x.abs() < rho));
        if let Some(sim) = following.as_mut() {
            commands.drive(sim, head.resolution);
        }
        sink.extend(|| program.extend(&commands.commands));
        sink.push(program.take_text());
        sink.planned(planned);
        if let Some(t) = table_sink.as_mut() {
            t.push(program.take_table_text());
        }
    };
    let planned = prepared.planner().plan(&p.fast_axis, |pts| {
        commands.next(pts);
        write(&mut commands, pts.len());
    });
    if planned.is_ok() {
        // The path's last point, led once the path is known to end.
        commands.finish();
        write(&mut commands, 0);
    }
    let mut summary = planned.map_err(|error| {
        let advice = match error {
            FtsError::AccelerationExceeded { acceleration, .. } => {
                Some(super::advice::search(spec, acceleration))
            }
            _ => None,
        };
        vec![super::errors::error(
            error,
            &p.spiral.speed,
            axis_words(spec),
            advice,
            site,
        )]
    })?;
    // A measured edge lies mirrored on the opposite ray (its +X offsets
    // point toward the axis there), which the sweep does not model: such
    // a nose is swept on its own ray only, which the revolution past the
    // axis covers from both sides (the simulation errs toward material
    // left, never toward a cut it did not make).
    if spec.edge.is_none() {
        across_axis(sweep.path(), &near_axis);
    }
    // The points the program cuts: the planned path's, and the lead's
    // added beside its bends.
    summary.points = commands.written;
    // Every move written as a move within the machine's feed (the lead's
    // short moves beside a bend are the fastest).
    if let Some(fastest) = commands.over_max_feed(spec) {
        let advice = super::advice::search_feed(spec, fastest.0);
        return Err(vec![
            super::errors::feed_refused(spec, fastest, advice).at(site),
        ]);
    }
    // The servo on its own letter within its own velocity limit.
    if let Some(fastest) = commands.over_servo_velocity(spec) {
        let advice = super::advice::search_servo(spec, fastest.0);
        return Err(vec![
            super::errors::servo_velocity_refused(spec, fastest, advice).at(site),
        ]);
    }
    let mut sink = sink.written(head)?;
    if let Some(t) = table_sink.as_mut() {
        t.push(program.take_table_text());
    }
    sink.push(program.finish().map_err(not_printable)?);
    let mut beside = Vec::new();
    if let (Some(name), Some(t)) = (table_name, table_sink) {
        beside.push((name, t.finish(site)?));
    }
    let text = sink.finish(site)?;
    let mut plots = crate::plots::PlotSeries::default();
    let height_map = simulated_height_map(spec, sweep, window, disc, &mut plots);
    let followed = following.map(|sim| sim.finish());
    if program_leads(spec) {
        let led = super::errors::lead_refused(spec, commands.range, followed.as_ref());
        if let Some(e) = led {
            return Err(vec![e.at(site)]);
        }
    }
    let simulation = simulation(followed, height_map, data_rate, p.slow, &mut plots);
    let toolpath = toolpath(spec, &summary);
    let cut = (summary.points, summary.time);
    let mut built = parts::built(head, prov, text, toolpath, simulation, plots, cut);
    if let Some((name, table)) = beside.first() {
        built.report.program.fts_table = Some(report::FtsTable {
            file: name.clone(),
            rows: table.lines().saturating_sub(2),
        });
    }
    built.beside = beside;
    built.warnings = chords_warning(spec, &summary, data_rate)
        .into_iter()
        .collect();
    Ok(built)
}

/// The nose swept again over the opposite ray, for the points `near`
/// (within a nose radius of the spindle axis, in order): its edge is a
/// circle in the plane through the axis, so the nose at spindle angle c,
/// centre at radius x, lies on the ray at c + π at radius −x as well, and
/// within ρ of the axis it cuts that ray too. Without, a polar map's cell
/// on the axis saw only the revolution on its own ray, up to a feed away
/// (a dome's axis, cut by the spiral's last point, showed 95 nm: f²/2ρ at
/// 10 µm/rev under a 0.5 mm nose).
fn across_axis(path: &mut dyn NosePath, near: &[SpiralPoint]) {
    path.lift();
    for q in near {
        path.point(q.c + std::f64::consts::PI, -q.x, q.w);
    }
    path.lift();
}

/// The table a fast tool servo's controller reads its motion from
/// (`JOB.EXT`), if its dialect takes one: the program then moves X and C a
/// revolution a block.
fn table_name(spec: &SpiralSpec) -> Option<String> {
    match &spec.head.dialect.fts_table {
        Some(ext) if !spec.slow => Some(format!("{}.{ext}", spec.head.name)),
        _ => None,
    }
}

/// The axis that carries the surface, in words.
fn axis_words(spec: &SpiralSpec) -> &'static str {
    if spec.slow { "Z" } else { "the fast axis" }
}

/// The spiral's section of the report: a fast or a slow tool servo's.
fn toolpath(spec: &SpiralSpec, summary: &FtsSummary) -> report::Toolpath {
    let mut spiral = report::Spiral::new(
        summary,
        &spec.spiral,
        spec.settling.as_ref(),
        spec.servo.as_ref(),
        spec.nose_radius,
    );
    spiral.edge_profile = spec.edge.as_ref().map(|(_, r)| r.clone());
    if spec.slow {
        report::Toolpath::SpiralTurning(spiral)
    } else {
        report::Toolpath::FtsSpiral(spiral)
    }
}

/// The height map the swept nose leaves over the window, for the report,
/// and its form error for the plots.
fn simulated_height_map(
    spec: &SpiralSpec,
    sweep: Simulation,
    window: Window,
    disc: f64,
    plots: &mut crate::plots::PlotSeries,
) -> report::HeightMap {
    let lowered = &spec.head.surface.lowered;
    // The height alone: the frame asks nothing else of the design.
    let design = height_map::DesignHeights::of(&spec.head.surface);
    let frame = LatheFrame::new(
        &design,
        window,
        lowered.domain,
        // The default window is the disc the spiral cuts (`disc`); one
        // the job gives counts every cell of it, cut or not.
        if window.given { f64::INFINITY } else { disc },
        &spec.lenslets,
        spec.head.surface.lenslets.as_ref(),
    );
    // A polar grid's cells lie askew to the raster's blocks: √2 times the
    // spacing puts a cell in every block (1.5 for margin).
    let (map, raster) = sweep.finish(&frame, &window, 1.5 * window.spacing);
    plots.form_error = Some(height_map::form_error_series(
        raster,
        &window,
        ("x (mm)", "y (mm)"),
    ));
    report::HeightMap::new(
        &map,
        &window,
        "columns at spindle angles (column step in rad), rows at radii",
        spec.spiral.feed_per_rev,
    )
}

/// W: chords the data period kept from their share of the tolerance.
fn chords_warning(spec: &SpiralSpec, summary: &FtsSummary, data_rate: f64) -> Option<Diagnostic> {
    let share =
        spec.spiral.chord_tolerance * lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE;
    let (file, span) = spec.head.site;
    summary.chords_over_tolerance.map(|o| {
        Diagnostic::warning(
            codes::CHORDS_OVER_TOLERANCE,
            format!(
                "{} chords of the spiral stray up to {} nm from the exact path (their share of the tolerance is {} nm), the worst at r = {} mm: {} may not be commanded faster than its data rate ({} Hz) allows",
                o.count,
                trim_num(o.deviation * 1e6),
                trim_num(share * 1e6),
                trim_num(o.at_radius),
                axis_words(spec),
                trim_num(data_rate)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("lower the spindle or surface speed, or give the axis a higher `data_rate`; the report's `chords_over_tolerance` says how many and where")
    })
}

/// A spiral's simulation for its report: the fast axis's following where
/// it has a servo model (at `data_rate`, Hz; its series go into `plots`),
/// and the height map either way.
fn simulation(
    following: Option<lensc_runtime::verify::follow::Following>,
    height_map: report::HeightMap,
    data_rate: f64,
    slow: bool,
    plots: &mut crate::plots::PlotSeries,
) -> report::Simulation {
    let Some(f) = following else {
        return report::Simulation::Skipped(report::Skipped {
            skipped: if slow {
                "slow tool servo: Z is a machine axis, with no servo model here"
            } else {
                "the fast axis has no servo model"
            },
            height_map: Some(height_map),
        });
    };
    let following = report::Following::new(&f, data_rate, height_map);
    plots.following = Some(crate::plots::FollowingSeries {
        by_radius: f.by_radius,
        samples: f.samples,
        data_rate_hz: data_rate,
        max_error: (f.max_error, f.max_error_at),
    });
    report::Simulation::Following(following)
}

/// The program's header: provenance, units, the surface, tool, spiral
/// and machine in words, and the settling offset.
fn header_lines(spec: &SpiralSpec, prov: &Provenance, table: Option<&str>) -> Vec<String> {
    let (head, spiral, slow) = (&spec.head, &spec.spiral, spec.slow);
    let settling = spec.settling.as_ref();
    let table_words;
    let (servo_words, axis_words) = if slow {
        ("slow-tool-servo", "Z carries the surface")
    } else if let Some(table) = table {
        table_words = format!(
            "Z held at 0 while the fast tool servo follows the table {table} [rows C X W, one per point]"
        );
        ("fast-tool-servo", table_words.as_str())
    } else if let Some(letter) = super::servo::servo_letter(spec) {
        table_words = format!(
            "Z the slide, held at 0 while the fast tool servo moves on its own axis {letter} [the tool tip at Z + {letter}]"
        );
        ("fast-tool-servo", table_words.as_str())
    } else {
        ("fast-tool-servo", "Z the fast tool servo's axis")
    };
    let speed = match spiral.speed {
        SpindleSpeed::Constant(w) => format!("constant spindle speed {} rpm", exact_in(w, "rpm")),
        SpindleSpeed::SurfaceSpeed { speed, max } => format!(
            "constant surface speed {} m/min capped at {} rpm",
            exact_in(speed, "m/min"),
            exact_in(max, "rpm")
        ),
    };
    let units = format!(
        "units mm; X is {}, C the spindle angle in degrees counted on from the start, {axis_words}, +Z out of the material",
        lensc_runtime::emit::x_word(&head.dialect)
    );
    let mut lines = parts::nose_centre_header(head, prov, &units, spec.nose_radius);
    if let Some((m, _)) = &spec.edge
        && let Some(tool) = lines.last_mut()
    {
        tool.push_str(&format!(
            ", edge profile {}: each centre clears the surface with the measured edge at its angle of contact",
            m.source
        ));
    }
    lines.push(format!(
        "strategy {}: {servo_words} spiral from r = {} mm, feed {} um/rev, {speed}, path tolerance {} nm [chords {}, blending {} nm]",
        head.names.strategy,
        derived_in(spiral.start_radius, "mm", 7),
        exact_in(spiral.feed_per_rev, "um"),
        exact_in(spiral.chord_tolerance, "nm"),
        trim_num(
            spiral.chord_tolerance * lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE * 1e6
        ),
        trim_num(spiral.chord_tolerance * lensc_runtime::plan::optimise::BLEND_SHARE * 1e6)
    ));
    let lead = if super::servo::program_leads(spec) {
        match super::servo::servo_letter(spec) {
            Some('W') | None => ", feed_forward none: the servo led by this program [its W written as the servo's inverse model of the path]".to_string(),
            Some(l) => format!(", feed_forward none: the servo led by this program [its {l} written as the servo's inverse model of the path]"),
        }
    } else if spec.controller_leads && !slow {
        ", feed_forward inverse_model: the servo led by its controller [its W the path]".to_string()
    } else {
        String::new()
    };
    lines.push(format!(
        "machine {}: {} {servo_words} lathe{lead}",
        head.names.machine, head.dialect.name
    ));
    match settling {
        None if slow => {}
        Some(s) => lines.push(format!(
            "settling: tool held {} um above the land, lenslets continued {} um past their rims [settling time {} ms at {} m/min]",
            derived_in(s.offset, "um", 4),
            derived_in(s.d_traj, "um", 4),
            exact_in(s.time, "ms"),
            exact_in(s.surface_speed, "m/min")
        )),
        None => lines.push("settling: none, the tool follows the surface".into()),
    }
    lines.push(format!(
        "estimated cutting time {}",
        lensc_runtime::post::header::duration(spiral.cutting_time())
    ));
    lines
}
