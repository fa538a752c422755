//! `lensc measure --lenslet N`: a map of one lenslet's field (an
//! interferometer's or a profilometer's field of view, seed 003's 1.8 mm
//! at 1.8 µm pixels) held to that lenslet's design alone. The map's own x
//! and y are the instrument's, not the part's: its reference point (its
//! middle pixel, or the file's origin with `--keep-origin`) is taken to
//! lie on the lenslet's centre, or where `--at X,Y` says on the part. The
//! pixels that then fall inside the lenslet's aperture widened by a fifth
//! (the margin of land that tells a sphere's decentre from its tilt) and
//! on the design are registered to the design seen from the lenslet's
//! centre (piston, tilt, decentre; clocking where the lenslet is not of
//! revolution), starting from the lenslet's nominal place (clear of its
//! rim where it steps onto the land: `steps`); the
//! decentre found is where the lenslet's centre lies from where the field
//! was placed. Refused, with a code, on a surface that is not an array
//! (E0368), a lenslet the array does not have (E0369) and a field whose
//! valid pixels cover less than `--min-valid` of the lenslet (E0370);
//! one that covers less than 95 % of it is measured with a finding
//! (W0037).

use lensc_lang::codes;
use lensc_measure::map::{Measured, Measurement};
use lensc_measure::register::{self, Options as Fit};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::lenslets::Lenslets;

use super::lenslets::{FromCentre, MARGIN, rows_and_columns};
use super::placed::{self, Failure, LensletPick, Options, fail};
use super::steps::{SteppedRims, register_clear};
use super::{Outcome, report};

/// Below this share of the lenslet's aperture covered, its figures are
/// said to describe only the part measured (W0037).
const WHOLE: f64 = 0.95;
use crate::job::JobHead;

/// The lenslet `pick` names in the array of the job `head`: its index, or
/// why not (E0368 without an array, E0369 past its last lenslet). The
/// messages name the job and the surface, not a file: the command checks
/// this before it reads the measurement.
pub fn lenslet_of(head: &JobHead, pick: LensletPick) -> Result<usize, Failure> {
    let surface = &head.names.surface;
    let Some(l) = head.surface.lenslets.as_ref() else {
        return Err(fail(
            codes::PER_LENSLET_UNAVAILABLE,
            format!(
                "--lenslet measures one lenslet of an array, and the surface `{surface}` of job `{}` is not an array of lenslets (grid, hex_grid or linear_array, or one wrapped on a roller)",
                head.name
            ),
            Some("leave out --lenslet to register the map to the whole surface"),
        ));
    };
    let places = rows_and_columns(l.centres());
    let rows = places.iter().map(|p| p.0 + 1).max().unwrap_or(0);
    let widths: Vec<usize> = (0..rows)
        .map(|r| places.iter().filter(|p| p.0 == r).count())
        .collect();
    let (least, most) = (
        widths.iter().copied().min().unwrap_or(0),
        widths.iter().copied().max().unwrap_or(0),
    );
    let columns = if least == most {
        format!("of {most} columns each")
    } else {
        format!("of {least} to {most} columns")
    };
    let shape = format!(
        "the array `{surface}` of job `{}` has {} lenslets, 0 to {} ({rows} rows, 0 to {}, {columns})",
        head.name,
        l.len(),
        l.len() - 1,
        rows - 1
    );
    let help = Some(
        "lenslets are numbered from 0, row by row from the least y and along each row from the least x, as the build report's `lenslets` and `lensc measure --per-lenslet` number them; ROW,COLUMN count from 0 in the same order",
    );
    match pick {
        LensletPick::Index(k) if k < l.len() => Ok(k),
        LensletPick::Index(k) => Err(fail(
            codes::LENSLET_NOT_IN_ARRAY,
            format!("--lenslet {k}: {shape}"),
            help,
        )),
        LensletPick::RowColumn(r, c) => places.iter().position(|&p| p == (r, c)).ok_or_else(|| {
            let why = if r >= rows {
                format!("there is no row {r}")
            } else {
                format!("row {r} has {} columns, 0 to {}", widths[r], widths[r] - 1)
            };
            fail(
                codes::LENSLET_NOT_IN_ARRAY,
                format!("--lenslet {r},{c}: {why}: {shape}"),
                help,
            )
        }),
    }
}

/// Where the registration `reg` puts the map's reference point, placed
/// at `off` from the lenslet's centre, the lenslet at its design centre:
/// R(γ)(off − d), from the lenslet's centre.
fn where_found(reg: &register::Registration, off: (f64, f64)) -> (f64, f64) {
    let (d, gamma) = (reg.decentre(), reg.values[5]);
    let (s, co) = gamma.sin_cos();
    let (ex, ey) = (off.0 - d.0, off.1 - d.1);
    (co * ex + s * ey, -s * ex + co * ey)
}

/// E0370: placed with `reference` at `place` on the part, the field's
/// valid pixels cover `covered` of the lenslet's `aperture`.
fn misses(
    file: &str,
    (reference, place): (&str, (f64, f64)),
    covered: f64,
    lenslet_words: &str,
    aperture: &Domain,
    opts: &Options,
) -> Failure {
    fail(
        codes::FIELD_MISSES_LENSLET,
        format!(
            "{file}: placed with {reference} at x = {}, y = {} mm, the map's valid pixels cover {:.1} % of the aperture of {lenslet_words}, {}; at least {:.1} % is needed (--min-valid)",
            place.0,
            place.1,
            100.0 * covered,
            placed::aperture_words(aperture),
            100.0 * opts.min_valid
        ),
        Some(if opts.at.is_some() {
            "check --at: it is where the field's reference point lay on the part, in the job's x and y (mm)"
        } else {
            "the map is taken to be centred on the lenslet: give where it lay on the part with --at X,Y, or measure the lenslet again with the field on it"
        }),
    )
}

/// The area of an aperture (mm²).
fn area(d: &Domain) -> f64 {
    use std::f64::consts::PI;
    match *d {
        Domain::Circle { radius } => PI * radius * radius,
        Domain::Annulus { inner, outer } => PI * (outer * outer - inner * inner),
        Domain::Rect { x, y } => (x.1 - x.0) * (y.1 - y.0),
    }
}

/// Holds the map `m` (of the file `file`, whose bytes are `bytes`) to
/// lenslet `pick` of the array of the job `head`, whose design is `f`
/// over `domain`.
pub(super) fn measure(
    head: &JobHead,
    f: &dyn SurfaceFn,
    domain: &Domain,
    (file, bytes): (&str, &[u8]),
    m: Measurement,
    pick: LensletPick,
    opts: &Options,
) -> Result<Outcome, Failure> {
    let k = lenslet_of(head, pick)?;
    let lenslets: &Lenslets = head.surface.lenslets.as_ref().expect("lenslet_of checked");
    let surface_name = &head.names.surface;
    let Measured::Map(map) = m.data else {
        return Err(fail(
            codes::PER_LENSLET_UNAVAILABLE,
            format!(
                "{file}: --lenslet places a map of one lenslet's field on the lenslet, and this measurement is a point cloud or a profile"
            ),
            Some("measure the lenslet as a map (X3P, SDF, MetroPro), or leave out --lenslet"),
        ));
    };
    let c = lenslets.centre(k);
    let (row, column) = rows_and_columns(lenslets.centres())[k];
    let (place, placed_by) = match opts.at {
        Some(at) => (at, "--at"),
        None => (c, "the lenslet's centre"),
    };
    // A map point (x, y) lies at (x, y) + off from the lenslet's centre.
    let off = (place.0 - c.0, place.1 - c.1);
    let aperture = lenslets.aperture();
    let wide = lenslets.widened(MARGIN).map_or(aperture, |w| w.aperture());
    // The map's pixels on the lenslet with the map's reference point at
    // `off` from its centre, and the share of its aperture they cover.
    let select = |off: (f64, f64)| {
        let within = |x: f64, y: f64| {
            let (u, v) = (x + off.0, y + off.1);
            wide.contains(u, v) && domain.contains(u + c.0, v + c.1)
        };
        let p = placed::points(Measured::Map(map.clone()), opts, &within);
        let grid = p.map.as_ref().expect("a map's points keep their map");
        let mut under = 0usize;
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                if grid.valid[j * grid.nx + i]
                    && aperture.contains(grid.x(i) + off.0, grid.y(j) + off.1)
                {
                    under += 1;
                }
            }
        }
        let covered = (under as f64 * grid.dx * grid.dy / area(&aperture)).min(1.0);
        (p, covered)
    };
    let (mut p, mut covered) = select(off);
    let reference = if opts.keep_origin {
        "the file's origin (--keep-origin)"
    } else {
        "the map's middle pixel"
    };
    let lenslet_words = format!(
        "lenslet {k} (row {row}, column {column}; centre x = {}, y = {} mm)",
        c.0, c.1
    );
    if covered < opts.min_valid {
        return Err(misses(
            file,
            (reference, place),
            covered,
            &lenslet_words,
            &aperture,
            opts,
        ));
    }
    let g = FromCentre { f, centre: c };
    let target = format!("{lenslet_words} of `{surface_name}`");
    let shifted = |p: &placed::Points, off: (f64, f64)| -> Vec<[f64; 3]> {
        p.inside
            .iter()
            .map(|q| [q[0] + off.0, q[1] + off.1, q[2]])
            .collect()
    };
    // Rims that step onto the land: the fit stays clear of them.
    let rims = SteppedRims::of(f, lenslets);
    let pixel = map.dx.max(map.dy);
    let fit = |pts: &[[f64; 3]]| {
        register_clear(
            &|pts, fit| register::register_heights(&g, pts, fit),
            pts,
            Fit::default(),
            rims.as_ref().map(|r| (r, c)),
            pixel,
        )
        .map_err(|e| placed::not_registered(file, &target, e))
    };
    let mut local = shifted(&p, off);
    let (mut reg, mut band) = fit(&local)?;
    // Found more than a pixel from where it was placed: the pixels are
    // taken again where the registration puts the field, and registered
    // again from there (in the frame of the first placement: a shift s of
    // the points' origin is a decentre d − s and a piston p + t·s).
    let moved_to = where_found(&reg, off);
    let s_shift = (moved_to.0 - off.0, moved_to.1 - off.1);
    if s_shift.0.hypot(s_shift.1) > pixel {
        (p, covered) = select(moved_to);
        (reg, band) = fit(&shifted(&p, moved_to))?;
        let (tx, ty) = reg.tilt();
        reg.values[3] -= s_shift.0;
        reg.values[4] -= s_shift.1;
        reg.values[0] += tx * s_shift.0 + ty * s_shift.1;
        local = shifted(&p, off);
        if covered < opts.min_valid {
            let at = (c.0 + moved_to.0, c.1 + moved_to.1);
            return Err(misses(
                file,
                (reference, at),
                covered,
                &lenslet_words,
                &aperture,
                opts,
            ));
        }
    }
    // Where the field was found: how much of the lenslet it covers.
    let finding = (covered < WHOLE).then(|| report::Finding {
        code: codes::FIELD_PART_OF_LENSLET.to_owned(),
        message: format!(
            "{file}: the map's valid pixels cover {:.1} % of the aperture of {lenslet_words}: its figures describe that part of it only",
            100.0 * covered
        ),
    });
    let pred = register::predict(&g, &local, &reg.values);
    let errors: Vec<f64> = local
        .iter()
        .zip(&pred)
        .map(|(q, h)| (q[2] - h[0]) / (1.0 + h[1] * h[1] + h[2] * h[2]).sqrt())
        .collect();
    let form = placed::form_error(&p.inside, &errors);
    placed::departs(&pred, &form, file, &target)?;
    let found = where_found(&reg, off);
    let found = (c.0 + found.0, c.1 + found.1);
    let (texture, texture_skipped) = super::texture_of(&p, &errors, opts.cutoff);
    let raster = super::raster(&p.inside, &errors, Some(map.dx.max(map.dy)));
    let mut registration = placed::registration_report(&reg);
    registration.method = format!(
        "{}, on the map's pixels within the aperture of {lenslet_words} widened by a fifth, against the design seen from its centre, started with {reference} at x = {}, y = {} mm ({placed_by})",
        registration.method, place.0, place.1
    );
    if let (Some(r), Some(band)) = (&rims, band) {
        registration.method.push_str(&r.words(band));
    }
    let mut caption = super::caption(&form, &registration, &raster);
    caption.push_str(&format!(
        " The map is one lenslet's field: {lenslet_words}, its aperture {:.1} % covered; the registration puts {reference} at x = {:.4}, y = {:.4} mm on the part (placed at {}, {} by {placed_by}).",
        100.0 * covered,
        found.0,
        found.1,
        place.0,
        place.1
    ));
    let svg = crate::plots::measured_error_svg(
        &format!(
            "{}: measured error of lenslet {k} of `{surface_name}` ({file})",
            head.name
        ),
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
    let report = report::MeasureReport {
        job: head.name.clone(),
        surface: surface_name.clone(),
        measurement: report::Measurement {
            file: file.to_owned(),
            format: m.format.name().to_owned(),
            kind: "map".to_owned(),
            md5: lensc_measure::md5_hex(bytes),
            instrument: m.instrument,
            points: p.total,
            valid_points: p.valid,
            pixel_um: Some([map.dx * 1000.0, map.dy * 1000.0]),
            extent_mm: p.extent,
            centred: !opts.keep_origin,
        },
        coverage: report::Coverage {
            points_in_aperture: p.in_aperture,
            valid_share: p.inside.len() as f64 / p.in_aperture.max(1) as f64,
            min_valid_share: opts.min_valid,
        },
        registration,
        form_error: form,
        texture,
        texture_skipped,
        setup: None,
        lenslets: None,
        lenslet: Some(report::LensletField {
            index: k,
            row,
            column,
            centre_mm: [c.0, c.1],
            reference: reference.to_owned(),
            placed_at_mm: [place.0, place.1],
            placed_by: placed_by.to_owned(),
            found_at_mm: [found.0, found.1],
            aperture_covered: covered,
            min_covered: opts.min_valid,
            finding,
        }),
    };
    Ok(Outcome { report, svg })
}
