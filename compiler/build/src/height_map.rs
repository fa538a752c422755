//! The height-map simulation of a surface job, as the job builders use it:
//! the window the job's `simulate` block asks for (or a default one where
//! the surface is representative), the grid over it in the coordinates of
//! the cut (Cartesian for a raster, polar for a lathe, angle and axial
//! position for a roller), the frames that tie those coordinates to the
//! design, and the report's `simulation.height_map` section.

use lensc_grammar::Diagnostic;
use lensc_runtime::moves::{Move, Plane};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::{ErrorFigures, Frame, Grid, HeightMap, Scallops, Sweep};
use serde_json::{Value, json};
use std::f64::consts::TAU;

use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::job::JobHead;

/// The most cells a window may have (8 bytes each in the map, plus the
/// passes gathered per column).
pub const MAX_CELLS: usize = 4_000_000;
/// The default window: this wide (mm) and this fine (mm).
pub const DEFAULT_SIZE: f64 = 0.2;
pub const DEFAULT_SPACING: f64 = 1e-3;

/// The part of the surface (x, y in the design's coordinates, mm) that is
/// simulated, and the grid spacing (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub spacing: f64,
    /// Set by the job's `simulate` block, not by default.
    pub given: bool,
}

impl Window {
    /// The job's window (lowering checked it is not empty), or the
    /// default one about `centre`.
    pub fn of(head: &JobHead, centre: (f64, f64)) -> Window {
        match head.simulate {
            Some(s) => Window {
                x: s.x,
                y: s.y,
                spacing: s.spacing.unwrap_or(DEFAULT_SPACING),
                given: true,
            },
            None => {
                let h = DEFAULT_SIZE / 2.0;
                Window {
                    x: (centre.0 - h, centre.0 + h),
                    y: (centre.1 - h, centre.1 + h),
                    spacing: DEFAULT_SPACING,
                    given: false,
                }
            }
        }
    }

    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x.0 && x <= self.x.1 && y >= self.y.0 && y <= self.y.1
    }

    /// E0149 when `grid` has more cells than the simulation takes.
    pub fn check_size(&self, head: &JobHead, grid: &Grid) -> Result<(), Diagnostic> {
        let cells = grid.ns * grid.nu;
        if cells <= MAX_CELLS {
            return Ok(());
        }
        let (file, span) = head.simulate.map_or(head.site, |s| s.site);
        Err(Diagnostic::error(
            codes::SIMULATION_TOO_LARGE,
            format!(
                "the simulation grid would have {cells} cells ({} × {}), more than the {MAX_CELLS} it takes",
                grid.ns, grid.nu
            ),
            file,
            span,
        )
        .with_label("this window")
        .with_help("make the window smaller or its spacing coarser"))
    }

    /// Columns along x (`along_x`) or y, rows across.
    pub fn cartesian(&self, along_x: bool) -> Grid {
        let count = |r: (f64, f64)| ((r.1 - r.0) / self.spacing + 1e-9).floor() as usize + 1;
        let (s, u) = if along_x {
            (self.x, self.y)
        } else {
            (self.y, self.x)
        };
        Grid {
            s0: s.0,
            ds: self.spacing,
            ns: count(s),
            u0: u.0,
            du: self.spacing,
            nu: count(u),
            period: None,
        }
    }

    /// Columns at spindle angles, rows at radii, covering the window; the
    /// whole turn when it holds the axis.
    pub fn polar(&self) -> Grid {
        let corners = [
            (self.x.0, self.y.0),
            (self.x.1, self.y.0),
            (self.x.1, self.y.1),
            (self.x.0, self.y.1),
        ];
        let r_max = corners.iter().map(|c| c.0.hypot(c.1)).fold(0.0, f64::max);
        let near = (
            0.0f64.clamp(self.x.0, self.x.1),
            0.0f64.clamp(self.y.0, self.y.1),
        );
        let r_min = near.0.hypot(near.1);
        let nu = ((r_max - r_min) / self.spacing).floor() as usize + 1;
        if r_min < self.spacing {
            let ns = (TAU * r_max / self.spacing).ceil().max(8.0) as usize;
            return Grid {
                s0: 0.0,
                ds: TAU / ns as f64,
                ns,
                u0: 0.0,
                du: self.spacing,
                nu: (r_max / self.spacing).floor() as usize + 1,
                period: Some(TAU),
            };
        }
        let mid = ((self.y.0 + self.y.1) / 2.0).atan2((self.x.0 + self.x.1) / 2.0);
        let relative = |c: &(f64, f64)| {
            let a = c.1.atan2(c.0) - mid;
            a - TAU * (a / TAU).round()
        };
        let lo = corners.iter().map(relative).fold(f64::INFINITY, f64::min);
        let hi = corners
            .iter()
            .map(relative)
            .fold(f64::NEG_INFINITY, f64::max);
        let ds = self.spacing / r_max;
        Grid {
            s0: mid + lo,
            ds,
            ns: ((hi - lo) / ds).ceil() as usize + 1,
            u0: r_min,
            du: self.spacing,
            nu,
            period: Some(TAU),
        }
    }

    /// Columns at spindle angles (design y over the roller radius), rows
    /// along the roller axis (design x).
    pub fn roller(&self, roller_radius: f64) -> Grid {
        let ds = self.spacing / roller_radius;
        let span = ((self.y.1 - self.y.0) / roller_radius).min(TAU - ds);
        Grid {
            s0: self.y.0 / roller_radius,
            ds,
            ns: (span / ds + 1e-9).floor() as usize + 1,
            u0: self.x.0,
            du: self.spacing,
            nu: ((self.x.1 - self.x.0) / self.spacing + 1e-9).floor() as usize + 1,
            period: Some(TAU),
        }
    }
}

/// The design's heights z at (x, y) points.
fn heights(kernel: &dyn SurfaceFn, xy: impl Iterator<Item = (f64, f64)>, out: &mut [f64]) {
    let (xs, ys): (Vec<f64>, Vec<f64>) = xy.unzip();
    let mut all = vec![0.0; 6 * xs.len()];
    kernel.eval_batch(&xs, &ys, &mut all);
    for (o, v) in out.iter_mut().zip(all.chunks_exact(6)) {
        *o = v[0];
    }
}

/// A raster on a mill: s along the cut (x or y), u across, h = z.
pub struct RasterFrame<'a> {
    pub kernel: &'a (dyn SurfaceFn + Sync),
    pub along_x: bool,
    pub window: Window,
    pub domain: Domain,
}

impl Frame for RasterFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        if self.along_x { (s, u) } else { (u, s) }
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.window.contains(x, y) && self.domain.contains(x, y)
    }
}

/// A spiral on a lathe: s the spindle angle, u the radius, h the height
/// of the nose centre (the fast axis or Z).
pub struct LatheFrame<'a> {
    pub kernel: &'a (dyn SurfaceFn + Sync),
    pub window: Window,
    pub domain: Domain,
    /// The lenslets (centre x, y, radius) that reach into the window.
    pub features: Vec<(f64, f64, f64)>,
}

impl<'a> LatheFrame<'a> {
    pub fn new(
        kernel: &'a (dyn SurfaceFn + Sync),
        window: Window,
        domain: Domain,
        features: &[(f64, f64, f64)],
    ) -> LatheFrame<'a> {
        let reaches = |&&(cx, cy, r): &&(f64, f64, f64)| {
            cx + r >= window.x.0
                && cx - r <= window.x.1
                && cy + r >= window.y.0
                && cy - r <= window.y.1
        };
        LatheFrame {
            kernel,
            window,
            domain,
            features: features.iter().filter(reaches).copied().collect(),
        }
    }
}

impl Frame for LatheFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        (u * s.cos(), u * s.sin())
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.window.contains(x, y) && self.domain.contains(x, y)
    }
    fn features(&self) -> &[(f64, f64, f64)] {
        &self.features
    }
}

/// A helix on a roller: s the spindle angle, u the axial position (design
/// x), h the nose centre's distance from the roller axis.
pub struct RollerFrame<'a> {
    pub kernel: &'a (dyn SurfaceFn + Sync),
    pub window: Window,
    pub roller_radius: f64,
    pub domain: Domain,
}

impl Frame for RollerFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
        for o in out.iter_mut() {
            *o += self.roller_radius;
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        (u, self.roller_radius * s.rem_euclid(TAU))
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.window.contains(x, y) && self.domain.contains(x, y)
    }
}

/// Feeds a mill's (optimised) move stream to `sweep`, as printed: rapids
/// lift the tool; straight moves and arcs in the plane of the cut are
/// followed.
pub fn sweep_mill_moves(sweep: &mut Sweep, moves: &[Move], along_x: bool, resolution: f64) {
    let printed = |v: f64| lensc_runtime::verify::simulate::as_printed(v, resolution);
    let mut at = [f64::NAN; 3];
    let to_here = |to: &lensc_runtime::moves::Position, at: &mut [f64; 3]| {
        for (a, v) in at.iter_mut().zip([to.x, to.y, to.z]) {
            if !v.is_nan() {
                *a = printed(v);
            }
        }
    };
    let su = |p: &[f64; 3]| if along_x { (p[0], p[1]) } else { (p[1], p[0]) };
    for m in moves {
        match m {
            Move::Rapid(to) => {
                to_here(to, &mut at);
                sweep.lift();
            }
            Move::Linear { to, .. } => {
                to_here(to, &mut at);
                if at.iter().all(|v| !v.is_nan()) {
                    let (s, u) = su(&at);
                    sweep.point(s, u, at[2]);
                }
            }
            Move::Arc {
                to, centre, plane, ..
            } => {
                to_here(to, &mut at);
                let (s, u) = su(&at);
                let in_plane = matches!((plane, along_x), (Plane::Zx, true) | (Plane::Yz, false));
                if in_plane {
                    let cs = if along_x { centre.x } else { centre.y };
                    sweep.arc(s, u, at[2], (printed(cs), printed(centre.z)));
                } else {
                    sweep.point(s, u, at[2]);
                }
            }
            _ => {}
        }
    }
}

/// The default window's centre on a lathe: the outermost lenslet's
/// centre, or half way out along x.
pub fn lathe_centre(domain: &Domain, features: &[(f64, f64, f64)]) -> (f64, f64) {
    features
        .iter()
        .max_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)))
        .map(|f| (f.0, f.1))
        .unwrap_or_else(|| domain_centre(domain))
}

/// The default window's centre on a surface's domain: half way out along
/// x for a disc or ring, the middle of a rectangle.
pub fn domain_centre(domain: &Domain) -> (f64, f64) {
    match *domain {
        Domain::Circle { radius } => (radius / 2.0, 0.0),
        Domain::Annulus { inner, outer } => ((inner + outer) / 2.0, 0.0),
        Domain::Rect { x, y } => ((x.0 + x.1) / 2.0, (y.0 + y.1) / 2.0),
    }
}

/// PV, RMS and extremes of a set of errors as the report gives them (nm).
pub fn figures_json(f: &Option<ErrorFigures>) -> Value {
    match f {
        None => Value::Null,
        Some(f) => json!({
            "cells": f.count,
            "pv_nm": f.pv * 1e6,
            "rms_nm": f.rms * 1e6,
            "max_residual_nm": { "value": f.max_residual.0 * 1e6, "x_mm": f.max_residual.1.0, "y_mm": f.max_residual.1.1 },
            "max_gouge_nm": { "value": f.max_gouge.0 * 1e6, "x_mm": f.max_gouge.1.0, "y_mm": f.max_gouge.1.1 },
        }),
    }
}

fn scallops_json(s: &Option<Scallops>) -> Value {
    match s {
        None => Value::Null,
        Some(s) => json!({ "count": s.count, "max_nm": s.max * 1e6, "mean_nm": s.mean * 1e6 }),
    }
}

/// The report's `simulation.height_map`: the window, the grid, the form
/// error over the cut surface and at the passes' contacts, the scallops
/// beside the flat-surface figure for `stepover`, the roughness along and
/// across the cut, and the same per lenslet.
pub fn json(map: &HeightMap, window: &Window, coordinates: &str, stepover: f64) -> Value {
    let g = &map.grid;
    json!({
        "kind": "height map of the nose swept along the program's moves, as printed, against the design",
        "window": {
            "x_mm": [window.x.0, window.x.1],
            "y_mm": [window.y.0, window.y.1],
            "spacing_mm": window.spacing,
            "given": window.given,
        },
        "grid": {
            "coordinates": coordinates,
            "columns": g.ns,
            "rows": g.nu,
            "column_step": g.ds,
            "row_step_mm": g.du,
        },
        "uncut_cells": map.uncut,
        "surface": figures_json(&map.surface),
        "contact": figures_json(&map.contact),
        "scallops": {
            "stepover_mm": stepover,
            "flat_theory_nm": HeightMap::flat_scallop(map.nose_radius, stepover) * 1e6,
            "simulated": scallops_json(&map.scallops),
        },
        "rq_cutting_direction_nm": finite(map.rq_cutting * 1e6),
        "rq_stepover_direction_nm": finite(map.rq_stepover * 1e6),
        "lenslets": map.features.iter().map(|f| json!({
            "centre_mm": [f.centre.0, f.centre.1],
            "surface": figures_json(&f.surface),
            "contact": figures_json(&f.contact),
            "scallops": scallops_json(&f.scallops),
        })).collect::<Vec<_>>(),
    })
}

fn finite(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

/// A height map as the series of its plot: the error on a raster of at
/// most `plots::RASTER_SIDE` blocks a side over the window, blocks no
/// finer than `min_block` (mm).
pub fn form_error_series(
    map: &HeightMap,
    frame: &dyn Frame,
    window: &Window,
    min_block: f64,
    axes: (&'static str, &'static str),
) -> crate::plots::FormErrorSeries {
    crate::plots::FormErrorSeries {
        raster: map.raster(
            frame,
            window.x,
            window.y,
            min_block,
            crate::plots::RASTER_SIDE,
        ),
        window: (window.x, window.y),
        spacing: window.spacing,
        x_axis: axes.0,
        y_axis: axes.1,
    }
}

/// One line for the build summary.
pub fn summary(map: &HeightMap) -> Option<String> {
    let c = map.contact.as_ref()?;
    let s = map.surface.as_ref()?;
    Some(format!(
        "height map: form error at the contacts {} nm RMS, {} nm PV; surface with scallops {} nm PV",
        trim_num((c.rms * 1e7).round() / 10.0),
        trim_num((c.pv * 1e7).round() / 10.0),
        trim_num((s.pv * 1e7).round() / 10.0)
    ))
}
