//! `lensc measure`: a measured part held to its job's design. The file
//! is read under the same rules as a job's files (inside the project
//! root after symlinks, a regular file, bounded in size), read into
//! lensc-measure's model, checked against the job's surface (does it lie
//! on the aperture, is enough of it valid), registered to the design, and
//! reported: the error along the surface normal with its PV and RMS, the
//! texture after form removal, a turned part's set-up errors, and the
//! error map as an SVG picture; with `--lenslet`, a map of one lenslet's
//! field held to that lenslet alone (`field`). Every refusal is a `Failure`, a coded
//! error in words that names the file; nothing is written then.

mod field;
mod lenslets;
pub mod placed;
pub mod report;
pub mod steps;

use lensc_measure::map::Measured;
use lensc_measure::register;
use lensc_measure::texture;
use lensc_runtime::post::Setup;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::ErrorRaster;

use crate::strategy::JobSpec;
pub use field::lenslet_of;
pub use placed::{
    Failure, LensletPick, MAX_MEASUREMENT_BYTES, Options, read_failure, read_file,
    register_measurement,
};
use placed::{Points, Registered, fail, registration_report};
use report::MeasureReport;

/// What was made: the report and the picture.
pub struct Outcome {
    pub report: MeasureReport,
    pub svg: String,
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
    let lowered = head.surface.design();
    let (f, _) = crate::evaluate::evaluator(&lowered.tape);
    if let Some(pick) = opts.lenslet {
        return field::measure(
            head,
            f.as_ref(),
            &lowered.domain,
            (file, bytes),
            m,
            pick,
            opts,
        );
    }
    let format = m.format;
    // Lenslet by lenslet: only a map of an array.
    let array = if opts.per_lenslet {
        let Some(l) = head.surface.lenslets.as_ref() else {
            return Err(fail(
                codes::PER_LENSLET_UNAVAILABLE,
                format!(
                    "{file}: --per-lenslet registers each lenslet of an array, and `{surface_name}` is not an array of lenslets (grid, hex_grid or linear_array, or one wrapped on a roller)"
                ),
                Some("leave out --per-lenslet to register the whole surface"),
            ));
        };
        if !matches!(m.data, Measured::Map(_)) {
            return Err(fail(
                codes::PER_LENSLET_UNAVAILABLE,
                format!(
                    "{file}: --per-lenslet registers each lenslet on a map's pixels, and this measurement is a point cloud or a profile"
                ),
                Some("measure the array as a map (X3P, SDF, MetroPro), or leave out --per-lenslet"),
            ));
        }
        Some(l)
    } else {
        None
    };
    let kind = match &m.data {
        Measured::Map(_) => "map",
        Measured::Cloud(_) => "point_cloud",
        Measured::Profile(_) => "profile",
    };
    // An array whose rims step onto the land: its map is registered
    // clear of them.
    let rims = match (&m.data, head.surface.lenslets.as_ref()) {
        (Measured::Map(_), Some(l)) => steps::SteppedRims::of(f.as_ref(), l),
        _ => None,
    };
    let placed = register_measurement(
        f.as_ref(),
        &lowered.domain,
        &surface_name,
        file,
        m.data,
        format,
        opts,
        rims.as_ref(),
    )?;
    let Registered {
        points: p,
        registration: reg,
        errors,
        form,
        share,
        clear_of_rims,
        ..
    } = placed;
    let (texture, texture_skipped) = texture_of(&p, &errors, opts.cutoff);
    let lenslets = array
        .zip(p.map.as_ref())
        .map(|(l, map)| lenslets::measure(f.as_ref(), l, map, &reg, rims.as_ref(), opts));
    let setup = (spec.setup() == Setup::Lathe)
        .then(|| setup_of(f.as_ref(), &p, &errors, &reg))
        .flatten();
    let raster = raster(&p.inside, &errors, p.map.as_ref().map(|m| m.dx.max(m.dy)));
    let mut registration = registration_report(&reg);
    if let (Some(r), Some(band)) = (&rims, clear_of_rims) {
        registration.method.push_str(&r.words(band));
    }
    let mut caption = caption(&form, &registration, &raster);
    if let Some(l) = &lenslets {
        caption.push_str(&lenslets_caption(l));
    }
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
        lenslets,
        lenslet: None,
    };
    Ok(Outcome { report, svg })
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
        Some(t) => (Some(texture_report(&t, cutoff)), None),
        None => (None, Some("fewer than two valid points".into())),
    }
}

/// The report's words for texture `t` after the filter of nesting index
/// `cutoff` (mm).
fn texture_report(t: &texture::Texture, cutoff: f64) -> report::Texture {
    report::Texture {
        form_removed:
            "the registered design surface (least squares: piston, tilt, decentre, clocking)".into(),
        filter:
            "Gaussian L-filter (ISO 16610-61 weighting), first-order regression at edges and holes"
                .into(),
        cutoff_mm: cutoff,
        sa_nm: t.sa * 1e6,
        sq_nm: t.sq * 1e6,
        sz_nm: t.sz * 1e6,
        sdq: t.sdq,
        points: t.points,
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
        // A measurement has no uncut area: only points or none.
        uncut: vec![false; cells.len()],
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

/// What the picture adds with `--per-lenslet`: the lenslets registered,
/// the worst, and those not registered.
fn lenslets_caption(l: &report::Lenslets) -> String {
    let worst = l
        .worst_pv
        .and_then(|k| l.each.iter().find(|e| e.index == k))
        .and_then(|e| e.form_error.as_ref().map(|f| (e.index, e.centre_mm, f)));
    let mut s = format!(
        " Lenslet by lenslet (each registered on its own): {} of the array's {} reached, {} not registered",
        l.reached, l.in_array, l.not_registered
    );
    if let Some((k, c, f)) = worst {
        s.push_str(&format!(
            "; the worst, lenslet {k} at x {:.4}, y {:.4} mm: PV {:.2} nm, RMS {:.2} nm",
            c[0], c[1], f.pv_nm, f.rms_nm
        ));
    }
    s.push('.');
    s
}
