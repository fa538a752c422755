//! A measurement read and placed on a design: the file read under the
//! project's rules, its points, the checks that it lies on the part and
//! is valid enough, the registration, and the error at each point. Both
//! `lensc measure` (the parent module) and a job's `compensate` block
//! (`crate::compensate`) start here; nothing here knows a job.

use std::path::Path;

use lensc_measure::map::{Format, Measured};
use lensc_measure::read::TextUnits;
use lensc_measure::register::{self, Options as Fit, RegisterError};
use lensc_measure::{HeightMap, ReadError};
use lensc_runtime::surface::ir::SurfaceFn;

use super::report;

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
    /// Whether a job's `compensate` block names the file (its messages
    /// then name the block's parameters instead of the command's flags).
    pub from_job: bool,
    /// Register each lenslet of the job's array on its own too
    /// (`--per-lenslet`).
    pub per_lenslet: bool,
    /// The map is one lenslet's field (`--lenslet`): register it to that
    /// lenslet's design alone.
    pub lenslet: Option<LensletPick>,
    /// Where on the part (mm, the design's x and y) the map's reference
    /// point lay (`--at`): its middle pixel, or the file's origin with
    /// `keep_origin`. `None`: on the picked lenslet's centre.
    pub at: Option<(f64, f64)>,
}

/// A lenslet of an array as a user names it: its index in the array (as
/// the build report and `--per-lenslet` number them, from 0, row by row
/// from the least y, along each row from the least x), or its row and
/// column (from 0, in the same order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LensletPick {
    Index(usize),
    RowColumn(usize, usize),
}

impl Default for Options {
    fn default() -> Self {
        Options {
            units: TextUnits::MM,
            min_valid: 0.5,
            cutoff: 0.08,
            keep_origin: false,
            from_job: false,
            per_lenslet: false,
            lenslet: None,
            at: None,
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

pub(crate) fn fail(code: &'static str, message: String, help: Option<&str>) -> Failure {
    Failure {
        code,
        message,
        at: None,
        help: help.map(str::to_owned),
    }
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
pub(crate) struct Points {
    /// Valid points inside the aperture.
    pub(crate) inside: Vec<[f64; 3]>,
    /// All measured points inside the aperture, valid or not, and all points.
    pub(crate) in_aperture: usize,
    pub(crate) total: usize,
    pub(crate) valid: usize,
    pub(crate) extent: [[f64; 2]; 2],
    /// The map (centred or not), for texture and the picture's spacing.
    pub(crate) map: Option<HeightMap>,
    pub(crate) two_d: bool,
    pub(crate) cloud: bool,
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

pub(crate) fn points(data: Measured, opts: &Options, within: &dyn Fn(f64, f64) -> bool) -> Points {
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

/// A measurement registered to a design: its points, the placement found,
/// and the error at each point, along the normal (`errors`) and along z
/// (`vertical`: measured − design height, mm).
pub struct Registered {
    pub(crate) points: Points,
    pub registration: register::Registration,
    pub errors: Vec<f64>,
    pub vertical: Vec<f64>,
    pub form: report::FormError,
    /// The share of the measured aperture that is valid.
    pub share: f64,
    /// How far either side of an array's stepped rims (mm) the pixels
    /// were left out of the registration (`steps`); none without them.
    pub(crate) clear_of_rims: Option<f64>,
}

impl Registered {
    /// The valid points inside the aperture, as measured (mm).
    pub fn inside(&self) -> &[[f64; 3]] {
        &self.points.inside
    }
    /// Whether the measurement is a profile (one line, no y).
    pub fn is_profile(&self) -> bool {
        !self.points.two_d
    }
    /// The report's words for the placement found.
    pub fn registration_report(&self) -> report::Registration {
        registration_report(&self.registration)
    }
}

/// Registers the measurement `data` (of the file `file`) to the design
/// `f` over `domain` (the surface `surface_name`): refused, with its code,
/// when too little of it lies on the aperture or is valid, when the
/// registration does not converge, or when what is left departs from the
/// design more than a part could (other units, another surface). A map
/// of an array whose rims step onto the land (`rims`) is registered clear
/// of them (`steps::register_clear`).
#[allow(clippy::too_many_arguments)]
pub fn register_measurement(
    f: &(dyn SurfaceFn + Sync),
    domain: &lensc_runtime::surface::analysis::Domain,
    surface_name: &str,
    file: &str,
    data: Measured,
    format: Format,
    opts: &Options,
    rims: Option<&super::steps::SteppedRims>,
) -> Result<Registered, Failure> {
    use lensc_lang::codes;
    let domain = *domain;
    let p = points(data, opts, &|x, y| domain.contains(x, y));
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
                if opts.from_job {
                    "a text file's numbers carry no unit: say which with `units:` in the `compensate` block (mm unless given)"
                } else {
                    "a text file's numbers carry no unit: say which with --units (mm unless given)"
                }
            } else if opts.from_job {
                "check that the file measures this job's part, centred on it"
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
                "{file}: {:.1} % of the {} measured points inside the aperture of `{surface_name}` are valid; at least {:.1} % are needed{}",
                100.0 * share,
                p.in_aperture,
                100.0 * opts.min_valid,
                if opts.from_job { "" } else { " (--min-valid)" }
            ),
            Some(if opts.from_job {
                "measure the part again: a correction is made only where the part was measured"
            } else {
                "measure the part again, or lower --min-valid knowing what the figures then cover"
            }),
        ));
    }
    let fit = Fit {
        two_d: p.two_d,
        ..Fit::default()
    };
    let reg = if p.cloud {
        register::register_cloud(f, &p.inside, fit).map(|r| (r, None))
    } else {
        let pixel = p.map.as_ref().map_or(0.0, |m| m.dx.max(m.dy));
        super::steps::register_clear(
            &|pts, fit| register::register_heights_parallel(f, pts, fit),
            &p.inside,
            fit,
            rims.map(|r| (r, (0.0, 0.0))),
            pixel,
        )
    };
    let (reg, clear_of_rims) =
        reg.map_err(|e| not_registered(file, &format!("`{surface_name}`"), e))?;
    // The error along the normal, at each registered point.
    let pred = register::predict(f, &p.inside, &reg.values);
    let errors: Vec<f64> = p
        .inside
        .iter()
        .zip(&pred)
        .map(|(q, h)| (q[2] - h[0]) / (1.0 + h[1] * h[1] + h[2] * h[2]).sqrt())
        .collect();
    let vertical: Vec<f64> = p
        .inside
        .iter()
        .zip(&pred)
        .map(|(q, h)| q[2] - h[0])
        .collect();
    let form = form_error(&p.inside, &errors);
    departs(&pred, &form, file, &format!("`{surface_name}`"))?;
    Ok(Registered {
        points: p,
        registration: reg,
        errors,
        vertical,
        form,
        share,
        clear_of_rims,
    })
}

/// The coded failure for a registration of the file `file` to `what`
/// (the surface's name in backquotes, or more) that failed with `e`.
pub(crate) fn not_registered(file: &str, what: &str, e: RegisterError) -> Failure {
    use lensc_lang::codes;
    match e {
        RegisterError::TooFewPoints { points } => fail(
            codes::MEASURE_TOO_LITTLE,
            format!(
                "{file}: {points} valid points inside the aperture of {what}: too few to register"
            ),
            None,
        ),
        RegisterError::NotConverged { iterations, rms } => fail(
            codes::MEASURE_NOT_CONVERGED,
            format!(
                "{file}: the registration to {what} did not converge in {iterations} iterations{}",
                if rms.is_finite() {
                    format!(" (residual RMS {:.1} nm)", rms * 1e6)
                } else {
                    String::new()
                }
            ),
            Some(
                "centre the map in the instrument's software, or check that it measures this surface",
            ),
        ),
        RegisterError::Undefined { points } => fail(
            codes::MEASURE_NOT_CONVERGED,
            format!(
                "{file}: the registration to {what} moved {points} measured points where the design has no value"
            ),
            Some(
                "centre the map in the instrument's software, or check that it measures this surface",
            ),
        ),
    }
}

/// E0364 when the error left after registration (`form`) is more than a
/// quarter of the design's sag range over the points (`pred`, the heights
/// the registered design predicts) and over 1 µm RMS: heights in other
/// units, or another surface.
pub(crate) fn departs(
    pred: &[[f64; 3]],
    form: &report::FormError,
    file: &str,
    what: &str,
) -> Result<(), Failure> {
    use lensc_lang::codes;
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
                "{file}: after registration the measurement departs from {what} by {:.3} µm RMS, more than a quarter of the design's {:.3} µm sag range over the measured points: heights in other units, or another surface",
                form.rms_nm / 1000.0,
                sag_range * 1000.0
            ),
            Some(
                "check the file's units (--units for a text file) and that it measures this job's surface",
            ),
        ));
    }
    Ok(())
}

pub(crate) fn aperture_words(d: &lensc_runtime::surface::analysis::Domain) -> String {
    use lensc_runtime::surface::analysis::Domain;
    match *d {
        Domain::Circle { radius } => format!("a disc {} mm across", 2.0 * radius),
        Domain::Annulus { inner, outer } => {
            format!("a ring {} to {} mm across", 2.0 * inner, 2.0 * outer)
        }
        Domain::Rect { x, y } => format!("x {} .. {} mm, y {} .. {} mm", x.0, x.1, y.0, y.1),
    }
}

pub(crate) fn form_error(pts: &[[f64; 3]], e: &[f64]) -> report::FormError {
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

pub(crate) fn registration_report(r: &register::Registration) -> report::Registration {
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
