//! The compiler's entry points: check a file, build a file's jobs into
//! programs. Pure apart from the `FileSystem` it reads through and the
//! atomic writes of `build`.

use std::path::Path;

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::turning::{ToolLocation, Toolpath};
use lensc_runtime::post::Provenance;

use lensc_lang::check::{self, trim_num};
use lensc_lang::codes;
use lensc_lang::loader::Loaded;
use lensc_lang::lower;

use crate::diagnostics::RuntimeError;
use crate::report;

pub use lensc_lang::{Checked, check_path, check_text};

/// One job's output, not yet written.
pub struct Built {
    /// File name of the program (`JOB.ngc`); the report is `JOB.report.json`.
    pub program_name: String,
    pub report_name: String,
    pub program: ProgramText,
    /// Points of the cut and its estimated time (s), for the summary line.
    pub cut_points: usize,
    pub cutting_time: f64,
    /// The build report (its fields are documented in
    /// docs/report.schema.json, generated from `crate::report`).
    pub report: crate::report::Report,
    /// Files the program reads, written beside it (a fast-tool-servo
    /// table): name and text.
    pub beside: Vec<(String, ProgramText)>,
    /// The series behind the plots of `lensc report`.
    pub plots: crate::plots::PlotSeries,
    /// Warnings the build found (the job still built).
    pub warnings: Vec<Diagnostic>,
}

/// A program's text: in memory, or spooled as it was written to a
/// temporary file in the output directory (the programs of fast-tool-servo
/// jobs run to millions of lines).
pub enum ProgramText {
    Memory(String),
    Spooled {
        file: tempfile::NamedTempFile,
        lines: usize,
        bytes: u64,
    },
}

impl ProgramText {
    pub fn lines(&self) -> usize {
        match self {
            ProgramText::Memory(t) => t.lines().count(),
            ProgramText::Spooled { lines, .. } => *lines,
        }
    }
    pub fn bytes(&self) -> u64 {
        match self {
            ProgramText::Memory(t) => t.len() as u64,
            ProgramText::Spooled { bytes, .. } => *bytes,
        }
    }
    /// The whole text (read back from the spool file if need be).
    pub fn text(&self) -> std::io::Result<String> {
        match self {
            ProgramText::Memory(t) => Ok(t.clone()),
            ProgramText::Spooled { file, .. } => std::fs::read_to_string(file.path()),
        }
    }
    /// Puts the program at `path` atomically (a spooled program is renamed
    /// into place: it was written in the same directory).
    pub fn write_to(self, path: &Path) -> std::io::Result<()> {
        match self {
            ProgramText::Memory(t) => write_atomic(path, &t),
            ProgramText::Spooled { file, .. } => {
                readable_by_all(file.as_file())?;
                file.as_file().sync_all()?;
                file.persist(path).map(|_| ()).map_err(|e| e.error)
            }
        }
    }
}

/// What `lensc build` was asked for beyond the file.
#[derive(Clone, Copy, Debug, Default)]
pub struct Request<'a> {
    /// Only this job.
    pub job: Option<&'a str>,
    /// This dialect instead of each machine's own (it must offer it).
    pub dialect: Option<&'a str>,
}

/// Builds programs and reports (without writing them) for the checked
/// jobs. Returns them and any further diagnostics. Large programs are
/// spooled into `spool_dir` (the output directory) when one is given.
pub fn plan_and_emit(
    c: &Checked,
    request: Request,
    source_name: &str,
    spool_dir: Option<&Path>,
) -> (Vec<Built>, Vec<Diagnostic>) {
    let only = request.job;
    let mut diags = Vec::new();
    let mut out = Vec::new();
    let jobs: Vec<&check::CheckedJob> = c
        .checked
        .jobs
        .iter()
        .filter(|j| only.is_none_or(|n| j.name.name == n))
        .collect();
    let prov = Provenance {
        source: source_name.to_string(),
        source_hash: source_hash(&c.loaded),
        lensc_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    for job in jobs {
        let strategy =
            lensc_lang::value::object(&job.fields, "strategy").expect("checked job part");
        let dialect = match lower::dialect(job, request.dialect) {
            Ok(d) => d,
            Err(d) => {
                diags.push(d);
                continue;
            }
        };
        // Profile jobs are simulated along their whole profile: a window
        // means nothing to them.
        if let ("profile_turning" | "profile_grinding", Some(f)) = (
            strategy.kind.name,
            lensc_lang::value::field(&job.fields, "simulate"),
        ) {
            diags.push(
                Diagnostic::error(
                    codes::UNSUPPORTED_COMBINATION,
                    format!(
                        "`simulate` sets the window of a surface's height map; this `{}` job is simulated along its whole profile",
                        strategy.kind.name
                    ),
                    f.file,
                    f.span,
                )
                .with_label("not for a profile job")
                .with_help("remove the `simulate` block"),
            );
            continue;
        }
        let other = match strategy.kind.name {
            "fts_spiral" | "spiral_turning" => {
                Some(crate::fts_job::build(job, &prov, &dialect, spool_dir))
            }
            "raster" => Some(crate::mill_job::build_raster(job, &prov, &dialect)),
            "roller_helix" => Some(crate::roller_job::build(job, &prov, &dialect, spool_dir)),
            "profile_grinding" => Some(crate::mill_job::build_grinding(job, &prov, &dialect)),
            _ => None,
        };
        match other {
            Some(Ok(mut b)) => {
                diags.append(&mut b.warnings);
                out.push(b);
                continue;
            }
            Some(Err(mut d)) => {
                diags.append(&mut d);
                continue;
            }
            None => {}
        }
        let lowered = match lower::lower(job, dialect) {
            Ok(j) => j,
            Err(mut d) => {
                diags.append(&mut d);
                continue;
            }
        };
        let (file, span) = lower::job_site(job);
        // The planner follows the surface as the JIT evaluates it.
        let surface = lensc_lang::value::object(&job.fields, "surface").expect("checked job part");
        let lowered_surface = match lensc_lang::lower::surface::lower_surface(surface) {
            Ok(l) => l,
            Err(e) => {
                diags.push(RuntimeError::Surface(e).at(file, span));
                continue;
            }
        };
        let (kernel, _) = evaluator(&lowered_surface.tape);
        let profile = lensc_runtime::surface::SectionAlongX(kernel.as_ref());
        let path = match lensc_runtime::plan::turning::plan_profile_turning(&lowered, &profile) {
            Ok(p) => p,
            Err(errs) => {
                diags.extend(
                    errs.into_iter()
                        .map(|e| RuntimeError::Turning(e).at(file, span)),
                );
                continue;
            }
        };
        let h = lowered.tool.centre_height.abs();
        let inmost = path
            .moves
            .iter()
            .filter_map(|m| match *m {
                lensc_runtime::plan::turning::Move::Feed { x, .. } => Some(x.abs()),
                lensc_runtime::plan::turning::Move::Rapid { .. } => None,
            })
            .fold(f64::INFINITY, f64::min);
        if h > 0.0 && inmost < h {
            diags.push(
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
            diags.push(
                Diagnostic::warning(
                    codes::SEAM_LEFT_UNCUT,
                    format!(
                        "the {} mm nose cannot reach into {where_}: up to {} um of material is left above the design (at r = {} mm)",
                        trim_num(lowered.tool.nose_radius),
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
        match lensc_runtime::emit::turning::emit(&lowered, &path, &prov) {
            Ok(lensc_runtime::emit::Emitted {
                text,
                stream,
                optimised,
            }) => {
                let program_name =
                    format!("{}.{}", lowered.name, lowered.machine.dialect.extension);
                let name = job.part_names.get("surface").cloned().unwrap_or_default();
                let analysis = surface_analysis(&name, surface.kind.name, &lowered_surface, 201);
                let mut plots = crate::plots::PlotSeries::default();
                let simulation = if lowered.tool.centre_height == 0.0 {
                    use lensc_runtime::surface::Profile as _;
                    let design = |x: f64| profile.point(x).z;
                    let range = (
                        lowered.strategy.end_radius,
                        lowered
                            .strategy
                            .start_radius
                            .unwrap_or(lowered.surface.aperture_radius),
                    );
                    let cut = lensc_runtime::verify::simulate::profile_cut(
                        &stream,
                        lowered.tool.nose_radius,
                        lowered.machine.resolution,
                        &design,
                        range,
                        PROFILE_SAMPLES,
                    );
                    plots.profile = Some(profile_series(
                        &cut,
                        &design,
                        &stream,
                        ("nose", lowered.tool.nose_radius),
                        lowered.machine.resolution,
                        path.seams.iter().map(|s| s.at_radius).collect(),
                    ));
                    report::Simulation::Profile((&cut).into())
                } else {
                    report::Simulation::Skipped(report::Skipped {
                        skipped: "the edge is set off the spindle axis: the program's X is not the nose centre's radius",
                        height_map: None,
                    })
                };
                let report = build_report(
                    &lowered,
                    &prov,
                    &program_name,
                    &text,
                    &path,
                    &optimised,
                    simulation,
                    analysis,
                );
                out.push(Built {
                    report_name: format!("{}.report.json", lowered.name),
                    program_name,
                    program: ProgramText::Memory(text),
                    cut_points: path.cut_points,
                    cutting_time: path.cutting_time(),
                    report,
                    beside: Vec::new(),
                    plots,
                    warnings: Vec::new(),
                });
            }
            Err(e) => diags.push(RuntimeError::Program(e).at(file, span)),
        }
    }
    (out, diags)
}

/// Radii sampled by a profile's cut simulation.
pub const PROFILE_SAMPLES: usize = 20_001;

/// A profile's simulated cut as the series of its plot: the design and
/// the error at every simulated radius, the tool centre's path as printed
/// (the cutting moves of `stream`), the seams' radii. `tool` names the
/// tool ("nose", "wheel") and gives its radius (mm).
pub fn profile_series(
    cut: &lensc_runtime::verify::simulate::ProfileCut,
    design: &dyn Fn(f64) -> f64,
    stream: &[lensc_runtime::moves::Move],
    tool: (&'static str, f64),
    resolution: f64,
    seams: Vec<f64>,
) -> crate::plots::ProfileSeries {
    crate::plots::ProfileSeries {
        tool: tool.0,
        tool_radius: tool.1,
        samples: cut
            .samples
            .iter()
            .map(|&(x, e)| (x, design(x), e))
            .collect(),
        centre_path: lensc_runtime::verify::simulate::centre_path(stream, resolution),
        seams,
        pv: cut.pv,
        rms: cut.rms,
    }
}

/// Makes a finished output file readable by all and writable by its owner.
fn readable_by_all(file: &std::fs::File) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        file.set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    #[cfg(not(unix))]
    let _ = file;
    Ok(())
}

/// The report written beside a profile-turning program.
#[allow(clippy::too_many_arguments)]
fn build_report(
    job: &lensc_runtime::plan::turning::TurningJob,
    prov: &Provenance,
    program_name: &str,
    text: &str,
    path: &Toolpath,
    optimised: &lensc_runtime::plan::optimise::Summary,
    simulation: report::Simulation,
    surface: report::SurfaceAnalysis,
) -> report::Report {
    let toolpath = report::ProfileTurning {
        cut_points: path.cut_points,
        cut_length_mm: path.cut_length,
        feed_mm_per_min: path.feed_speed * 60.0,
        surface_speed_m_per_min: job.strategy.surface_speed.map(|v| v * 0.06),
        max_spindle_rpm: job.strategy.spindle_speed * 60.0 / std::f64::consts::TAU,
        cutting_time_s: path.cutting_time(),
        passes: path
            .pass_times
            .iter()
            .enumerate()
            .map(|(i, &t)| report::TurningPass {
                pass: if i < path.roughing_passes {
                    report::PassKind::Roughing
                } else {
                    report::PassKind::Finish
                },
                cutting_time_s: t,
            })
            .collect(),
        chord_tolerance_mm: job.strategy.chord_tolerance,
        max_profile_slope_deg: path.max_slope.0.to_degrees(),
        min_concave_radius_mm: path.min_concave_radius.map(|(r, at)| report::AtRadius {
            value: r,
            at_radius_mm: at,
        }),
        roughing_passes: path.roughing_passes,
        tool_location: match job.strategy.location {
            ToolLocation::Exact => report::ToolLocation::Exact,
            ToolLocation::Sequential { .. } => report::ToolLocation::Sequential,
            ToolLocation::Binary { .. } => report::ToolLocation::Binary,
        },
        seams: path
            .seams
            .iter()
            .map(|s| report::Seam {
                at_radius_mm: s.at_radius,
                uncut_depth_mm: s.depth,
                corner_angle_deg: s.angle.to_degrees(),
            })
            .collect(),
        optimisation: optimised.into(),
    };
    report::Report {
        job: job.name.clone(),
        lensc_version: prov.lensc_version.clone(),
        source: prov.source.clone(),
        source_fnv1a64: format!("{:016x}", prov.source_hash),
        program: report::Program {
            file: program_name.to_string(),
            dialect: job.machine.dialect.name.clone(),
            lines: text.lines().count(),
            bytes: text.len() as u64,
            fts_table: None,
        },
        toolpath: report::Toolpath::ProfileTurning(toolpath),
        simulation,
        surface,
    }
}

/// FNV-1a 64 over every loaded source, in load order.
pub fn source_hash(l: &Loaded) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for (_, f) in l.sources.iter() {
        for b in f.text.bytes().chain(std::iter::once(0u8)) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// Writes `text` to `path` atomically: a temporary file in the same
/// directory, flushed, then renamed over the target. On failure the
/// target is untouched and no temporary file is left behind.
/// Temporary files are created private (0600); a program and its report
/// are put in place readable by all (0644), as any other written file, so
/// they can be copied to the controller's share.
pub fn write_atomic(path: &Path, text: &str) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let mut tmp = tempfile::Builder::new()
        .prefix(".lensc-")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    readable_by_all(tmp.as_file())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Where `lensc sample` evaluates a surface.
pub enum SamplePoints {
    /// n × n over the domain's bounding box, points inside the domain.
    Grid(usize),
    /// n points from the centre of the domain to its edge along +x.
    Radial(usize),
    /// Given points (mm).
    Points(Vec<(f64, f64)>),
}

/// One sample: x, y, z (mm), dz/dx, dz/dy, curvature along x and y (1/mm).
pub type Sample = [f64; 7];

/// The backend that evaluates surfaces: a JIT kernel, or the reference
/// interpreter should cranelift refuse the tape (they agree to 1e-13, see
/// tests/jit_conformance.rs and tests/surface_kinds.rs).
/// The second value names the backend used (reports carry it).
pub fn evaluator(
    tape: &lensc_runtime::surface::ir::SurfaceTape,
) -> (
    Box<dyn lensc_runtime::surface::ir::SurfaceFn + Sync>,
    report::Backend,
) {
    match lensc_runtime::surface::jit::JitSurface::compile(tape) {
        Ok(j) => (Box::new(j), report::Backend::Jit),
        Err(_) => (
            Box::new(lensc_runtime::surface::ir::Interpreter::new(tape)),
            report::Backend::Interpreter,
        ),
    }
}

/// The declared surface `name`, lowered to IR, or a message saying why not.
pub fn declared_surface(
    c: &Checked,
    name: &str,
) -> Result<lensc_lang::lower::surface::LoweredSurface, String> {
    let Some(obj) = c.checked.declarations.get(name) else {
        let mut names: Vec<&str> = c
            .checked
            .declarations
            .iter()
            .filter(|(_, o)| o.kind.category == lensc_lang::schema::Category::Surface)
            .map(|(n, _)| n.as_str())
            .collect();
        names.sort_unstable();
        return Err(format!(
            "no surface `{name}` (surfaces: {})",
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        ));
    };
    if obj.kind.category != lensc_lang::schema::Category::Surface {
        return Err(format!(
            "`{name}` is {}, not a surface",
            obj.kind.category.noun()
        ));
    }
    lensc_lang::lower::surface::lower_surface(obj).map_err(|e| {
        format!(
            "`{name}` cannot be evaluated yet: {}",
            crate::diagnostics::lowering_words(&e)
        )
    })
}

/// The analysis of a surface as the reports carry it (and `lensc
/// analyse` prints it), on a `grid` per side.
pub fn surface_analysis(
    name: &str,
    kind: &str,
    l: &lensc_lang::lower::surface::LoweredSurface,
    grid: usize,
) -> report::SurfaceAnalysis {
    let (f, backend) = evaluator(&l.tape);
    let a = lensc_runtime::surface::analysis::analyse(f.as_ref(), &l.domain, grid);
    report::SurfaceAnalysis::new(name, kind, &l.domain, grid, backend, &a)
}

/// Evaluates a declared surface at the requested points.
pub fn sample(c: &Checked, surface: &str, at: &SamplePoints) -> Result<Vec<Sample>, String> {
    let lowered = declared_surface(c, surface)?;
    let (f, _) = evaluator(&lowered.tape);
    let domain = lowered.domain;
    let ((x0, x1), (y0, y1)) = domain.bounds();
    let (xs, ys): (Vec<f64>, Vec<f64>) = match at {
        SamplePoints::Grid(n) => {
            let n = (*n).max(1);
            let step = |a: f64, b: f64, i: usize| {
                if n == 1 {
                    0.5 * (a + b)
                } else {
                    a + (b - a) * i as f64 / (n - 1) as f64
                }
            };
            (0..n)
                .flat_map(|j| (0..n).map(move |i| (step(x0, x1, i), step(y0, y1, j))))
                .filter(|&(x, y)| domain.contains(x, y))
                .unzip()
        }
        SamplePoints::Radial(n) => {
            let n = (*n).max(1);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            (0..n)
                .map(|i| {
                    (
                        if n == 1 {
                            cx
                        } else {
                            cx + (x1 - cx) * i as f64 / (n - 1) as f64
                        },
                        cy,
                    )
                })
                .unzip()
        }
        SamplePoints::Points(p) => p.iter().copied().unzip(),
    };
    let mut out = vec![0.0; 6 * xs.len()];
    f.eval_batch(&xs, &ys, &mut out);
    Ok((0..xs.len())
        .map(|i| {
            let o = &out[6 * i..6 * i + 6];
            [
                xs[i],
                ys[i],
                o[0],
                o[1],
                o[2],
                lensc_runtime::surface::analysis::curvature_x(o),
                lensc_runtime::surface::analysis::curvature_y(o),
            ]
        })
        .collect())
}
