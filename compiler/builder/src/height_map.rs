//! The height-map simulation of a surface job, as the job builders use it:
//! the window the job's `simulate` block asks for (the whole part's extent
//! where it leaves a range out, or a default window where the surface is
//! representative; the window, its grids in the coordinates of the cut
//! and their tiles are the runtime's `verify::window`), the path kept as
//! it is planned and simulated tile by tile (`verify::tiles`), the frames
//! that tie those coordinates to the design (the report's
//! `simulation.height_map` section is `crate::report::HeightMap`).

use lensc_runtime::moves::{Move, Plane};
use lensc_runtime::reader::{Executed, Path as ExecutedPath};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::heightmap::{
    Cutter, ErrorRaster, Frame, Grid, HeightMap, NosePath, RasterLayout,
};
use lensc_runtime::verify::lenslets::Lenslets;
use lensc_runtime::verify::tiles::{Recorder, simulate};
use lensc_runtime::verify::window::Tile;
use std::f64::consts::TAU;

use crate::job::JobHead;
use lensc_lang::check::trim_num;

pub use crate::job::window::{domain_extent, roller_extent};
pub use lensc_runtime::verify::window::Window;

/// The window a job simulates: the one its `simulate` block gives, a
/// range it leaves out being the part's `extent` (its tiles' size was
/// checked by lowering), or by default the whole `extent` of what the job
/// cuts, at the finest spacing whose `tiles` hold at most `budget` cells
/// (`Window::whole`).
pub fn window(
    head: &JobHead,
    extent: ((f64, f64), (f64, f64)),
    budget: usize,
    tiles: impl Fn(&Window) -> Vec<Tile>,
) -> Window {
    crate::job::window::simulated(head, extent)
        .unwrap_or_else(|| Window::whole(extent, budget, tiles))
}

/// The cells a whole part is simulated in by default with a round nose
/// whose edge lies across the cut (a knife, a lathe's or roller lathe's
/// diamond): each column's envelope is exact whatever the rows, and a
/// cell costs about 0.1 µs, so about half a second on one core.
pub const WHOLE_CELLS_NOSE: usize = 4_000_000;

/// The cells a whole part is simulated in by default with a ball-end
/// mill, whose every cell is cut by every piece of the path within its
/// radius: a sixteenth of a knife's (the bench's 4 mm cubic phase plate
/// at 10 µm; at 5 µm, a million cells, it took 14.7 s of CPU).
pub const WHOLE_CELLS_BALL: usize = 250_000;

/// A height-map simulation under way: the path kept as it is planned
/// (only what reaches the tiles), then swept tile by tile.
pub struct Simulation {
    /// The window's whole grid (the report's), and its tiles.
    pub grid: Grid,
    pub tiles: Vec<Tile>,
    cutter: Cutter,
    recorder: Recorder,
}

impl Simulation {
    /// A simulation of a round nose of `nose_radius` whose edge lies
    /// across the cut (a knife, a lathe's diamond).
    pub fn new(grid: Grid, tiles: Vec<Tile>, nose_radius: f64) -> Simulation {
        Simulation::of(grid, tiles, Cutter::nose(nose_radius))
    }

    /// A simulation of `cutter`.
    pub fn of(grid: Grid, tiles: Vec<Tile>, cutter: Cutter) -> Simulation {
        Simulation {
            grid,
            recorder: Recorder::new(Recorder::band_of(&tiles, cutter.reach())),
            tiles,
            cutter,
        }
    }

    /// Where the planned path goes.
    pub fn path(&mut self) -> &mut Recorder {
        &mut self.recorder
    }

    /// The map of every tile against `frame`'s design, and its error on a
    /// raster of at most `plots::RASTER_SIDE` blocks a side over `window`,
    /// blocks no finer than `min_block` (mm).
    pub fn finish(
        self,
        frame: &dyn Frame,
        window: &Window,
        min_block: f64,
    ) -> (HeightMap, ErrorRaster) {
        let layout = RasterLayout::new(window.x, window.y, min_block, crate::plots::RASTER_SIDE);
        let t = simulate(
            &self.recorder,
            &self.tiles,
            self.grid,
            self.cutter,
            frame,
            layout,
        );
        (t.map, t.raster)
    }
}

/// The design's heights z at (x, y) points (a few at a time on the
/// stack: the simulation asks for one to six points per contact).
fn heights(kernel: &dyn SurfaceFn, xy: impl Iterator<Item = (f64, f64)>, out: &mut [f64]) {
    const FEW: usize = 8;
    if out.len() <= FEW {
        let (mut xs, mut ys, mut all) = ([0.0; FEW], [0.0; FEW], [0.0; 6 * FEW]);
        let n = out.len();
        for (k, (x, y)) in xy.take(n).enumerate() {
            (xs[k], ys[k]) = (x, y);
        }
        kernel.eval_batch(&xs[..n], &ys[..n], &mut all[..6 * n]);
        for (o, v) in out.iter_mut().zip(all.chunks_exact(6)) {
            *o = v[0];
        }
        return;
    }
    let (xs, ys): (Vec<f64>, Vec<f64>) = xy.unzip();
    let mut all = vec![0.0; 6 * xs.len()];
    kernel.eval_batch(&xs, &ys, &mut all);
    for (o, v) in out.iter_mut().zip(all.chunks_exact(6)) {
        *o = v[0];
    }
}

/// The design heights a frame compares the cut with: the design's height
/// alone (a kernel of `SurfaceTape::height_only`) and, for a compensated
/// job, the correction it cuts less (the surface aimed at is the design
/// less `gain` times the correction: `compensate::corrected_tape`). The
/// correction is not in the kernel: the simulation asks ten million
/// heights of a 10 mm part, and a correction of 66 terms cost about as
/// much a point as the off-axis design's height (`benches/compensate.rs`);
/// along one column every frame's (x, y) is a line in u, where the
/// correction is a polynomial of u of a few terms (`Correction::along`).
pub struct DesignHeights {
    pub kernel: Box<dyn SurfaceFn + Sync>,
    pub correction: Option<crate::compensate::Applied>,
}

impl DesignHeights {
    /// The heights of the surface a job aims at.
    pub fn of(surface: &crate::job::SurfaceSpec) -> DesignHeights {
        match (&surface.design, &surface.correction) {
            (Some(design), Some(c)) => DesignHeights {
                kernel: crate::evaluate::evaluator(&design.tape.height_only()).0,
                correction: Some(c.clone()),
            },
            _ => DesignHeights {
                kernel: crate::evaluate::evaluator(&surface.lowered.tape.height_only()).0,
                correction: None,
            },
        }
    }
}

thread_local! {
    /// The correction along the line a frame's column lies on, for the
    /// column last asked (its cells are asked a few at a time): the
    /// correction's `id`, the line's origin and direction (bits) and the
    /// polynomial along it.
    static ALONG: std::cell::RefCell<Option<(u64, [u64; 4], lensc_measure::correct::Along)>> =
        const { std::cell::RefCell::new(None) };
}

/// Takes `gain` times the correction out of the design heights `out` at
/// the frame's (s, u) `points`: along each column's line, origin + u ·
/// direction (every frame's (x, y) is affine in u at a given s).
fn less_correction(
    frame: &dyn Frame,
    c: &crate::compensate::Applied,
    points: &[(f64, f64)],
    out: &mut [f64],
) {
    ALONG.with(|cell| {
        let mut last = cell.borrow_mut();
        let mut s_last = f64::NAN;
        for (&(s, u), o) in points.iter().zip(out.iter_mut()) {
            if s.to_bits() != s_last.to_bits() {
                s_last = s;
                let origin = frame.xy(s, 0.0);
                let end = frame.xy(s, 1.0);
                let direction = (end.0 - origin.0, end.1 - origin.1);
                let key = [origin.0, origin.1, direction.0, direction.1].map(f64::to_bits);
                if !last.as_ref().is_some_and(|l| l.0 == c.id && l.1 == key) {
                    *last = Some((c.id, key, c.fitted.along(origin, direction)));
                }
            }
            let along = &last.as_ref().expect("set for this column").2;
            *o -= c.gain * along.at(u);
        }
    })
}

/// A raster on a mill: s along the cut (x or y), u across, h = z.
pub struct RasterFrame<'a> {
    /// The design; only its height is read (a kernel of
    /// `SurfaceTape::height_only` does no other work).
    pub kernel: &'a (dyn SurfaceFn + Sync),
    /// A compensated job's correction, taken out of the kernel's heights
    /// (`DesignHeights`).
    pub correction: Option<&'a crate::compensate::Applied>,
    pub along_x: bool,
    pub window: Window,
    pub domain: Domain,
    /// An array's lenslets, each reported on its own.
    pub lenslets: Option<&'a Lenslets>,
}

impl Frame for RasterFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
        if let Some(c) = self.correction {
            less_correction(self, c, points, out);
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        if self.along_x { (s, u) } else { (u, s) }
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.window.contains(x, y) && self.domain.contains(x, y)
    }
    fn lenslets(&self) -> Option<&Lenslets> {
        self.lenslets
    }
}

thread_local! {
    /// The last spindle angle turned to and its cosine and sine: a
    /// column's cells share their angle.
    static TURNED: std::cell::Cell<(f64, f64, f64)> = const { std::cell::Cell::new((f64::NAN, 1.0, 0.0)) };
}

/// cos s and sin s, from the last angle asked for when it is the same.
fn turned(s: f64) -> (f64, f64) {
    TURNED.with(|last| {
        let (a, cos, sin) = last.get();
        if a == s {
            return (cos, sin);
        }
        let (cos, sin) = (s.cos(), s.sin());
        last.set((s, cos, sin));
        (cos, sin)
    })
}

/// A spiral on a lathe: s the spindle angle, u the radius, h the height
/// of the nose centre (the fast axis or Z).
pub struct LatheFrame<'a> {
    /// The design; only its height is read (a kernel of
    /// `SurfaceTape::height_only` does no other work).
    pub kernel: &'a (dyn SurfaceFn + Sync),
    /// A compensated job's correction, taken out of the kernel's heights
    /// (`DesignHeights`).
    pub correction: Option<&'a crate::compensate::Applied>,
    pub window: Window,
    pub domain: Domain,
    /// The radius the spiral starts at (mm): the job cuts nothing beyond.
    pub reach: f64,
    /// The array's lenslets (centre x, y, radius), in the array's order
    /// (their indices are the lenslets' in the report).
    pub features: Vec<(f64, f64, f64)>,
    /// An array's lenslets, each reported on its own, where they are not
    /// discs (`features`): rectangular lenslets, rings.
    pub lenslets: Option<&'a Lenslets>,
}

impl<'a> LatheFrame<'a> {
    pub fn new(
        heights: &'a DesignHeights,
        window: Window,
        domain: Domain,
        reach: f64,
        features: &[(f64, f64, f64)],
        lenslets: Option<&'a Lenslets>,
    ) -> LatheFrame<'a> {
        LatheFrame {
            kernel: heights.kernel.as_ref(),
            correction: heights.correction.as_ref(),
            window,
            domain,
            reach,
            features: features.to_vec(),
            lenslets,
        }
    }
}

impl Frame for LatheFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
        if let Some(c) = self.correction {
            less_correction(self, c, points, out);
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        let (cos, sin) = turned(s);
        (u * cos, u * sin)
    }
    /// The polar cell's parallelogram: its radial step times its
    /// angular step's chord across, u · du · sin(ds).
    fn cell_area(&self, g: &Grid, _: f64, u: f64) -> f64 {
        (u * g.du * g.ds.sin()).abs()
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        // `hypot`, not squares: a polar grid's row lies on the reach's
        // circle, and squares would drop some of its cells.
        self.window.contains(x, y) && self.domain.contains(x, y) && x.hypot(y) <= self.reach
    }
    /// The column at angle s is the line (u cos s, u sin s): within the
    /// reach where |u| is, and within a disc where its chord of it is,
    /// each found with the reach and the discs' radii a millionth of a
    /// nanometre per millimetre wider than they are (`xy` and the tests
    /// of `inside` and `in_disc` round within 1e-14 mm of the part's 35
    /// mm), so no point they hold is left out.
    fn column_reach(&self, s: f64, discs: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
        let widen = |r: f64| r * (1.0 + 1e-9) + 1e-12;
        let reach = widen(self.reach);
        if discs.is_empty() {
            return Some((-reach, reach));
        }
        let (cos, sin) = turned(s);
        let (lo, hi) = discs.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), &(cx, cy, r)| {
                // Along the line to the disc's centre's foot, and across.
                let (along, across) = (cx * cos + cy * sin, cx * sin - cy * cos);
                let r = widen(r);
                if across.abs() > r {
                    return (lo, hi);
                }
                let half = (r * r - across * across).sqrt();
                (lo.min(along - half), hi.max(along + half))
            },
        );
        Some((lo.max(-reach), hi.min(reach)))
    }
    fn features(&self) -> &[(f64, f64, f64)] {
        &self.features
    }
    fn lenslets(&self) -> Option<&Lenslets> {
        self.lenslets
    }
}

/// A helix on a roller: s the spindle angle, u the axial position (design
/// x), h the nose centre's distance from the roller axis.
pub struct RollerFrame<'a> {
    /// The design; only its height is read (a kernel of
    /// `SurfaceTape::height_only` does no other work).
    pub kernel: &'a (dyn SurfaceFn + Sync),
    /// A compensated job's correction, taken out of the kernel's heights
    /// (`DesignHeights`).
    pub correction: Option<&'a crate::compensate::Applied>,
    pub window: Window,
    pub roller_radius: f64,
    /// Design y under spindle angle 0 (`RollerHelix::y_start`).
    pub y_start: f64,
    pub domain: Domain,
    /// A wrapped array's lenslets (design x, y), each reported on its own.
    pub lenslets: Option<&'a Lenslets>,
}

impl Frame for RollerFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        heights(self.kernel, points.iter().map(|&(s, u)| self.xy(s, u)), out);
        if let Some(c) = self.correction {
            less_correction(self, c, points, out);
        }
        for o in out.iter_mut() {
            *o += self.roller_radius;
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        (u, self.y_start + self.roller_radius * s.rem_euclid(TAU))
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.window.contains(x, y) && self.domain.contains(x, y)
    }
    fn lenslets(&self) -> Option<&Lenslets> {
        self.lenslets
    }
}

/// Feeds a mill's (optimised) move stream to `sweep`, as printed: rapids
/// lift the tool; straight moves and arcs in the plane of the cut are
/// followed.
pub fn sweep_mill_moves(sweep: &mut dyn NosePath, moves: &[Move], along_x: bool, resolution: f64) {
    let printed = lensc_runtime::verify::simulate::Printed::new(resolution);
    let printed = |v: f64| printed.round(v);
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

/// The largest change of radius (mm) over one circular piece of a
/// blended arc: a circle at the piece's mean radius strays at most half of
/// it, a tenth of a nanometre, from the controller's blend.
const ARC_BLEND_STEP: f64 = 2e-7;

/// Feeds a mill program's moves, read from its text as the controller
/// reads it (`reader::read_moves`), to `sweep`: rapids lift the tool;
/// straight moves are followed; an arc in the plane of the cut is cut as
/// the controller cuts it, its radius blended from the start's to the
/// end's over its turn (see `verify::simulate`), in circular pieces over
/// which the radius changes by at most `ARC_BLEND_STEP` (each at most a
/// quarter turn); an arc in another plane by its chord.
pub fn sweep_mill_program(sweep: &mut dyn NosePath, moves: &[Executed], along_x: bool) {
    let su = |p: [f64; 3]| if along_x { (p[0], p[1]) } else { (p[1], p[0]) };
    let xyz = |v: &[Option<f64>; 4]| Some([v[0]?, v[1]?, v[2]?]);
    let mut cutting = false;
    for m in moves {
        let (Some(from), Some(to)) = (xyz(&m.from), xyz(&m.to)) else {
            sweep.lift();
            cutting = false;
            continue;
        };
        if m.path == ExecutedPath::Rapid {
            sweep.lift();
            cutting = false;
            continue;
        }
        if !cutting {
            let (s, u) = su(from);
            sweep.point(s, u, from[2]);
            cutting = true;
        }
        if let ExecutedPath::Arc {
            plane,
            centre,
            cw,
            turn,
        } = m.path
            && matches!((plane, along_x), (Plane::Zx, true) | (Plane::Yz, false))
        {
            // The plane's two coordinates in its order: (Z, X) or (Y, Z).
            let in_plane = |p: [f64; 3]| match plane {
                Plane::Zx => (p[2], p[0]),
                _ => (p[1], p[2]),
            };
            let back = |(a, b): (f64, f64)| match plane {
                Plane::Zx => [b, from[1], a],
                _ => [from[0], a, b],
            };
            let (a, b) = (in_plane(from), in_plane(to));
            let r0 = (a.0 - centre.0).hypot(a.1 - centre.1);
            let r1 = (b.0 - centre.0).hypot(b.1 - centre.1);
            let start = (a.1 - centre.1).atan2(a.0 - centre.0);
            let sweep_angle = if cw { -turn } else { turn };
            let n = ((r1 - r0).abs() / ARC_BLEND_STEP)
                .max(sweep_angle.abs() / std::f64::consts::FRAC_PI_2)
                .ceil()
                .clamp(1.0, 1e6) as usize;
            // The centre in the sweep's (s, h): (X, Z) or (Y, Z).
            let (cs, ch) = match plane {
                Plane::Zx => (centre.1, centre.0),
                _ => centre,
            };
            for k in 1..=n {
                let p = if k == n {
                    to
                } else {
                    let f = k as f64 / n as f64;
                    let (theta, r) = (start + f * sweep_angle, r0 + f * (r1 - r0));
                    back((centre.0 + r * theta.cos(), centre.1 + r * theta.sin()))
                };
                let (s, u) = su(p);
                sweep.arc(s, u, p[2], (cs, ch));
            }
            continue;
        }
        let (s, u) = su(to);
        sweep.point(s, u, to[2]);
    }
}

/// A height map's error on its raster (see [`Simulation::finish`]) as
/// the series of its plot.
pub fn form_error_series(
    raster: ErrorRaster,
    window: &Window,
    axes: (&'static str, &'static str),
) -> crate::plots::FormErrorSeries {
    crate::plots::FormErrorSeries {
        raster,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::{Applied, corrected_tape};
    use lensc_measure::correct::{Basis, Correction};
    use lensc_runtime::surface::ir::{Graph, SurfaceTape};

    /// A design (a paraboloid with a tilt) and a correction of order 10
    /// across its 10 mm map, every term non-zero.
    fn design_and_correction(basis: Basis) -> (SurfaceTape, Applied) {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let r2 = {
            let x2 = g.mul(x, x);
            let y2 = g.mul(y, y);
            g.add(x2, y2)
        };
        let k = g.constant_node(0.01);
        let sag = g.mul(k, r2);
        let t = g.constant_node(0.003);
        let tilt = g.mul(t, x);
        let z = g.add(sag, tilt);
        let design = SurfaceTape::new(g, z);
        let n = basis.terms().len();
        let fitted = Correction {
            basis,
            coefficients: (0..n)
                .map(|k| 2e-5 * (1.0 + k as f64).recip() * if k % 3 == 0 { -1.0 } else { 1.0 })
                .collect(),
            fit_residual_rms: 0.0,
            cells: 0,
        };
        let applied = Applied {
            fitted,
            gain: 0.8,
            // Each correction its own (the per-thread line is known by it).
            id: basis.terms().len() as u64,
        };
        (design, applied)
    }

    /// Every frame's heights of a compensated job, the design's kernel
    /// less the correction along each column, are the corrected tape's
    /// heights (`compensate::corrected_tape`) to 1e-12 of the correction,
    /// column after column (the per-thread line follows the column), for
    /// a map's and a turned part's correction.
    fn raster(h: &DesignHeights, along_x: bool, window: Window, domain: Domain) -> RasterFrame<'_> {
        RasterFrame {
            kernel: h.kernel.as_ref(),
            correction: h.correction.as_ref(),
            along_x,
            window,
            domain,
            lenslets: None,
        }
    }

    fn roller(h: &DesignHeights, window: Window, domain: Domain) -> RollerFrame<'_> {
        RollerFrame {
            kernel: h.kernel.as_ref(),
            correction: h.correction.as_ref(),
            window,
            roller_radius: 10.0,
            y_start: -5.0,
            domain,
            lenslets: None,
        }
    }

    #[test]
    fn a_frame_takes_the_correction_out_as_the_corrected_tape_does() {
        let domain = Domain::Circle { radius: 5.0 };
        let window = Window {
            x: (-5.0, 5.0),
            y: (-5.0, 5.0),
            spacing: 0.01,
            given: false,
            whole: true,
        };
        for basis in [
            Basis::map((-5.0, 5.0), (-5.0, 5.0), 1.0),
            Basis::radial(5.0, 1.0),
        ] {
            let (design, applied) = design_and_correction(basis);
            let corrected = corrected_tape(&design, &applied.fitted, applied.gain);
            let split = DesignHeights {
                kernel: crate::evaluate::evaluator(&design.height_only()).0,
                correction: Some(applied.clone()),
            };
            let whole = DesignHeights {
                kernel: crate::evaluate::evaluator(&corrected.height_only()).0,
                correction: None,
            };
            let bare = DesignHeights {
                kernel: crate::evaluate::evaluator(&design.height_only()).0,
                correction: None,
            };
            let lathe = |h| LatheFrame::new(h, window, domain, 5.0, &[], None);
            let frames: [(Box<dyn Frame + '_>, Box<dyn Frame + '_>); 4] = [
                (Box::new(lathe(&split)), Box::new(lathe(&whole))),
                (
                    Box::new(raster(&split, true, window, domain)),
                    Box::new(raster(&whole, true, window, domain)),
                ),
                (
                    Box::new(raster(&split, false, window, domain)),
                    Box::new(raster(&whole, false, window, domain)),
                ),
                (
                    Box::new(roller(&split, window, domain)),
                    Box::new(roller(&whole, window, domain)),
                ),
            ];
            let largest = 0.8 * 2e-5 * basis.terms().len() as f64;
            for (k, (split, whole)) in frames.iter().enumerate() {
                let mut compared = 0;
                // Columns one after another, a few cells each, and back.
                for column in [0.3, 1.7, -2.2, 0.3, 0.95] {
                    let s = if k == 3 { column / 10.0 + 0.5 } else { column };
                    let points: Vec<(f64, f64)> =
                        (0..9).map(|i| (s, -3.5 + 0.8 * i as f64)).collect();
                    let (mut a, mut b) = (vec![0.0; 9], vec![0.0; 9]);
                    split.design(&points, &mut a);
                    whole.design(&points, &mut b);
                    for (p, (a, b)) in points.iter().zip(a.iter().zip(&b)) {
                        assert!(
                            (a - b).abs() <= 1e-12 * largest,
                            "{basis:?} frame {k} at {p:?}: {a} vs {b}"
                        );
                        compared += 1;
                    }
                }
                assert_eq!(compared, 45);
            }
            // The correction is there to be taken out: the design alone
            // differs from the surface aimed at.
            let (mut a, mut b) = ([0.0], [0.0]);
            lathe(&bare).design(&[(0.3, 2.0)], &mut a);
            lathe(&split).design(&[(0.3, 2.0)], &mut b);
            assert!(
                (a[0] - b[0]).abs() > 1e-7,
                "{basis:?}: {} vs {}",
                a[0],
                b[0]
            );
        }
    }

    /// A design the tests below never ask for.
    struct Level;
    impl SurfaceFn for Level {
        fn eval_batch(&self, _: &[f64], _: &[f64], out: &mut [f64]) {
            out.fill(0.0);
        }
    }

    /// Seed 003's lenslets (10 × 10 at 3.5 mm, 0.85 mm in radius) on a
    /// lathe whose spiral starts at 24.7 mm: at angles that graze the
    /// discs (tangent, and a hair either side) and others, every point of
    /// a column inside the window and a disc (as `inside` and the frame's
    /// disc test by squares find it) lies in the column's reach, and the
    /// reach is the chord to within a nanometre; a column that misses a
    /// disc has an empty reach of it.
    #[test]
    fn a_lathe_column_s_reach_holds_every_point_of_its_lenslets() {
        let discs: Vec<(f64, f64, f64)> = (0..100)
            .map(|k| {
                let (i, j) = ((k % 10) as f64, (k / 10) as f64);
                (-15.75 + 3.5 * i, -15.75 + 3.5 * j, 0.85)
            })
            .collect();
        let window = Window {
            x: (-17.5, 17.5),
            y: (-17.5, 17.5),
            spacing: 2e-3,
            given: false,
            whole: true,
        };
        let domain = Domain::Rect {
            x: (-17.5, 17.5),
            y: (-17.5, 17.5),
        };
        let design = DesignHeights {
            kernel: Box::new(Level),
            correction: None,
        };
        let frame = LatheFrame::new(&design, window, domain, 24.7, &discs, None);
        let mut angles: Vec<f64> = (0..2000).map(|k| k as f64 * TAU / 2000.0).collect();
        for &(cx, cy, r) in &discs[..30] {
            let (mid, half) = (cy.atan2(cx), (r / cx.hypot(cy)).asin());
            for side in [-1.0, 1.0] {
                let a = mid + side * half;
                angles.extend([a, a.next_up(), a.next_down(), a + 1e-9, a - 1e-9]);
            }
        }
        let mut inside = 0;
        for &s in &angles {
            for (k, &(cx, cy, r)) in discs.iter().enumerate() {
                let reach = frame.column_reach(s, &discs[k..=k]).expect("a lathe tells");
                let (along, across) = (cx * s.cos() + cy * s.sin(), cx * s.sin() - cy * s.cos());
                if across.abs() > 1.5 * r {
                    assert!(reach.0 > reach.1, "{s} misses lenslet {k}: {reach:?}");
                    continue;
                }
                // Rows every micron across the chord and beyond, and a
                // few a hundredth of a nanometre apart about its middle
                // (all a grazing column's chord holds).
                let rows = (-900..=900)
                    .map(|n| along + n as f64 * 1e-3)
                    .chain((-50..=50).map(|n| along + n as f64 * 1e-8));
                for u in rows {
                    let (x, y) = frame.xy(s, u);
                    let (dx, dy) = (x - cx, y - cy);
                    if u >= 0.0 && frame.inside(x, y) && dx * dx + dy * dy <= r * r {
                        inside += 1;
                        assert!(reach.0 <= u && u <= reach.1, "{s} {u} {reach:?}");
                    }
                }
                if reach.0 <= reach.1 {
                    // The chord, its ends no more than a nanometre beyond
                    // the disc.
                    for u in [reach.0, reach.1] {
                        let (x, y) = frame.xy(s, u);
                        assert!((x - cx).hypot(y - cy) <= r + 1e-6, "{s} {u} {reach:?}");
                    }
                }
            }
        }
        assert!(inside > 100_000, "{inside}");
        // Every lenslet at once: the span of those the line crosses (on
        // both sides of the axis: rows are radii, never negative), within
        // the reach.
        let all = frame.column_reach(0.3, &discs).expect("a lathe tells");
        let widest = 24.7 * (1.0 + 1e-9) + 1e-12;
        assert!(all.0 < -15.0 && all.1 > 15.0, "{all:?}");
        assert!(all.0 >= -widest && all.1 <= widest, "{all:?}");
    }
}
