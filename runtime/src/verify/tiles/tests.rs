//! Tests of simulation in tiles: the same figures as one grid, and the
//! same for any number of threads.

use super::*;
use crate::verify::heightmap::Grid;
use crate::verify::window::split_columns;

/// A gently curved design on a Cartesian window, with two lenslets.
struct Wavy {
    features: Vec<(f64, f64, f64)>,
}
fn design(x: f64, y: f64) -> f64 {
    2e-4 * (40.0 * x).sin() * (30.0 * y).cos()
}
impl Frame for Wavy {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        for (o, &(s, u)) in out.iter_mut().zip(points) {
            *o = design(s, u);
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        (s, u)
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        (0.0..=0.12).contains(&x) && (0.0..=0.1).contains(&y)
    }
    fn features(&self) -> &[(f64, f64, f64)] {
        &self.features
    }
}

const GRID: Grid = Grid {
    s0: 0.0,
    ds: 0.001,
    ns: 121,
    u0: 0.0,
    du: 0.001,
    nu: 101,
    period: None,
    j0: 0,
    i0: 0,
};
const NOSE: f64 = 0.005;

/// Passes 7 µm apart along s, points every 3 µm on the design with a
/// ripple, a lift between passes; three passes stop short (a strip
/// uncut).
fn cut(path: &mut dyn NosePath) {
    for k in -14..=30 {
        let u = k as f64 * 0.007;
        path.lift();
        let end = if (4..=6).contains(&k) { 30 } else { 45 };
        for j in 0..=end {
            let s = -0.005 + 0.003 * j as f64;
            let ripple = 3e-6 * (j as f64 * 0.9 + k as f64).sin();
            path.point(s, u, NOSE + design(s, u) + ripple);
        }
    }
}

fn frame() -> Wavy {
    Wavy {
        features: vec![(0.03, 0.05, 0.02), (0.09, 0.05, 0.03), (0.07, 0.05, 0.02)],
    }
}

fn tiled(threads: usize) -> TiledMap {
    let tiles = split_columns(&GRID, None, 25);
    assert_eq!(tiles.len(), 5);
    let mut recorder = Recorder::new(Recorder::band_of(&tiles, NOSE));
    cut(&mut recorder);
    let layout = RasterLayout::new((0.0, 0.12), (0.0, 0.1), 0.001, 16);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a pool");
    pool.install(|| {
        simulate(
            &recorder,
            &tiles,
            GRID,
            Cutter::nose(NOSE),
            &frame(),
            layout,
        )
    })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-15 + 1e-12 * a.abs().max(b.abs())
}

/// Cut into 5 tiles, the map has the one grid's figures: counts,
/// extremes and their places exactly, means and RMS to rounding, every
/// lenslet's, and the same downsampled map.
#[test]
fn tiles_give_the_one_grids_figures() {
    let mut sweep = Sweep::new(GRID, NOSE);
    cut(&mut sweep);
    let f = frame();
    let whole = sweep.finish(&f);
    let t = tiled(2);
    let m = &t.map;
    assert_eq!(m.tiles, 5);
    assert_eq!((m.cells, m.uncut), (whole.cells, whole.uncut));
    assert!(
        whole.uncut > 0 && whole.uncut < whole.cells,
        "{}",
        whole.uncut
    );
    assert!(close(m.area, whole.area) && close(m.uncut_area, whole.uncut_area));
    let same = |a: &Option<ErrorFiguresXY>, b: &Option<ErrorFiguresXY>| {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert_eq!(
            (
                a.count,
                a.pv,
                a.max_gouge,
                a.max_residual,
                a.largest_deviation
            ),
            (
                b.count,
                b.pv,
                b.max_gouge,
                b.max_residual,
                b.largest_deviation
            )
        );
        assert!(close(a.mean, b.mean) && close(a.rms, b.rms), "{a:?} {b:?}");
    };
    same(&m.surface, &whole.surface);
    same(&m.contact, &whole.contact);
    let (sa, sb) = (m.scallops.unwrap(), whole.scallops.unwrap());
    assert_eq!((sa.count, sa.max), (sb.count, sb.max));
    assert!(close(sa.mean, sb.mean));
    // Whole columns in each tile: the step-over roughness is the grid's.
    assert!(close(m.rq_stepover, whole.rq_stepover));
    assert_eq!(m.features.len(), 3);
    assert_eq!(whole.features.len(), 3);
    for (a, b) in m.features.iter().zip(&whole.features) {
        assert_eq!(a.centre, b.centre);
        same(&a.surface, &b.surface);
        same(&a.contact, &b.contact);
    }
    let r = whole.raster(&f, (0.0, 0.12), (0.0, 0.1), 0.001, 16);
    assert_eq!(
        (t.raster.nx, t.raster.ny, t.raster.block),
        (r.nx, r.ny, r.block)
    );
    let bits = |c: &[f64]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&t.raster.cells), bits(&r.cells));
    assert_eq!(t.raster.uncut, r.uncut);
}

type ErrorFiguresXY = crate::verify::heightmap::ErrorFigures;

/// One thread or two: the same map, bit for bit.
#[test]
fn the_same_map_for_any_number_of_threads() {
    let (one, two) = (tiled(1), tiled(2));
    assert_eq!(format!("{:?}", one.map), format!("{:?}", two.map));
    let bits = |c: &[f64]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one.raster.cells), bits(&two.raster.cells));
}

/// The recorder keeps only what reaches the tiles' band, and an arc's
/// centre with the step it ends at.
#[test]
fn the_recorder_keeps_the_band_only() {
    let mut r = Recorder::new((0.0, 1.0));
    r.point(0.0, 5.0, 0.0);
    r.point(1.0, 5.0, 0.0); // outside: not kept
    r.point(2.0, 0.5, 0.0); // reaches: both ends kept
    r.arc(3.0, 0.5, 0.0, (2.5, 1.0));
    r.lift();
    r.point(0.0, 0.7, 0.0);
    r.point(1.0, 0.7, 0.0);
    assert_eq!(r.len(), 2 + 1 + 1 + 2);
    assert_eq!(r.arcs, [(2, (2.5, 1.0))]);
    assert!(r.steps[3].0.is_nan());
}

/// A spiral's design on a polar grid (s the spindle angle, u the radius).
struct Turned;
fn turned_design(x: f64, y: f64) -> f64 {
    1e-4 * (3.0 * x).sin() * (2.0 * y).cos()
}
impl Frame for Turned {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        for (o, &(s, u)) in out.iter_mut().zip(points) {
            let (x, y) = self.xy(s, u);
            *o = turned_design(x, y);
        }
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        (u * s.cos(), u * s.sin())
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        (1.0..=1.05).contains(&x.hypot(y))
    }
}

/// Five turns of a spiral, 10 000 points a turn (each of the recorder's
/// blocks under half a turn), 12 µm a turn inward, with a ripple.
fn spiral(path: &mut dyn NosePath, nose: f64) {
    for k in 0..50_000 {
        let s = k as f64 * std::f64::consts::TAU / 10_000.0;
        let u = 1.062 - 0.012 * s / std::f64::consts::TAU;
        let ripple = 2e-6 * (k as f64 * 0.37).sin();
        path.point(
            s,
            u,
            nose + turned_design(u * s.cos(), u * s.sin()) + ripple,
        );
    }
}

/// A lathe's tiles sweep only the recorder's blocks some turn of which
/// crosses their columns; the figures are those of one grid swept with
/// every point of the path (the brute force): counts, extremes and their
/// places exactly, means and RMS to rounding.
#[test]
fn a_lathe_s_tiles_skip_the_turns_that_miss_them_and_keep_the_figures() {
    let nose = 0.02;
    let grid = Grid {
        s0: 0.2,
        ds: 0.001,
        ns: 300,
        u0: 1.0,
        du: 0.001,
        nu: 51,
        period: Some(std::f64::consts::TAU),
        j0: 0,
        i0: 0,
    };
    let mut sweep = Sweep::new(grid, nose);
    spiral(&mut sweep, nose);
    let whole = sweep.finish(&Turned);
    let tiles = split_columns(&grid, None, 60);
    let mut recorder = Recorder::new(Recorder::band_of(&tiles, nose));
    spiral(&mut recorder, nose);
    let layout = RasterLayout::new((-1.1, 1.1), (-1.1, 1.1), 0.01, 16);
    let m = simulate(&recorder, &tiles, grid, Cutter::nose(nose), &Turned, layout).map;
    assert_eq!((m.cells, m.uncut), (whole.cells, whole.uncut));
    assert!(whole.cells > 10_000 && whole.uncut == 0, "{}", whole.uncut);
    for (a, b) in [(m.surface, whole.surface), (m.contact, whole.contact)] {
        let (a, b) = (a.expect("figures"), b.expect("figures"));
        assert_eq!(
            (a.count, a.pv, a.max_gouge, a.max_residual),
            (b.count, b.pv, b.max_gouge, b.max_residual)
        );
        assert!(close(a.mean, b.mean) && close(a.rms, b.rms), "{a:?} {b:?}");
    }
    // Blocks of a turn's part: the first misses the columns (0.2 .. 0.5
    // rad) in every turn, one a turn later crosses them.
    let p = Some(std::f64::consts::TAU);
    assert!(misses((0.2, 0.5), p, (1.0, 3.0)));
    assert!(misses((0.2, 0.5), p, (1.0 + 6.3, 3.0 + 6.3)));
    assert!(!misses((0.2, 0.5), p, (6.3, 6.7)));
    assert!(!misses((0.2, 0.5), p, (1.0, 9.0)));
    assert!(misses((0.2, 0.5), None, (6.3, 6.7)));
}

/// Lenslets on a lathe (`Turned`'s design), each a disc: with `reach`, the
/// frame tells each column's chord of the discs (the line u (cos s, sin
/// s) across each, the radii a little wider), as a lathe's frame does.
struct TurnedLenslets {
    discs: Vec<(f64, f64, f64)>,
    reach: bool,
}
impl Frame for TurnedLenslets {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        Turned.design(points, out)
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        Turned.xy(s, u)
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        Turned.inside(x, y)
    }
    fn features(&self) -> &[(f64, f64, f64)] {
        &self.discs
    }
    fn column_reach(&self, s: f64, discs: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
        if !self.reach {
            return None;
        }
        let (cos, sin) = (s.cos(), s.sin());
        let (lo, hi) = discs.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), &(cx, cy, r)| {
                let (along, across) = (cx * cos + cy * sin, cx * sin - cy * cos);
                let r = r * (1.0 + 1e-9) + 1e-12;
                if across.abs() > r {
                    return (lo, hi);
                }
                let half = (r * r - across * across).sqrt();
                (lo.min(along - half), hi.max(along + half))
            },
        );
        Some((lo, hi))
    }
}

/// A lathe's lenslets tile by tile, each over the polar square around
/// its disc: with the frame telling each column's chord of the discs,
/// the corner columns gather no passes and rows, contacts and cusps
/// beyond the chord are not tried, and the map is the same, bit for bit
/// (every figure, every lenslet's, the downsampled map), as with every
/// row of every column tried.
#[test]
fn rows_beyond_a_column_s_chord_of_the_lenslets_are_not_tried_and_change_no_figure() {
    let nose = 0.02;
    let discs = vec![
        (1.03 * 0.3f64.cos(), 1.03 * 0.3f64.sin(), 0.018),
        (1.025 * 0.42f64.cos(), 1.025 * 0.42f64.sin(), 0.015),
    ];
    let window = crate::verify::window::Window::given(
        (0.85, 1.05),
        (0.25, 0.45),
        Some(0.001),
        ((0.85, 1.05), (0.25, 0.45)),
    );
    let tiles = window.polar_tiles(&discs);
    assert_eq!(tiles.len(), 2, "lenslet by lenslet");
    let mut recorder = Recorder::new(Recorder::band_of(&tiles, nose));
    spiral(&mut recorder, nose);
    let layout = RasterLayout::new(window.x, window.y, 0.0015, 64);
    let map = |reach: bool| {
        let frame = TurnedLenslets {
            discs: discs.clone(),
            reach,
        };
        let cutter = Cutter::Nose {
            radius: nose,
            edge: None,
        };
        simulate(&recorder, &tiles, window.polar(), cutter, &frame, layout)
    };
    let (tried, told) = (map(false), map(true));
    assert_eq!(format!("{:?}", told.map), format!("{:?}", tried.map));
    let bits = |c: &[f64]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&told.raster.cells), bits(&tried.raster.cells));
    assert_eq!(told.raster.uncut, tried.raster.uncut);
    // Both lenslets cut, with contacts and scallops.
    assert_eq!(told.map.features.len(), 2);
    let scallops: Vec<usize> = told
        .map
        .features
        .iter()
        .map(|f| f.contact.map_or(0, |_| f.scallops.map_or(0, |s| s.count)))
        .collect();
    assert!(scallops.iter().all(|&n| n > 20), "{scallops:?}");
    assert!(told.map.cells > 1500, "{}", told.map.cells);
}
