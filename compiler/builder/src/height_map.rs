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

/// A raster on a mill: s along the cut (x or y), u across, h = z.
pub struct RasterFrame<'a> {
    /// The design; only its height is read (a kernel of
    /// `SurfaceTape::height_only` does no other work).
    pub kernel: &'a (dyn SurfaceFn + Sync),
    pub along_x: bool,
    pub window: Window,
    pub domain: Domain,
    /// An array's lenslets, each reported on its own.
    pub lenslets: Option<&'a Lenslets>,
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
        kernel: &'a (dyn SurfaceFn + Sync),
        window: Window,
        domain: Domain,
        reach: f64,
        features: &[(f64, f64, f64)],
        lenslets: Option<&'a Lenslets>,
    ) -> LatheFrame<'a> {
        LatheFrame {
            kernel,
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
