//! `lensc measure`: a measured part held to its job's design. The file
//! is read under the same rules as a job's files (inside the project
//! root after symlinks, a regular file, bounded in size), read into
//! lensc-measure's model, checked against the job's surface (does it lie
//! on the aperture, is enough of it valid), registered to the design, and
//! reported: the error along the surface normal with its PV and RMS, the
//! texture after form removal, a turned part's set-up errors, and the
//! error map as an SVG picture. Every refusal is a `Failure`, a coded
//! error in words that names the file; nothing is written then.

pub mod report;

use std::path::Path;

use lensc_measure::map::{Format, Measured};
use lensc_measure::read::TextUnits;
use lensc_measure::register::{self, Options as Fit, RegisterError};
use lensc_measure::texture;
use lensc_measure::{HeightMap, ReadError};
use lensc_runtime::post::Setup;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::ErrorRaster;

use crate::strategy::JobSpec;
use report::MeasureReport;

/// The largest measurement file read: 256 MiB (a 4096 × 4096 map of
/// float64 with room to spare). Job files have their own, smaller, limit.
pub const MAX_MEASUREMENT_BYTES: u64 = 256 << 20;

/// What `lensc measure` was asked for beyond the files.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// What a plain-text file's numbers are (mm per unit).
    pub units: TextUnits,
    /// The least share of the measured aperture that must be valid.
    pub min_valid: f64,
    /// The texture's nesting index λc (mm).
    pub cutoff: f64,
    /// Use the file's own coordinates instead of centring the map.
    pub keep_origin: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            units: TextUnits::MM,
            min_valid: 0.5,
            cutoff: 0.08,
            keep_origin: false,
        }
    }
}

/// A refusal: its code, its words (naming the file), the byte of the
/// file it points at when there is one, and help.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub code: &'static str,
    pub message: String,
    pub at: Option<usize>,
    pub help: Option<String>,
}

fn fail(code: &'static str, message: String, help: Option<&str>) -> Failure {
    Failure {
        code,
        message,
        at: None,
        help: help.map(str::to_owned),
    }
}

/// What was made: the report and the picture.
pub struct Outcome {
    pub report: MeasureReport,
    pub svg: String,
}

/// Reads the measurement file at `path` as lensc reads a job's files:
/// inside `root` once symlinks are resolved, a regular file, at most
/// `MAX_MEASUREMENT_BYTES`.
pub fn read_file(path: &Path, root: &Path) -> Result<Vec<u8>, Failure> {
    use lensc_lang::sandbox;
    let resolved = sandbox::resolve(path);
    let root = sandbox::resolve(root);
    let e = if !sandbox::inside(&resolved, &root) {
        sandbox::ReadError::OutsideRoot { resolved, root }
    } else {
        match sandbox::read_regular(&resolved, MAX_MEASUREMENT_BYTES) {
            Ok(b) => return Ok(b),
            Err(e) => e,
        }
    };
    Err(fail(
        e.code(),
        format!("cannot read {}: {e}", path.display()),
        None,
    ))
}

/// The coded failure for a reader's error on `file`.
pub fn read_failure(file: &str, e: &ReadError) -> Failure {
    use lensc_lang::codes;
    let (code, at, help) = match e {
        ReadError::Malformed { at, .. } => (codes::MEASURE_UNREADABLE, *at, None),
        ReadError::UnknownFormat => (
            codes::MEASURE_UNREADABLE,
            None,
            Some(
                "export the measurement as X3P, or name a text file .xyz/.csv (points) or .txt (an x z profile)",
            ),
        ),
        ReadError::Unsupported { .. } => (codes::MEASURE_UNREADABLE, None, None),
        ReadError::Truncated { .. } => (
            codes::MEASURE_TRUNCATED,
            None,
            Some("copy the file again from the instrument"),
        ),
        ReadError::Checksum { .. } => (
            codes::MEASURE_CHECKSUM,
            None,
            Some(
                "export the measurement again; a file edited by hand needs its checksums written again",
            ),
        ),
    };
    Failure {
        code,
        message: format!("{file}: {e}"),
        at,
        help: help.map(str::to_owned),
    }
}

/// The points to register, in mm, in the design's frame before
/// registration, with the kind of data and what the report says of it.
struct Points {
    /// Valid points inside the aperture.
    inside: Vec<[f64; 3]>,
    /// All measured points inside the aperture, valid or not, and all points.
    in_aperture: usize,
    total: usize,
    valid: usize,
    extent: [[f64; 2]; 2],
    /// The map (centred or not), for texture and the picture's spacing.
    map: Option<HeightMap>,
    two_d: bool,
    cloud: bool,
}

/// The x and y ranges of points: [[x min, x max], [y min, y max]].
fn extent_of(pts: &[[f64; 3]]) -> [[f64; 2]; 2] {
    let mut e = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for p in pts {
        for k in 0..2 {
            e[k][0] = e[k][0].min(p[k]);
            e[k][1] = e[k][1].max(p[k]);
        }
    }
    e
}

/// Points measured anywhere (a cloud, or a profile along x when `cloud`
/// is false), centred on their extent unless `keep_origin`, with those
/// within the aperture kept.
fn scattered(
    mut pts: Vec<[f64; 3]>,
    keep_origin: bool,
    within: &dyn Fn(f64, f64) -> bool,
    cloud: bool,
) -> Points {
    if !keep_origin {
        let e = extent_of(&pts);
        let (cx, cy) = ((e[0][0] + e[0][1]) / 2.0, (e[1][0] + e[1][1]) / 2.0);
        for p in pts.iter_mut() {
            p[0] -= cx;
            p[1] -= cy;
        }
    }
    let total = pts.len();
    let extent = extent_of(&pts);
    let inside: Vec<[f64; 3]> = pts.into_iter().filter(|p| within(p[0], p[1])).collect();
    Points {
        in_aperture: inside.len(),
        total,
        valid: total,
        inside,
        extent,
        map: None,
        two_d: cloud,
        cloud,
    }
}

fn points(data: Measured, opts: &Options, within: &dyn Fn(f64, f64) -> bool) -> Points {
    match data {
        Measured::Map(m) => {
            let m = if opts.keep_origin { m } else { m.centred() };
            let (mut inside, mut in_aperture) = (Vec::new(), 0);
            for j in 0..m.ny {
                for i in 0..m.nx {
                    let (x, y) = (m.x(i), m.y(j));
                    if within(x, y) {
                        in_aperture += 1;
                        let k = j * m.nx + i;
                        if m.valid[k] {
                            inside.push([x, y, m.z[k]]);
                        }
                    }
                }
            }
            let extent = [
                [m.x(0).min(m.x(m.nx - 1)), m.x(0).max(m.x(m.nx - 1))],
                [m.y(0).min(m.y(m.ny - 1)), m.y(0).max(m.y(m.ny - 1))],
            ];
            Points {
                in_aperture,
                total: m.nx * m.ny,
                valid: m.valid_count(),
                inside,
                extent,
                map: Some(m),
                two_d: true,
                cloud: false,
            }
        }
        Measured::Cloud(c) => scattered(c.points, opts.keep_origin, within, true),
        Measured::Profile(p) => {
            let pts = p.x.iter().zip(&p.z).map(|(x, z)| [*x, 0.0, *z]).collect();
            scattered(pts, opts.keep_origin, within, false)
        }
    }
}

/// Holds the measurement `bytes` (of the file named `file`) to the job's
/// design; the report and the picture, or why not.
pub fn measure(
    spec: &JobSpec,
    file: &str,
    bytes: &[u8],
    opts: &Options,
) -> Result<Outcome, Failure> {
    use lensc_lang::codes;
    let m =
        lensc_measure::read::read(file, bytes, opts.units).map_err(|e| read_failure(file, &e))?;
    let head = spec.head();
    let surface_name = head.names.surface.clone();
    let lowered = &head.surface.lowered;
    let (f, _) = crate::evaluate::evaluator(&lowered.tape);
    let domain = lowered.domain;
    let format = m.format;
    let kind = match &m.data {
        Measured::Map(_) => "map",
        Measured::Cloud(_) => "point_cloud",
        Measured::Profile(_) => "profile",
    };
    let p = points(m.data, opts, &|x, y| domain.contains(x, y));
    let aperture = aperture_words(&domain);
    // Does it lie on the part at all? Then is enough of it valid?
    let on_part = p.in_aperture as f64 / p.total.max(1) as f64;
    if on_part < 0.5 {
        return Err(fail(
            codes::MEASURE_MISMATCH,
            format!(
                "{file}: {:.1} % of the measured points lie inside the aperture of `{surface_name}` ({aperture}): a measurement in other units, or of another part",
                100.0 * on_part
            ),
            Some(if matches!(format, Format::Xyz | Format::Profile) {
                "a text file's numbers carry no unit: say which with --units (mm unless given)"
            } else {
                "check that the file measures this job's part; --keep-origin uses the file's own coordinates instead of centring the map"
            }),
        ));
    }
    let share = p.inside.len() as f64 / p.in_aperture.max(1) as f64;
    if share < opts.min_valid {
        return Err(fail(
            codes::MEASURE_TOO_LITTLE,
            format!(
                "{file}: {:.1} % of the {} measured points inside the aperture of `{surface_name}` are valid; at least {:.1} % are needed (--min-valid)",
                100.0 * share,
                p.in_aperture,
                100.0 * opts.min_valid
            ),
            Some(
                "measure the part again, or lower --min-valid knowing what the figures then cover",
            ),
        ));
    }
    let fit = Fit {
        two_d: p.two_d,
        ..Fit::default()
    };
    let reg = if p.cloud {
        register::register_cloud(f.as_ref(), &p.inside, fit)
    } else {
        register::register_heights(f.as_ref(), &p.inside, fit)
    };
    let reg = reg.map_err(|e| match e {
        RegisterError::TooFewPoints { points } => fail(
            codes::MEASURE_TOO_LITTLE,
            format!("{file}: {points} valid points inside the aperture of `{surface_name}`: too few to register"),
            None,
        ),
        RegisterError::NotConverged { iterations, rms } => fail(
            codes::MEASURE_NOT_CONVERGED,
            format!(
                "{file}: the registration to `{surface_name}` did not converge in {iterations} iterations{}",
                if rms.is_finite() { format!(" (residual RMS {:.1} nm)", rms * 1e6) } else { String::new() }
            ),
            Some("centre the map in the instrument's software, or check that it measures this surface"),
        ),
        RegisterError::Undefined { points } => fail(
            codes::MEASURE_NOT_CONVERGED,
            format!("{file}: the registration to `{surface_name}` moved {points} measured points where the design has no value"),
            Some("centre the map in the instrument's software, or check that it measures this surface"),
        ),
    })?;
    // The error along the normal, at each registered point.
    let pred = register::predict(f.as_ref(), &p.inside, &reg.values);
    let errors: Vec<f64> = p
        .inside
        .iter()
        .zip(&pred)
        .map(|(q, h)| (q[2] - h[0]) / (1.0 + h[1] * h[1] + h[2] * h[2]).sqrt())
        .collect();
    let form = form_error(&p.inside, &errors);
    let (lo, hi) = pred
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| {
            (lo.min(h[0]), hi.max(h[0]))
        });
    let sag_range = hi - lo;
    if form.rms_nm * 1e-6 > 0.25 * sag_range && form.rms_nm > 1000.0 {
        return Err(fail(
            codes::MEASURE_MISMATCH,
            format!(
                "{file}: after registration the measurement departs from `{surface_name}` by {:.3} µm RMS, more than a quarter of the design's {:.3} µm sag range over the measured points: heights in other units, or another surface",
                form.rms_nm / 1000.0,
                sag_range * 1000.0
            ),
            Some(
                "check the file's units (--units for a text file) and that it measures this job's surface",
            ),
        ));
    }
    let (texture, texture_skipped) = texture_of(&p, &errors, opts.cutoff);
    let setup = (spec.setup() == Setup::Lathe)
        .then(|| setup_of(f.as_ref(), &p, &errors, &reg))
        .flatten();
    let raster = raster(&p.inside, &errors, p.map.as_ref().map(|m| m.dx.max(m.dy)));
    let registration = registration_report(&reg);
    let caption = caption(&form, &registration, &raster);
    let svg = crate::plots::measured_error_svg(
        &format!("{}: measured error of `{surface_name}` ({file})", head.name),
        &caption,
        &raster,
    )
    .map_err(|e| {
        fail(
            codes::MEASURE_UNREADABLE,
            format!("{file}: the error map cannot be drawn: {e}"),
            None,
        )
    })?;
    let report = MeasureReport {
        job: head.name.clone(),
        surface: surface_name,
        measurement: report::Measurement {
            file: file.to_owned(),
            format: format.name().to_owned(),
            kind: kind.to_owned(),
            md5: lensc_measure::md5_hex(bytes),
            instrument: m.instrument,
            points: p.total,
            valid_points: p.valid,
            pixel_um: p.map.as_ref().map(|m| [m.dx * 1000.0, m.dy * 1000.0]),
            extent_mm: p.extent,
            centred: !opts.keep_origin,
        },
        coverage: report::Coverage {
            points_in_aperture: p.in_aperture,
            valid_share: share,
            min_valid_share: opts.min_valid,
        },
        registration,
        form_error: form,
        texture,
        texture_skipped,
        setup,
    };
    Ok(Outcome { report, svg })
}

fn aperture_words(d: &lensc_runtime::surface::analysis::Domain) -> String {
    use lensc_runtime::surface::analysis::Domain;
    match *d {
        Domain::Circle { radius } => format!("a disc {} mm across", 2.0 * radius),
        Domain::Annulus { inner, outer } => {
            format!("a ring {} to {} mm across", 2.0 * inner, 2.0 * outer)
        }
        Domain::Rect { x, y } => format!("x {} .. {} mm, y {} .. {} mm", x.0, x.1, y.0, y.1),
    }
}

fn form_error(pts: &[[f64; 3]], e: &[f64]) -> report::FormError {
    let n = e.len() as f64;
    let mean = e.iter().sum::<f64>() / n;
    let rms = (e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let (mut imax, mut imin) = (0, 0);
    for k in 0..e.len() {
        if e[k] > e[imax] {
            imax = k;
        }
        if e[k] < e[imin] {
            imin = k;
        }
    }
    let at = |k: usize| report::Extreme {
        nm: e[k] * 1e6,
        at_mm: [pts[k][0], pts[k][1]],
    };
    report::FormError {
        along: "the surface normal, measured − design (positive: material left)".into(),
        points: e.len(),
        pv_nm: (e[imax] - e[imin]) * 1e6,
        rms_nm: rms * 1e6,
        mean_nm: mean * 1e6,
        max: at(imax),
        min: at(imin),
    }
}

fn texture_of(
    p: &Points,
    errors: &[f64],
    cutoff: f64,
) -> (Option<report::Texture>, Option<String>) {
    let Some(m) = &p.map else {
        return (None, Some("texture is figured on maps (ISO 25178-2 areal parameters); this measurement is not one".into()));
    };
    let (wx, wy) = (m.nx as f64 * m.dx, m.ny as f64 * m.dy);
    if wx.min(wy) < 2.0 * cutoff {
        return (
            None,
            Some(format!(
                "the map is {:.3} × {:.3} mm, less than twice the cutoff λc = {cutoff} mm across (--cutoff)",
                wx, wy
            )),
        );
    }
    // The residual on the map's grid: the error where valid and inside.
    let mut res = m.clone();
    res.valid.iter_mut().for_each(|v| *v = false);
    let mut k = 0;
    for j in 0..m.ny {
        for i in 0..m.nx {
            let at = j * m.nx + i;
            if k < p.inside.len() && p.inside[k][0] == m.x(i) && p.inside[k][1] == m.y(j) {
                res.z[at] = errors[k];
                res.valid[at] = true;
                k += 1;
            }
        }
    }
    match texture::texture(&res, cutoff) {
        Some(t) => (
            Some(report::Texture {
                form_removed: "the registered design surface (least squares: piston, tilt, decentre, clocking)".into(),
                filter: "Gaussian L-filter (ISO 16610-61 weighting), first-order regression at edges and holes".into(),
                cutoff_mm: cutoff,
                sa_nm: t.sa * 1e6,
                sq_nm: t.sq * 1e6,
                sz_nm: t.sz * 1e6,
                sdq: t.sdq,
                points: t.points,
            }),
            None,
        ),
        None => (None, Some("fewer than two valid points".into())),
    }
}

fn setup_of(
    f: &dyn SurfaceFn,
    p: &Points,
    errors: &[f64],
    reg: &register::Registration,
) -> Option<report::SetUp> {
    let (dx, dy) = reg.decentre();
    let r: Vec<f64> = p
        .inside
        .iter()
        .map(|q| ((q[0] - dx).powi(2) + (q[1] - dy).powi(2)).sqrt())
        .collect();
    let ring = match &p.map {
        Some(m) => m.dx.max(m.dy),
        None => {
            let rmax = r.iter().cloned().fold(0.0, f64::max);
            (rmax / 500.0).max(1e-6)
        }
    };
    let s = lensc_measure::turned::fit(f, &r, errors, ring)?;
    let um = |v: f64| v * 1000.0;
    Some(report::SetUp {
        x_offset_um: um(s.x_offset),
        x_correction: if s.x_offset.abs() < 1e-7 {
            "none: the cone is below 0.1 nm".into()
        } else {
            format!(
                "move the tool's X zero by {:+.3} µm (towards the spindle axis for a negative value)",
                -um(s.x_offset)
            )
        },
        centre_height_um: um(s.centre_height),
        centre_height_correction: if s.centre_height == 0.0 {
            "none seen: no stub stands at the centre".into()
        } else {
            format!(
                "move the tool tip {:.3} µm towards the centre height; the map does not tell whether it sits above or below: face a test part with the tip moved a known amount to learn which",
                um(s.centre_height)
            )
        },
        stub_radius_um: um(s.stub_radius),
        ring_um: um(s.ring),
        cone_fit_rms_nm: s.residual_rms * 1e6,
        rings: s.rings,
        model: "z(r) = f(sqrt(r² − h²) − δx): δx from the cone outside the stub, |h| from the stub's radius ρ = sqrt(δx² + h²)".into(),
    })
}

fn registration_report(r: &register::Registration) -> report::Registration {
    let (tx, ty) = r.tilt();
    let (dx, dy) = r.decentre();
    report::Registration {
        method: r.method.to_owned(),
        piston_um: r.piston() * 1000.0,
        tilt_x_urad: tx * 1e6,
        tilt_y_urad: ty * 1e6,
        decentre_x_um: dx * 1000.0,
        decentre_y_um: dy * 1000.0,
        clocking_urad: r.clocking().map(|c| c * 1e6),
        left_out: r
            .left_out
            .iter()
            .map(|(p, why)| report::LeftOut {
                parameter: (*p).to_owned(),
                reason: (*why).to_owned(),
            })
            .collect(),
        iterations: r.iterations,
    }
}

/// The error in blocks at most 200 a side (no smaller than the pixel),
/// each holding the error of largest magnitude (sign kept).
fn raster(pts: &[[f64; 3]], e: &[f64], pixel: Option<f64>) -> ErrorRaster {
    let (mut x, mut y) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for p in pts {
        x = (x.0.min(p[0]), x.1.max(p[0]));
        y = (y.0.min(p[1]), y.1.max(p[1]));
    }
    let span = (x.1 - x.0).max(y.1 - y.0).max(1e-6);
    let block = (span / 200.0).max(pixel.unwrap_or(0.0));
    let (x, y) = (
        (x.0 - block / 2.0, x.1 + block / 2.0),
        (y.0 - block / 2.0, y.1 + block / 2.0),
    );
    let nx = (((x.1 - x.0) / block).ceil() as usize).max(1);
    let ny = (((y.1 - y.0) / block).ceil() as usize).max(1);
    let mut cells = vec![f64::NAN; nx * ny];
    for (p, v) in pts.iter().zip(e) {
        let i = (((p[0] - x.0) / block) as usize).min(nx - 1);
        let j = (((p[1] - y.0) / block) as usize).min(ny - 1);
        let c = &mut cells[j * nx + i];
        if c.is_nan() || v.abs() > c.abs() {
            *c = *v;
        }
    }
    ErrorRaster {
        x,
        y,
        block,
        nx,
        ny,
        cells,
    }
}

fn caption(f: &report::FormError, r: &report::Registration, raster: &ErrorRaster) -> String {
    format!(
        "The measured part's error along the surface normal, measured − design in nm (positive where material is left), after registration ({}: piston {:.3} µm, tilt {:.1}, {:.1} µrad, decentre {:.3}, {:.3} µm{}). \
         PV {:.2} nm, RMS {:.2} nm over {} points. Shown on {} × {} blocks {:.2} µm square, each holding the error of largest magnitude among its points (sign kept); white: no valid point.",
        r.method,
        r.piston_um,
        r.tilt_x_urad,
        r.tilt_y_urad,
        r.decentre_x_um,
        r.decentre_y_um,
        r.clocking_urad
            .map_or(String::new(), |c| format!(", clocking {c:.1} µrad")),
        f.pv_nm,
        f.rms_nm,
        f.points,
        raster.nx,
        raster.ny,
        raster.block * 1000.0
    )
}
