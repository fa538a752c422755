//! Arrays of lenslets (grid, hex grid, linear array): each lenslet clipped
//! to its aperture on a land, and the settled trajectory for a fast tool servo.

use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::{Binary, Graph, Id, SurfaceTape};

use super::{LowerError, LoweredSurface, Side, height, radius_squared};
use crate::domain::{aperture_domain, domain, half_extent};
use crate::schema::{Array, Axis, Layout, Surface};
use crate::value::Object;

/// Arrays: each lenslet clipped to its own aperture with its rim at the
/// land (z = 0); where apertures overlap, the deepest cut (the lowest
/// height) wins; outside every aperture, the land. Each point looks at its
/// own cell and, where apertures reach past half a pitch, the neighbours.
pub(super) fn array_height(g: &mut Graph, a: &Array, x: Id, y: Id) -> Result<Id, LowerError> {
    array_height_settled(g, a, x, y, None, Cells::NearestWhereItWins)
}

/// Which cells' lenslets an array's height looks at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cells {
    /// The point's own cell alone where its lenslet always cuts deepest
    /// (`nearest_wins`), else as `Reaching`.
    NearestWhereItWins,
    /// The own cell and every neighbour whose aperture may reach the
    /// point (the reference the other is tested against).
    Reaching,
}

/// An array's six outputs, the slopes and curvatures by the chain rule:
/// each lenslet's own tape (its derivatives in closed form where it has
/// them, as a surface of revolution does) at the point's offset (u, v)
/// from its centre, whose derivatives in x and y are those in u and v (the
/// centre is constant over a cell). The height is `array_height`'s, node
/// for node; each slope is the one of the lenslet whose height wins. Half
/// the nodes of differentiating the height in x and y, and a tenth of its
/// divisions.
pub(super) fn array_outputs(g: &mut Graph, a: &Array, x: Id, y: Id) -> Result<[Id; 6], LowerError> {
    array_outputs_of(g, a, (x, y), Cells::NearestWhereItWins)
}

/// `array_outputs` looking at `cells`.
pub(super) fn array_outputs_of(
    g: &mut Graph,
    a: &Array,
    (x, y): (Id, Id),
    cells: Cells,
) -> Result<[Id; 6], LowerError> {
    let lenslet = &*a.lenslet;
    let ap = lenslet_domain(lenslet)?;
    let own = super::lower(lenslet)?.tape;
    let rim = rim_height(lenslet, &ap)?;
    let nearest = cells == Cells::NearestWhereItWins && nearest_wins(lenslet, &ap);
    let candidates = candidate_cells(g, &a.layout, (x, y), half_extent(&ap), nearest)?;
    let big = g.constant_node(BIG);
    let rim_c = g.constant_node(rim);
    let zero = g.constant_node(0.0);
    let mut best = big;
    let mut slopes = [zero; 5];
    for (cx, cy) in candidates {
        let u = g.sub(x, cx);
        let v = g.sub(y, cy);
        let zl = height(g, lenslet, u, v)?;
        let z = g.sub(zl, rim_c);
        let inside_test = inside(g, &ap, u, v);
        let h = g.select(inside_test, z, big);
        // This lenslet's slopes where its height is below the best so far.
        let map = g.import(&own.graph, u, v);
        let wins = g.sub(h, best);
        for (slope, out) in slopes.iter_mut().zip(&own.outputs[1..]) {
            *slope = g.select(wins, map[out.0 as usize], *slope);
        }
        best = g.binary(Binary::Min, best, h);
    }
    let half_big = g.constant_node(BIG / 2.0);
    let test = g.sub(best, half_big);
    let z = g.select(test, best, zero);
    let mut outputs = [z; 6];
    for (o, slope) in outputs[1..].iter_mut().zip(slopes) {
        *o = g.select(test, slope, zero);
    }
    Ok(outputs)
}

/// The height that stands for "no lenslet here" while the lowest lenslet
/// is sought: far above any lens.
const BIG: f64 = 1e6;

/// The tool trajectory over an array for fast-tool-servo turning with a
/// settling offset h (Hashimoto & Yan, fig. 16): each lenslet continued
/// past its rim until it rises h above the land, the land itself at h.
pub fn lower_trajectory(o: &Object, settle: f64) -> Result<LoweredSurface, LowerError> {
    let s = super::read(o)?;
    let Surface::Array(a) = &s else {
        return Err(LowerError::Unsupported(
            "a settling offset needs an array of lenslets",
        ));
    };
    let domain = domain(&s).ok_or(LowerError::Aperture("no aperture or domain"))?;
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = array_height_settled(&mut g, a, x, y, Some(settle), Cells::Reaching)?;
    Ok(LoweredSurface {
        tape: SurfaceTape::new(g, z),
        domain,
    })
}

/// The centres of an array's lenslets (mm), row by row from the least y,
/// as the lowering places them; `None` for other surfaces.
pub fn array_centres(o: &Object) -> Option<Vec<(f64, f64)>> {
    let Ok(Surface::Array(a)) = super::read(o) else {
        return None;
    };
    Some(centres(&a))
}

/// The lenslets of an array, or of an array wrapped on a roller (in the
/// design's coordinates, as the roller's height map reads them): their
/// centres, row by row from the least y, and the aperture each holds
/// about its centre. `None` for other surfaces. Every layout (`grid`,
/// `hex_grid`, `linear_array`) and every aperture (circles, rectangles,
/// rings) has them: what the height map reports lenslet by lenslet.
pub fn array_cells(o: &Object) -> Option<(Vec<(f64, f64)>, Domain)> {
    let a = match super::read(o).ok()? {
        Surface::Array(a) => a,
        Surface::Wrap(w) => match *w.surface {
            Surface::Array(a) => a,
            _ => return None,
        },
        _ => return None,
    };
    let aperture = lenslet_domain(&a.lenslet).ok()?;
    Some((centres(&a), aperture))
}

/// The centres of `a`'s lenslets (mm), row by row from the least y, as
/// the lowering places them.
fn centres(a: &Array) -> Vec<(f64, f64)> {
    let (px, py, nx, ny) = match a.layout {
        Layout::Hex {
            pitch,
            count_x,
            count_y,
        } => return hex_centres(pitch, count_x, count_y),
        Layout::Grid {
            pitch_x,
            pitch_y,
            count_x,
            count_y,
        } => (pitch_x, pitch_y, count_x, count_y),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::Y,
        } => (0.0, pitch, 1.0, count),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::X,
        } => (pitch, 0.0, count, 1.0),
    };
    let (nx, ny) = (nx as usize, ny as usize);
    let mut centres = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            centres.push((
                (i as f64 - (nx as f64 - 1.0) / 2.0) * px,
                (j as f64 - (ny as f64 - 1.0) / 2.0) * py,
            ));
        }
    }
    centres
}

/// The centres of a hexagonal grid's lenslets, as `hex_cells` places
/// them: rows p·√3/2 apart, row j shifted by (parity(j) − 1/2)·p/2, row
/// and column indices clamped to n − 1 as `cell_index` clamps them (a
/// hex grid's row count need not be whole).
fn hex_centres(p: f64, nx: f64, ny: f64) -> Vec<(f64, f64)> {
    let row = p * 3f64.sqrt() / 2.0;
    let indices = |n: f64| -> Vec<f64> {
        (0..n.ceil().max(1.0) as usize)
            .map(|k| (k as f64).min(n - 1.0).max(0.0))
            .collect()
    };
    let mut centres = Vec::new();
    for j in indices(ny) {
        let parity = j - 2.0 * (j * 0.5).floor();
        let shift = parity * (p / 2.0) - p / 4.0;
        let cy = (j - (ny - 1.0) / 2.0) * row;
        for i in indices(nx) {
            centres.push(((i - (nx - 1.0) / 2.0) * p + shift, cy));
        }
    }
    centres.dedup();
    centres
}

/// The lenslet of an array as its own surface, with the radius of its
/// circular aperture: what the settling offset is measured on.
pub fn array_lenslet(o: &Object) -> Option<(LoweredSurface, f64)> {
    let Ok(Surface::Array(a)) = super::read(o) else {
        return None;
    };
    let Domain::Circle { radius } = aperture_domain(a.lenslet.region()?) else {
        return None;
    };
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = height(&mut g, &a.lenslet, x, y).ok()?;
    Some((
        LoweredSurface {
            tape: SurfaceTape::new(g, z),
            domain: Domain::Circle { radius },
        },
        radius,
    ))
}

pub(super) fn array_height_settled(
    g: &mut Graph,
    a: &Array,
    x: Id,
    y: Id,
    settle: Option<f64>,
    cells: Cells,
) -> Result<Id, LowerError> {
    let lenslet = &*a.lenslet;
    let ap = lenslet_domain(lenslet)?;
    let (hx, hy) = half_extent(&ap);
    // Continued lenslets reach past their apertures: look at neighbours.
    let (hx, hy) = if settle.is_some() {
        (1.5 * hx, 1.5 * hy)
    } else {
        (hx, hy)
    };
    let rim = rim_height(lenslet, &ap)?;
    // Cell centres: (i, j) → (cx, cy) as nodes; candidate cells per point.
    // A continued lenslet is no longer held to its aperture: the nearest
    // cell's need not win.
    let nearest =
        cells == Cells::NearestWhereItWins && settle.is_none() && nearest_wins(lenslet, &ap);
    let candidates = candidate_cells(g, &a.layout, (x, y), (hx, hy), nearest)?;
    // min over the candidates that contain the point; +BIG where none do.
    let big = g.constant_node(BIG);
    let half_big = g.constant_node(BIG / 2.0);
    let rim_c = g.constant_node(rim);
    let mut best = big;
    for (cx, cy) in candidates {
        let u = g.sub(x, cx);
        let v = g.sub(y, cy);
        let zl = height(g, lenslet, u, v)?;
        let z = g.sub(zl, rim_c);
        if settle.is_some() {
            // A neighbour continued far past its rim may have no height
            // there (a sphere beyond its radius: NaN). The minimum's value
            // would skip it but not its derivatives (d min = db + s·(da −
            // db) with s = 0 still reads da), so a continuation counts
            // only where it is defined.
            let defined = g.sub(z, half_big);
            let z = g.select(defined, z, big);
            best = g.binary(Binary::Min, best, z);
            continue;
        }
        let inside_test = inside(g, &ap, u, v);
        let h = g.select(inside_test, z, big);
        best = g.binary(Binary::Min, best, h);
    }
    if let Some(h) = settle {
        let plateau = g.constant_node(h);
        return Ok(g.binary(Binary::Min, best, plateau));
    }
    let test = g.sub(best, half_big);
    let land = g.constant_node(0.0);
    Ok(g.select(test, best, land))
}

/// The domain of an array's lenslet: its own aperture.
fn lenslet_domain(lenslet: &Surface) -> Result<Domain, LowerError> {
    lenslet
        .region()
        .map(aperture_domain)
        .ok_or(LowerError::Aperture("lenslet without an aperture"))
}

/// The lenslet's height at the edge of its aperture along +x: the height
/// the land is cut at.
fn rim_height(lenslet: &Surface, ap: &Domain) -> Result<f64, LowerError> {
    let mut h = Graph::new();
    let (u, v) = (h.x(), h.y());
    let z = height(&mut h, lenslet, u, v)?;
    let f = lensc_runtime::surface::ir::Interpreter::new(&SurfaceTape::new(h, z));
    let at = match *ap {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => (radius, 0.0),
        Domain::Rect { x, y } => (x.1, 0.5 * (y.0 + y.1)),
    };
    Ok(lensc_runtime::surface::ir::SurfaceFn::eval(&f, at.0, at.1)[0])
}

/// Whether, in a rectangular grid of this lenslet, the lenslet of the cell
/// a point lies in always cuts at least as deep there as any other whose
/// aperture holds the point, so that the deepest cut is the own cell's.
///
/// So it is when the aperture is centred on the lenslet (a circle, or a
/// rectangle symmetric about its centre) and the height never falls as
/// |u| or |v| grows: the own cell's centre is the nearest along x and
/// along y (cells are the grid's rectangles), so wherever a neighbour's
/// aperture holds the point the own one does too, at a height no higher.
/// The height is then non-decreasing in |u| and |v| in floating point as
/// well, every operation on the way being monotonic: a concave ellipsoid,
/// z = c (1 − sqrt(1 − u²/a² − v²/b²)) with c > 0, and a concave sphere or
/// conic without aspheric terms and with (1 + k) ≥ 0, z = c s / (1 +
/// sqrt(1 − (1 + k) c² s)) with s = u² + v² and c > 0 (with a negative
/// (1 + k) its denominator would grow too).
fn nearest_wins(lenslet: &Surface, aperture: &Domain) -> bool {
    let centred = match *aperture {
        Domain::Circle { .. } => true,
        Domain::Rect { x, y } => x.0 == -x.1 && y.0 == -y.1,
        Domain::Annulus { .. } => false,
    };
    let rising = match lenslet {
        Surface::Ellipsoid(e) => {
            let side = Side::from(e.facing);
            let usable = |v: f64| v.is_finite() && v != 0.0;
            usable(e.a) && usable(e.b) && e.c * side.sigma > 0.0
        }
        Surface::Sphere(p) | Surface::Conic(p) => {
            let side = Side::from(p.facing);
            let c = side.curvature(p.base.radius) * side.sigma;
            let k = p.base.conic;
            c > 0.0 && c.is_finite() && 1.0 + k >= 0.0 && p.terms.is_empty()
        }
        _ => false,
    };
    centred && rising
}

/// The centres of the cells a point may lie in, as the array's layout
/// places them: a rectangular grid's or a linear array's (`grid_cells`, a
/// linear array's pitch infinite across it), or a hex grid's.
fn candidate_cells(
    g: &mut Graph,
    layout: &Layout,
    at: (Id, Id),
    half: (f64, f64),
    nearest: bool,
) -> Result<Vec<(Id, Id)>, LowerError> {
    match *layout {
        Layout::Grid {
            pitch_x,
            pitch_y,
            count_x,
            count_y,
        } => grid_cells(g, (pitch_x, pitch_y, count_x, count_y), at, half, nearest),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::Y,
        } => grid_cells(g, (f64::INFINITY, pitch, 1.0, count), at, half, nearest),
        Layout::Linear {
            pitch,
            count,
            axis: Axis::X,
        } => grid_cells(g, (pitch, f64::INFINITY, count, 1.0), at, half, nearest),
        Layout::Hex {
            pitch,
            count_x,
            count_y,
        } => hex_cells(g, (pitch, count_x, count_y), at, half),
    }
}

/// The centres of the cells of a rectangular grid or a linear array a
/// point may lie in: its own and, where apertures reach past half a
/// pitch, its neighbours — unless the own cell's lenslet is known to cut
/// deepest (`nearest`, see `nearest_wins`): then its own alone.
/// (`px`, `py`: the pitches along x and y; `nx`, `ny`: the counts.)
fn grid_cells(
    g: &mut Graph,
    (px, py, nx, ny): (f64, f64, f64, f64),
    (x, y): (Id, Id),
    (hx, hy): (f64, f64),
    nearest: bool,
) -> Result<Vec<(Id, Id)>, LowerError> {
    let mut candidates: Vec<(Id, Id)> = Vec::new();
    let reach = |half: f64, pitch: f64| {
        if half > 1.5 * pitch {
            None
        } else if half > 0.5 * pitch {
            Some(1)
        } else {
            Some(0)
        }
    };
    let (kx, ky) = match (reach(hx, px), reach(hy, py)) {
        _ if nearest && hx <= 1.5 * px && hy <= 1.5 * py => (0, 0),
        (Some(a), Some(b)) => (a, b),
        _ => {
            return Err(LowerError::Aperture(
                "lenslet apertures reach past their neighbours",
            ));
        }
    };
    let axis_cells = |g: &mut Graph, t: Id, pitch: f64, n: f64, k: i32| -> Vec<Id> {
        if n <= 1.0 {
            return vec![g.constant_node(0.0)];
        }
        let qt = cell_coordinate(g, t, pitch, n);
        (-k..=k)
            .map(|d| {
                let i = cell_index(g, qt, n, f64::from(d));
                cell_centre(g, i, n, pitch)
            })
            .collect()
    };
    let xs = axis_cells(g, x, px, nx, kx);
    let ys = axis_cells(g, y, py, ny, ky);
    for &cx in &xs {
        for &cy in &ys {
            candidates.push((cx, cy));
        }
    }
    Ok(candidates)
}

/// The centres of the cells of a hexagonal grid (pitch `p`, `nx` per row,
/// `ny` rows) a point may lie in: three rows of three.
fn hex_cells(
    g: &mut Graph,
    (p, nx, ny): (f64, f64, f64),
    (x, y): (Id, Id),
    (hx, hy): (f64, f64),
) -> Result<Vec<(Id, Id)>, LowerError> {
    let mut candidates: Vec<(Id, Id)> = Vec::new();
    // Hexagonal: rows of spacing p·√3/2, odd rows shifted by p/2.
    if hx.max(hy) > 1.5 * p {
        return Err(LowerError::Aperture(
            "lenslet apertures reach past their neighbours",
        ));
    }
    let row = p * 3f64.sqrt() / 2.0;
    let qt = cell_coordinate(g, y, row, ny);
    for dj in -1..=1 {
        let j = cell_index(g, qt, ny, f64::from(dj));
        let cy = cell_centre(g, j, ny, row);
        // parity of j: j − 2 floor(j/2), shifting the row by ±p/4.
        let h = g.constant_node(0.5);
        let jh = g.mul(j, h);
        let fl = g.floor(jh);
        let two = g.constant_node(2.0);
        let tf = g.mul(two, fl);
        let parity = g.sub(j, tf);
        let quarter = g.constant_node(p / 2.0);
        let pq = g.mul(parity, quarter);
        let back = g.constant_node(p / 4.0);
        let shift = g.sub(pq, back);
        let xl = g.sub(x, shift);
        let xt = cell_coordinate(g, xl, p, nx);
        for di in -1..=1 {
            let i = cell_index(g, xt, nx, f64::from(di));
            let cx0 = cell_centre(g, i, nx, p);
            let cx = g.add(cx0, shift);
            candidates.push((cx, cy));
        }
    }
    Ok(candidates)
}

/// t/pitch + n/2, as a node: the coordinate in cells from the edge of a
/// row of n cells centred on the origin.
fn cell_coordinate(g: &mut Graph, t: Id, pitch: f64, n: f64) -> Id {
    let inv = g.constant_node(1.0 / pitch);
    let q = g.mul(t, inv);
    let half = g.constant_node(n / 2.0);
    g.add(q, half)
}

/// (i − (n − 1)/2) · pitch, as a node: the centre of cell i of a row of n.
fn cell_centre(g: &mut Graph, i: Id, n: f64, pitch: f64) -> Id {
    let mid = g.constant_node((n - 1.0) / 2.0);
    let off = g.sub(i, mid);
    let p = g.constant_node(pitch);
    g.mul(off, p)
}

/// clamp(floor(t), 0, n − 1) + offset, as a node: a cell index.
fn cell_index(g: &mut Graph, t: Id, n: f64, offset: f64) -> Id {
    let f = g.floor(t);
    let zero = g.constant_node(0.0);
    let top = g.constant_node(n - 1.0);
    let lo = g.binary(Binary::Max, f, zero);
    let i = g.binary(Binary::Min, lo, top);
    if offset == 0.0 {
        // Already in 0 ..= n − 1: clamping again changes nothing.
        return i;
    }
    let off = g.constant_node(offset);
    let shifted = g.add(i, off);
    let clamped_lo = g.binary(Binary::Max, shifted, zero);
    g.binary(Binary::Min, clamped_lo, top)
}

/// A node that is negative exactly inside `domain` at (u, v).
fn inside(g: &mut Graph, domain: &Domain, u: Id, v: Id) -> Id {
    match *domain {
        Domain::Circle { radius } => {
            let r2 = radius_squared(g, u, v);
            let a2 = g.constant_node(radius * radius);
            g.sub(r2, a2)
        }
        Domain::Annulus { inner, outer } => {
            // max(r² − outer², inner² − r²)
            let r2 = radius_squared(g, u, v);
            let o2 = g.constant_node(outer * outer);
            let i2 = g.constant_node(inner * inner);
            let a = g.sub(r2, o2);
            let b = g.sub(i2, r2);
            g.binary(Binary::Max, a, b)
        }
        Domain::Rect {
            x: (x0, x1),
            y: (y0, y1),
        } => {
            // max(x0 − u, u − x1, y0 − v, v − y1)
            let c = |g: &mut Graph, k: f64| g.constant_node(k);
            let (cx0, cx1, cy0, cy1) = (c(g, x0), c(g, x1), c(g, y0), c(g, y1));
            let a = g.sub(cx0, u);
            let b = g.sub(u, cx1);
            let d = g.sub(cy0, v);
            let e = g.sub(v, cy1);
            let m1 = g.binary(Binary::Max, a, b);
            let m2 = g.binary(Binary::Max, d, e);
            g.binary(Binary::Max, m1, m2)
        }
    }
}
