//! The compiler's entry points: check a file, build a file's jobs into
//! programs (`plan_and_emit`, from `pipeline`), analyse and sample a
//! surface; what a built job is (`Built`, `ProgramText`) and the pieces of
//! report every builder shares. Pure apart from the `FileSystem` it reads
//! through and the atomic writes of `build`.

use std::path::Path;

use lensc_grammar::Diagnostic;

use lensc_lang::loader::Loaded;

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
    /// The build report (fields documented in README.md, "Build report").
    pub report: serde_json::Value,
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

pub use crate::pipeline::{Request, plan_and_emit};

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

/// A profile's simulated cut, for its report: the form error (design to
/// cut, positive where material is left) over the radii the cut reaches.
pub fn profile_cut_json(cut: &lensc_runtime::verify::simulate::ProfileCut) -> serde_json::Value {
    serde_json::json!({
        "kind": "profile envelope of the nose along the program's moves, as printed",
        "samples": cut.samples.len(),
        "from_radius_mm": cut.samples.first().map(|s| s.0),
        "to_radius_mm": cut.samples.last().map(|s| s.0),
        "form_error_pv_nm": cut.pv * 1e6,
        "form_error_rms_nm": cut.rms * 1e6,
        "max_residual_nm": { "value": cut.max_residual.0 * 1e6, "at_radius_mm": cut.max_residual.1 },
        "max_gouge_nm": { "value": cut.max_gouge.0 * 1e6, "at_radius_mm": cut.max_gouge.1 },
    })
}

/// What optimisation did to a program, for its report: motion blocks
/// before and after, arcs written, straight moves that absorbed collinear
/// points, and the largest deviation from the planned polyline against the
/// tolerance it was held to.
pub fn optimisation_json(s: &lensc_runtime::plan::optimise::Summary) -> serde_json::Value {
    serde_json::json!({
        "blocks_before": s.moves_before,
        "blocks_after": s.moves_after,
        "arcs": s.arcs,
        "merged_lines": s.merged_lines,
        "max_deviation_mm": s.max_deviation,
        "tolerance_mm": s.tolerance,
    })
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
    &'static str,
) {
    match lensc_runtime::surface::jit::JitSurface::compile(tape) {
        Ok(j) => (Box::new(j), "jit"),
        Err(_) => (
            Box::new(lensc_runtime::surface::ir::Interpreter::new(tape)),
            "interpreter",
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
    lensc_lang::lower::surface::lower_surface(obj)
        .map_err(|e| format!("`{name}` cannot be evaluated yet: {e:?}"))
}

/// The analysis of a surface as the JSON object the reports carry (its
/// fields are documented in README.md, "Surface analysis").
pub fn analysis_json(
    name: &str,
    kind: &str,
    l: &lensc_lang::lower::surface::LoweredSurface,
    grid: usize,
) -> serde_json::Value {
    use lensc_runtime::surface::analysis::{Domain, Extremum, analyse};
    use serde_json::json;
    let (f, backend) = evaluator(&l.tape);
    let a = analyse(f.as_ref(), &l.domain, grid);
    let at =
        |e: &Extremum, scale: f64| json!({ "value": e.value * scale, "x_mm": e.x, "y_mm": e.y });
    let deg = 180.0 / std::f64::consts::PI;
    let radius = |e: &Option<Extremum>| e.as_ref().map_or(serde_json::Value::Null, |e| at(e, 1.0));
    let domain = match l.domain {
        Domain::Circle { radius } => json!({ "circle": { "radius_mm": radius } }),
        Domain::Annulus { inner, outer } => {
            json!({ "annulus": { "inner_mm": inner, "outer_mm": outer } })
        }
        Domain::Rect { x, y } => json!({ "rect": { "x_mm": [x.0, x.1], "y_mm": [y.0, y.1] } }),
    };
    json!({
        "surface": name,
        "kind": kind,
        "domain": domain,
        "grid": grid,
        "backend": backend,
        "sag_mm": { "min": at(&a.sag_min, 1.0), "max": at(&a.sag_max, 1.0), "pv": a.pv() },
        "max_slope_deg": at(&a.max_slope, deg),
        "max_slope_x_deg": at(&a.max_slope_x, deg),
        "max_slope_y_deg": at(&a.max_slope_y, deg),
        "min_radius_of_curvature_mm": {
            "concave_x": radius(&a.min_radius_concave_x),
            "convex_x": radius(&a.min_radius_convex_x),
            "concave_y": radius(&a.min_radius_concave_y),
            "convex_y": radius(&a.min_radius_convex_y),
        },
    })
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
