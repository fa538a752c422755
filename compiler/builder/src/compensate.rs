//! A job's `compensate` block: the surface the next cut aims at, made
//! from a measurement of the part the last cut made. The measurement file
//! is read as a `use`d file is (beside the job's file, beneath the project
//! root, a regular file, bounded in size), registered to the design as
//! `lensc measure` registers it, and its error along z fitted by smooth
//! polynomials over the whole aperture (`lensc_measure::correct`, which
//! states the method); the surface cut is the design less `gain` times
//! that fit, one IR tape, so every strategy plans it with exact
//! derivatives as it plans the design (a spiral's planner and every
//! height-map simulation take the same polynomial out themselves, along
//! rays and columns where it has a few terms: `AlongRays`,
//! `height_map::DesignHeights`). Every refusal is a coded diagnostic at
//! the block's `measurement`, naming the file.

use lensc_grammar::Diagnostic;
use lensc_lang::codes;
use lensc_lang::lower::surface::LoweredSurface;
use lensc_lang::schema::CompensateParams;
use lensc_lang::value::Stated;
use lensc_measure::correct::{self, Basis, Correction};
use lensc_measure::read::TextUnits;
use lensc_runtime::surface::analysis::{self, Domain};
use lensc_runtime::surface::ir::{SurfaceTape, Var};

use crate::measure::placed::{self as measure, Failure, MAX_MEASUREMENT_BYTES};
use lensc_lang::check::CheckedJob;
use lensc_runtime::surface::ir::SurfaceFn;
use schemars::JsonSchema;
use serde::Serialize;

/// One iteration of the measure-and-correct loop: the measurement the
/// correction was made from, how it was placed on the design, and the
/// correction cut (the design less `gain` times the fitted error).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Compensation {
    /// The measurement file, as the job names it.
    pub measurement: String,
    /// The file's format (`x3p`, `sdf`, …).
    pub format: String,
    /// MD5 of the file's bytes, lowercase hex: which measurement this is.
    pub md5: String,
    /// Valid measured points inside the aperture, and their share of the
    /// measured aperture.
    pub points: usize,
    pub valid_share: f64,
    /// The placement of the measurement on the design.
    pub registration: crate::measure::report::Registration,
    /// The measured part's form error along z after registration (nm).
    pub measured_pv_nm: f64,
    pub measured_rms_nm: f64,
    /// The share of the fitted error taken out.
    pub gain: f64,
    /// The smoothing length (mm): no ripple shorter is followed.
    pub smoothing_mm: f64,
    /// How the error was smoothed and carried over the aperture, in words.
    pub method: String,
    /// The polynomials fitted, with their frame.
    pub basis: String,
    pub order: usize,
    /// Terms fitted (piston and tilts among them, left out of the
    /// correction), and the cells (rings or squares) fitted to.
    pub terms: usize,
    pub cells: usize,
    /// RMS of the cells' mean errors about the fit (nm): what the
    /// correction does not follow.
    pub fit_residual_rms_nm: f64,
    /// The correction's peak to valley over the aperture (nm): how far the
    /// surface cut departs from the design.
    pub correction_pv_nm: f64,
    /// The form error the next part is predicted to have, should the
    /// machine repeat the measured error: the measured error less `gain`
    /// times the correction, at the measured points, PV and RMS about its
    /// mean (nm).
    pub predicted_pv_nm: f64,
    pub predicted_rms_nm: f64,
}

/// What a correction needs of its job: the job itself (where its file is,
/// its root), its surface's name, its strategy's kind and its tool's
/// radius (nose or ball), if it has one.
pub(crate) struct Of<'a> {
    pub job: &'a CheckedJob,
    pub surface_name: String,
    pub strategy_kind: &'static str,
    pub tool_radius: Option<f64>,
}

/// The kernel a correction is made with: the JIT, or the interpreter
/// should cranelift refuse the tape (as the build evaluates surfaces).
fn kernel(tape: &SurfaceTape) -> Box<dyn SurfaceFn + Sync> {
    crate::evaluate::evaluator(tape).0
}

/// The strategies whose cut is a surface of revolution (a lathe without a
/// servo, a profile grinder): their correction is radial, the mean of
/// each ring being all such a cut can follow. Every other strategy (a
/// spiral whose Z or servo follows the surface, a mill's raster) is given
/// the map's correction.
const TURNED: [&str; 2] = ["profile_turning", "profile_grinding"];

/// The correction a job cuts with: the fitted polynomial and the share
/// of it taken out. Whatever else a strategy plans from the design (a
/// spiral's settled trajectory) takes it out too (`Applied::tape`).
#[derive(Clone, Debug)]
pub struct Applied {
    pub fitted: Correction,
    pub gain: f64,
    /// Tells corrections apart (a simulation keeps, per thread, the
    /// correction along the column it last asked: `height_map`).
    pub(crate) id: u64,
}

/// The next `Applied::id`.
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl Applied {
    /// `tape` less the correction (`corrected_tape`).
    pub fn tape(&self, tape: &SurfaceTape) -> SurfaceTape {
        corrected_tape(tape, &self.fitted, self.gain)
    }

    /// The correction as a spiral's planner takes it out along each ray
    /// from the spindle axis (`Correction::rays`), or `None` where its
    /// sections there would lose digits.
    pub fn along_rays(&self) -> Option<AlongRays> {
        Some(AlongRays {
            rays: self.fitted.rays()?,
            gain: self.gain,
        })
    }
}

/// A correction taken out along a lathe's rays: its sections, times the
/// gain.
pub struct AlongRays {
    rays: lensc_measure::correct::Rays,
    gain: f64,
}

impl lensc_runtime::plan::spiral::RayCorrection for AlongRays {
    fn section(&self, cos: f64, sin: f64) -> lensc_runtime::plan::spiral::RaySection {
        let mut a = [0.0; lensc_runtime::plan::spiral::RAY_TERMS];
        let terms = self.rays.section(cos, sin, self.gain, &mut a);
        lensc_runtime::plan::spiral::RaySection { a, terms }
    }
}

/// The surface to cut instead of `design`, the iteration for the report
/// and the correction applied; or why no correction is made.
pub(crate) fn corrected(
    p: &Of,
    design: &LoweredSurface,
    block: &Stated<CompensateParams>,
) -> Result<(LoweredSurface, Compensation, Applied), Diagnostic> {
    let c = &block.value;
    let file = c.measurement.value.as_str();
    let at = |f: Failure| {
        let mut d = Diagnostic::error(
            f.code,
            f.message,
            c.measurement.site.0,
            c.measurement.site.1,
        )
        .with_label("the measurement this job is compensated from");
        if let Some(h) = f.help {
            d = d.with_help(h);
        }
        d
    };
    let bytes = read(p, &c.measurement)?;
    // The file's MD5 (which measurement this is) beside its reading.
    let (md5, m) = rayon::join(
        || lensc_measure::md5_hex(&bytes),
        || lensc_measure::read::read(file, &bytes, TextUnits(c.units)),
    );
    let m = m.map_err(|e| at(measure::read_failure(file, &e)))?;
    let format = m.format;
    let (data, stride) = thinned(m.data);
    let surface_name = p.surface_name.clone();
    // A map or a profile is registered by least squares on heights and
    // slopes alone (`register::register_heights`); a cloud's closest
    // points take the second derivatives too.
    let f = if matches!(data, lensc_measure::Measured::Cloud(_)) {
        kernel(&design.tape)
    } else {
        kernel(&design.tape.slopes_only())
    };
    let opts = measure::Options {
        units: TextUnits(c.units),
        from_job: true,
        ..measure::Options::default()
    };
    let placed = measure::register_measurement(
        f.as_ref(),
        &design.domain,
        &surface_name,
        file,
        data,
        format,
        &opts,
        None,
    )
    .map_err(at)?;
    // Each measured point in the design's frame, with its error along z.
    let (us, vs) = lensc_measure::register::moved(placed.inside(), &placed.registration.values);
    let xy: Vec<(f64, f64)> = us.into_iter().zip(vs).collect();
    let radial = placed.is_profile() || TURNED.contains(&p.strategy_kind);
    let (basis, cell) = basis(&design.domain, radial, c.smoothing);
    let cells = correct::bin(&basis, &xy, &placed.vertical, cell);
    let fitted = correct::fit(basis, &cells)
        .filter(|k| k.coefficients.iter().all(|v| v.is_finite()))
        .ok_or_else(|| {
            at(Failure {
                code: codes::COMPENSATE_UNFITTED,
                message: format!(
                    "{file}: the measured points fill {} {} of the aperture of `{surface_name}`: too few to fit the {} terms a smoothing length of {} mm asks",
                    cells.len(),
                    if radial { "rings" } else { "cells" },
                    basis.terms().len(),
                    lensc_lang::check::trim_num(c.smoothing)
                ),
                at: None,
                help: Some(
                    "give a longer `smoothing` (a lower order), or measure more of the part"
                        .into(),
                ),
            })
        })?;
    // A polynomial carried beyond its points can swing: one that swings
    // far beyond the error it was fitted to follows no measurement. How
    // far it swings, the surface it makes and whether the tool can follow
    // it, beside the next part's prediction (should the machine repeat
    // the measured error); each refusal as it would be made in turn.
    let (measured_pv, measured_rms) = pv_rms(&placed.vertical);
    let (gain, tool_radius) = (c.gain, p.tool_radius);
    let ((swing, corrected, followed), predicted) = rayon::join(
        || {
            let swing = correction_pv(&fitted, &design.domain);
            let corrected = LoweredSurface {
                tape: corrected_tape(&design.tape, &fitted, gain),
                domain: design.domain,
            };
            let followed = curvature_check(tool_radius, design, &corrected, file, &surface_name);
            (swing, corrected, followed)
        },
        || -> Vec<f64> {
            xy.iter()
                .zip(&placed.vertical)
                .map(|(&(x, y), e)| e - gain * fitted.at(x, y))
                .collect()
        },
    );
    if swing > 2.0 * measured_pv + 1e-6 {
        return Err(at(Failure {
            code: codes::COMPENSATE_UNFITTED,
            message: format!(
                "{file}: the correction fitted to the measured error ({:.1} nm PV) swings {:.1} nm over the aperture of `{surface_name}`: it follows no measurement where it is carried beyond the measured points",
                measured_pv * 1e6,
                swing * 1e6
            ),
            at: None,
            help: Some(
                "give a longer `smoothing` (a lower order), or measure the whole aperture".into(),
            ),
        }));
    }
    followed.map_err(at)?;
    let (predicted_pv, predicted_rms) = pv_rms(&predicted);
    let report = Compensation {
        measurement: file.to_owned(),
        format: format.name().to_owned(),
        md5,
        points: placed.inside().len(),
        valid_share: placed.share,
        registration: placed.registration_report(),
        measured_pv_nm: measured_pv * 1e6,
        measured_rms_nm: measured_rms * 1e6,
        gain: c.gain,
        smoothing_mm: c.smoothing,
        method: format!(
            "the registered error along z averaged in {} {} mm wide{}, fitted by least squares weighted by each cell's points; piston{} left out; the polynomial carries the correction over the whole aperture, holes and rim included; the surface cut is the design less the gain times it",
            if radial { "rings" } else { "squares" },
            lensc_lang::check::trim_num(cell),
            if radial {
                " about the axis (a turned cut follows each ring's mean)"
            } else {
                ""
            },
            if radial { "" } else { " and tilts" }
        ) + &if stride > 1 {
            format!(
                "; a map of more than {MAX_POINTS} points taken at every {stride}th pixel along each axis"
            )
        } else {
            String::new()
        },
        basis: basis.words(),
        order: basis.order(),
        terms: basis.terms().len(),
        cells: fitted.cells,
        fit_residual_rms_nm: fitted.fit_residual_rms * 1e6,
        correction_pv_nm: c.gain * swing * 1e6,
        predicted_pv_nm: predicted_pv * 1e6,
        predicted_rms_nm: predicted_rms * 1e6,
    };
    let applied = Applied {
        fitted,
        gain: c.gain,
        id: NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
    };
    Ok((corrected, report, applied))
}

/// The program header's line for a compensated job: what is cut instead
/// of the design, from which measurement.
pub(crate) fn header_words(c: &Compensation) -> String {
    format!(
        "compensated: the surface cut is the design less {} times the error measured in {} md5 {}, fitted to order {} over smoothing {} mm; next part predicted {:.2} nm PV, {:.2} nm RMS",
        c.gain,
        c.measurement,
        c.md5,
        c.order,
        lensc_lang::check::trim_num(c.smoothing_mm),
        c.predicted_pv_nm,
        c.predicted_rms_nm
    )
}

/// The most points of a map a correction registers and fits: a larger
/// map is taken at every k-th pixel along each axis, k the least that
/// brings it under. A correction of order at most 12 (91 terms) needs no
/// more, and the noise of 100,000 points averages to far under a
/// nanometre. Measured (benches/compensate.rs, a 1000 × 1000 map): at
/// 250,000 points the compensated lowering took 0.67 s CPU.
pub const MAX_POINTS: usize = 100_000;

/// The measurement with a map thinned to at most `MAX_POINTS` points, and
/// the stride taken (1: whole).
fn thinned(data: lensc_measure::Measured) -> (lensc_measure::Measured, usize) {
    let lensc_measure::Measured::Map(m) = data else {
        return (data, 1);
    };
    let n = m.nx * m.ny;
    if n <= MAX_POINTS {
        return (lensc_measure::Measured::Map(m), 1);
    }
    let k = ((n as f64 / MAX_POINTS as f64).sqrt().ceil() as usize).max(2);
    let (nx, ny) = (m.nx.div_ceil(k), m.ny.div_ceil(k));
    let (mut z, mut valid) = (Vec::with_capacity(nx * ny), Vec::with_capacity(nx * ny));
    for j in (0..m.ny).step_by(k) {
        for i in (0..m.nx).step_by(k) {
            z.push(m.z[j * m.nx + i]);
            valid.push(m.valid[j * m.nx + i]);
        }
    }
    let thin = lensc_measure::HeightMap {
        nx,
        ny,
        dx: m.dx * k as f64,
        dy: m.dy * k as f64,
        x0: m.x0,
        y0: m.y0,
        z,
        valid,
    };
    (lensc_measure::Measured::Map(thin), k)
}

/// The measurement's bytes (`job_file::read`: beneath the root, at most
/// `MAX_MEASUREMENT_BYTES`).
fn read(p: &Of, m: &Stated<String>) -> Result<Vec<u8>, Diagnostic> {
    crate::job_file::read(
        p.job,
        m,
        "the measurement",
        MAX_MEASUREMENT_BYTES,
        "measurements of at most 256 MiB are read",
    )
}

/// The basis over the aperture and the width of the cells the error is
/// averaged in: rings a tenth of the smoothing length wide (five rings or
/// more to each term), squares a quarter of it, and no finer than a
/// 2000th of the radius (rings) or a 200th of the width (squares), which
/// bounds the fit's work.
fn basis(domain: &Domain, radial: bool, smoothing: f64) -> (Basis, f64) {
    let (x, y) = match *domain {
        Domain::Circle { radius } => ((-radius, radius), (-radius, radius)),
        Domain::Annulus { outer, .. } => ((-outer, outer), (-outer, outer)),
        Domain::Rect { x, y } => (x, y),
    };
    if radial {
        // The farthest corner from the axis: every point of the aperture
        // lies within it (for a disc or ring, its outer radius).
        let radius = match *domain {
            Domain::Circle { radius } => radius,
            Domain::Annulus { outer, .. } => outer,
            Domain::Rect { .. } => x.0.abs().max(x.1.abs()).hypot(y.0.abs().max(y.1.abs())),
        };
        (
            Basis::radial(radius, smoothing),
            (smoothing / 10.0).max(radius / 2000.0),
        )
    } else {
        let width = (x.1 - x.0).max(y.1 - y.0);
        (
            Basis::map(x, y, smoothing),
            (smoothing / 4.0).max(width / 200.0),
        )
    }
}

/// The design's tape less `gain` × the correction, value and derivatives
/// (the correction's derivatives taken by the graph, exactly).
pub fn corrected_tape(design: &SurfaceTape, fitted: &Correction, gain: f64) -> SurfaceTape {
    let mut g = design.graph.clone();
    let (x, y) = (g.x(), g.y());
    let c = fitted.node(&mut g, x, y, gain);
    let cx = g.derivative(c, Var::X);
    let cy = g.derivative(c, Var::Y);
    let cxx = g.derivative(cx, Var::X);
    let cxy = g.derivative(cx, Var::Y);
    let cyy = g.derivative(cy, Var::Y);
    let o = design.outputs;
    let outputs = [
        g.sub(o[0], c),
        g.sub(o[1], cx),
        g.sub(o[2], cy),
        g.sub(o[3], cxx),
        g.sub(o[4], cxy),
        g.sub(o[5], cyy),
    ];
    SurfaceTape::with_outputs(g, outputs)
}

/// E0366 when the corrected surface curves (concave, towards the tool)
/// more tightly than the tool's nose or ball (`tool_radius`), where the
/// design did not: the tool cannot follow the correction.
fn curvature_check(
    tool_radius: Option<f64>,
    design: &LoweredSurface,
    corrected: &LoweredSurface,
    file: &str,
    surface_name: &str,
) -> Result<(), Failure> {
    let Some(tool) = tool_radius.filter(|r| r.is_finite() && *r > 0.0) else {
        return Ok(());
    };
    let tightest = |l: &LoweredSurface| {
        let f = kernel(&l.tape);
        // 101 × 101 points: the correction's shortest ripple, the aperture
        // over 12, spans eight of them.
        let a = analysis::analyse(f.as_ref(), &l.domain, 101);
        [a.min_radius_concave_x, a.min_radius_concave_y]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.value.total_cmp(&b.value))
    };
    let Some(after) = tightest(corrected).filter(|e| e.value < tool) else {
        return Ok(());
    };
    if tightest(design).is_some_and(|e| e.value < tool) {
        // The design itself is too tight: the strategy's own check says so.
        return Ok(());
    }
    Err(Failure {
        code: codes::COMPENSATE_CURVATURE,
        message: format!(
            "{file}: the corrected `{surface_name}` curves concave to a radius of {:.4} mm at ({:.3}, {:.3}) mm, tighter than the tool's {} mm: the tool cannot follow the correction",
            after.value,
            after.x,
            after.y,
            lensc_lang::check::trim_num(tool)
        ),
        at: None,
        help: Some(
            "give a longer `smoothing` (the correction then follows no ripple shorter than it), or a lower `gain`"
                .into(),
        ),
    })
}

/// Peak to valley and RMS about the mean.
fn pv_rms(e: &[f64]) -> (f64, f64) {
    let n = e.len().max(1) as f64;
    let mean = e.iter().sum::<f64>() / n;
    let rms = (e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let (lo, hi) = e
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    (hi - lo, rms)
}

/// The correction's peak to valley over the aperture (mm), on a 201 × 201
/// grid over its bounding box.
fn correction_pv(fitted: &Correction, domain: &Domain) -> f64 {
    let (x, y) = match *domain {
        Domain::Circle { radius } => ((-radius, radius), (-radius, radius)),
        Domain::Annulus { outer, .. } => ((-outer, outer), (-outer, outer)),
        Domain::Rect { x, y } => (x, y),
    };
    let mut v = Vec::new();
    for j in 0..201 {
        for i in 0..201 {
            let (px, py) = (
                x.0 + (x.1 - x.0) * i as f64 / 200.0,
                y.0 + (y.1 - y.0) * j as f64 / 200.0,
            );
            if domain.contains(px, py) {
                v.push(fitted.at(px, py));
            }
        }
    }
    pv_rms(&v).0
}
