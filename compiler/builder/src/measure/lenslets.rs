//! `lensc measure --per-lenslet`: each lenslet of the job's array
//! registered on its own and figured on its own. A map point belongs to
//! the lenslet whose aperture, widened by a fifth, holds it where the
//! whole array's registration places it (the nearest such lenslet, as the
//! build's height map gives cells to lenslets: the margin of land about
//! a lenslet tells its decentre from a tilt); each lenslet's points are then
//! registered to the design seen from that lenslet's centre (piston,
//! tilt, decentre; clocking where its surface is not of revolution),
//! starting from where the whole array's registration puts it (clear of
//! rims that step onto the land: `steps`), and its
//! error along the normal, PV, RMS and texture are figured from its own
//! registration. A lenslet with too few valid points, or whose
//! registration does not settle, is a coded finding (W0036) in the report,
//! not an error: the other lenslets are still measured.

use lensc_lang::codes;
use lensc_measure::HeightMap;
use lensc_measure::register::{self, Options as Fit, Registration};
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::lenslets::Lenslets;

use super::placed::{Options, form_error};
use super::report;
use super::steps::{SteppedRims, register_clear};

/// The design `f` seen from a lenslet's centre: g(u, v) = f(u + cx, v + cy).
pub(super) struct FromCentre<'a> {
    pub(super) f: &'a dyn SurfaceFn,
    pub(super) centre: (f64, f64),
}

impl SurfaceFn for FromCentre<'_> {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        let xs: Vec<f64> = xs.iter().map(|x| x + self.centre.0).collect();
        let ys: Vec<f64> = ys.iter().map(|y| y + self.centre.1).collect();
        self.f.eval_batch(&xs, &ys, out)
    }
}

/// How far beyond its aperture a lenslet's points reach, as a factor of
/// the aperture about its centre.
pub(super) const MARGIN: f64 = 1.2;

/// A lenslet's map points: its points in the measurement's frame (valid
/// ones), their pixels, and how many of the map's pixels (valid or not)
/// fall in its aperture.
#[derive(Default)]
struct Share {
    points: Vec<[f64; 3]>,
    pixels: Vec<(usize, usize)>,
    in_aperture: usize,
}

/// Where the whole array's registration `whole` puts the design point
/// `c` in the measurement's frame: x = R(−γ) c + d.
fn placed(c: (f64, f64), whole: &Registration) -> (f64, f64) {
    let (d, gamma) = (whole.decentre(), whole.values[5]);
    let (s, co) = gamma.sin_cos();
    (co * c.0 - s * c.1 + d.0, s * c.0 + co * c.1 + d.1)
}

/// Each lenslet of `lenslets` that the map `m` reaches, registered to the
/// design `f` on its own, with the array's registration `whole`.
pub(super) fn measure(
    f: &dyn SurfaceFn,
    lenslets: &Lenslets,
    m: &HeightMap,
    whole: &Registration,
    rims: Option<&SteppedRims>,
    opts: &Options,
) -> report::Lenslets {
    // Each lenslet with a margin of the land about it (a fifth of its
    // aperture's reach, short of a neighbour's where they do not
    // overlap): a sphere's decentre is a tilt inside its aperture, and
    // only its rim against the land tells one from the other.
    let cells = lenslets.widened(MARGIN).unwrap_or_else(|| lenslets.clone());
    let mut shares: Vec<Share> = (0..lenslets.len()).map(|_| Share::default()).collect();
    for j in 0..m.ny {
        for i in 0..m.nx {
            let (x, y) = (m.x(i), m.y(j));
            let (u, v) = register::moved(&[[x, y, 0.0]], &whole.values);
            let Some(k) = cells.which(u[0], v[0]) else {
                continue;
            };
            let s = &mut shares[k];
            s.in_aperture += 1;
            let at = j * m.nx + i;
            if m.valid[at] {
                s.points.push([x, y, m.z[at]]);
                s.pixels.push((i, j));
            }
        }
    }
    let (tx, ty) = whole.tilt();
    let places = rows_and_columns(lenslets.centres());
    let mut each = Vec::new();
    for (k, s) in shares.into_iter().enumerate() {
        if s.in_aperture == 0 {
            continue;
        }
        let c = lenslets.centre(k);
        let share = s.points.len() as f64 / s.in_aperture as f64;
        let mut out = report::LensletMeasured {
            index: k,
            row: places[k].0,
            column: places[k].1,
            centre_mm: [c.0, c.1],
            points_in_aperture: s.in_aperture,
            valid_share: share,
            registration: None,
            form_error: None,
            texture: None,
            texture_skipped: None,
            finding: None,
        };
        let finding = |message: String| report::Finding {
            code: codes::LENSLET_NOT_REGISTERED.to_owned(),
            message,
        };
        if share < opts.min_valid {
            out.finding = Some(finding(format!(
                "lenslet {k} (centre x = {}, y = {} mm): {:.1} % of its {} measured points are valid; at least {:.1} % are needed to register it (--min-valid)",
                c.0,
                c.1,
                100.0 * share,
                s.in_aperture,
                100.0 * opts.min_valid
            )));
            each.push(out);
            continue;
        }
        // In the frame of where the whole array puts this lenslet.
        let at = placed(c, whole);
        let local: Vec<[f64; 3]> = s
            .points
            .iter()
            .map(|q| [q[0] - at.0, q[1] - at.1, q[2]])
            .collect();
        let g = FromCentre { f, centre: c };
        let (reg, _) = match register_clear(
            &|pts, fit| register::register_heights(&g, pts, fit),
            &local,
            Fit::default(),
            rims.map(|r| (r, c)),
            m.dx.max(m.dy),
        ) {
            Ok(r) => r,
            Err(e) => {
                let why = match e {
                    register::RegisterError::TooFewPoints { points } => {
                        format!("{points} valid points are too few to register it")
                    }
                    register::RegisterError::NotConverged { iterations, .. } => {
                        format!("its registration did not converge in {iterations} iterations")
                    }
                    register::RegisterError::Undefined { points } => format!(
                        "its registration moved {points} points where the design has no value"
                    ),
                };
                out.finding = Some(finding(format!(
                    "lenslet {k} (centre x = {}, y = {} mm): {why}",
                    c.0, c.1
                )));
                each.push(out);
                continue;
            }
        };
        let pred = register::predict(&g, &local, &reg.values);
        let errors: Vec<f64> = local
            .iter()
            .zip(&pred)
            .map(|(q, h)| (q[2] - h[0]) / (1.0 + h[1] * h[1] + h[2] * h[2]).sqrt())
            .collect();
        out.form_error = Some(form_error(&s.points, &errors));
        let (d, (ktx, kty)) = (reg.decentre(), reg.tilt());
        // The lenslet's centre found, in the measurement's frame.
        let found = (at.0 + d.0, at.1 + d.1);
        // The whole array's plane at the lenslet's centre: its piston there.
        let whole_piston = whole.piston() + tx * at.0 + ty * at.1;
        let um = |v: f64| v * 1000.0;
        out.registration = Some(report::LensletRegistration {
            piston_um: um(reg.piston()),
            tilt_x_urad: ktx * 1e6,
            tilt_y_urad: kty * 1e6,
            decentre_x_um: um(found.0 - c.0),
            decentre_y_um: um(found.1 - c.1),
            from_array: report::FromArray {
                piston_um: um(reg.piston() - whole_piston),
                tilt_x_urad: (ktx - tx) * 1e6,
                tilt_y_urad: (kty - ty) * 1e6,
                decentre_x_um: um(d.0),
                decentre_y_um: um(d.1),
            },
            iterations: reg.iterations,
        });
        let (texture, skipped) = texture(m, &s.pixels, &errors, opts.cutoff);
        out.texture = texture;
        out.texture_skipped = skipped;
        each.push(out);
    }
    let worst_pv = each
        .iter()
        .filter_map(|l| l.form_error.as_ref().map(|f| (l.index, f.pv_nm)))
        .fold(None, |w: Option<(usize, f64)>, (k, pv)| match w {
            Some((_, wp)) if wp >= pv => w,
            _ => Some((k, pv)),
        })
        .map(|(k, _)| k);
    let mut method: String = "each map point given to the nearest lenslet whose aperture, widened by a fifth (a margin of the land about it), holds it where the whole array's registration places it; each lenslet's points registered on their own to the design seen from its centre (least squares on the heights: piston, tilt, decentre, and clocking off a surface of revolution), starting where the whole array's registration puts it".into();
    if let Some(r) = rims {
        method.push_str(&format!(
            "; the pixels within three pixels ({:.1} µm) of the lenslets' rims, which step onto the land by up to {:.1} µm, left out of each fit (more while its placement still moved)",
            super::steps::BAND_PIXELS * m.dx.max(m.dy) * 1000.0,
            r.largest * 1000.0
        ));
    }
    report::Lenslets {
        method,
        in_array: lenslets.len(),
        reached: each.len(),
        not_registered: each.iter().filter(|l| l.finding.is_some()).count(),
        worst_pv,
        each,
    }
}

/// Each lenslet's row and column in its array, from 0: its row the rank
/// of its y among the array's distinct y (the row of least y is 0), its
/// column the rank of its x among the lenslets of its row. Centres whose
/// y differ by less than a nanometre share a row.
pub(super) fn rows_and_columns(centres: &[(f64, f64)]) -> Vec<(usize, usize)> {
    const SAME: f64 = 1e-6; // mm
    let mut ys: Vec<f64> = centres.iter().map(|c| c.1).collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup_by(|b, a| (*b - *a).abs() < SAME);
    let rows: Vec<usize> = centres
        .iter()
        .map(|c| ys.partition_point(|r| *r < c.1 - SAME))
        .collect();
    // In order of row, then x, then index: a row's columns count up.
    let mut order: Vec<usize> = (0..centres.len()).collect();
    order.sort_by(|&a, &b| {
        rows[a]
            .cmp(&rows[b])
            .then(centres[a].0.total_cmp(&centres[b].0))
            .then(a.cmp(&b))
    });
    let mut out = vec![(0, 0); centres.len()];
    let mut column = 0;
    for (n, &k) in order.iter().enumerate() {
        column = if n > 0 && rows[order[n - 1]] == rows[k] {
            column + 1
        } else {
            0
        };
        out[k] = (rows[k], column);
    }
    out
}

/// A lenslet's texture: its residual on the map's pixels over the box
/// its points span, through the same filter as the whole map's.
pub(super) fn texture(
    m: &HeightMap,
    pixels: &[(usize, usize)],
    errors: &[f64],
    cutoff: f64,
) -> (Option<report::Texture>, Option<String>) {
    let (mut i0, mut i1, mut j0, mut j1) = (usize::MAX, 0, usize::MAX, 0);
    for &(i, j) in pixels {
        (i0, i1, j0, j1) = (i0.min(i), i1.max(i), j0.min(j), j1.max(j));
    }
    if pixels.is_empty() {
        return (None, Some("no valid point".into()));
    }
    let (nx, ny) = (i1 - i0 + 1, j1 - j0 + 1);
    let (wx, wy) = (nx as f64 * m.dx, ny as f64 * m.dy);
    if wx.min(wy) < 2.0 * cutoff {
        return (
            None,
            Some(format!(
                "the lenslet's points span {wx:.3} × {wy:.3} mm, less than twice the cutoff λc = {cutoff} mm across (--cutoff)"
            )),
        );
    }
    let mut res = HeightMap {
        nx,
        ny,
        dx: m.dx,
        dy: m.dy,
        x0: m.x(i0),
        y0: m.y(j0),
        z: vec![0.0; nx * ny],
        valid: vec![false; nx * ny],
    };
    for (&(i, j), &e) in pixels.iter().zip(errors) {
        let at = (j - j0) * nx + (i - i0);
        res.z[at] = e;
        res.valid[at] = true;
    }
    match lensc_measure::texture::texture(&res, cutoff) {
        Some(t) => (Some(super::texture_report(&t, cutoff)), None),
        None => (None, Some("fewer than two valid points".into())),
    }
}
