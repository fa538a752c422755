//! Which lenslet of an array a point of the part belongs to, for height
//! maps that report an array lenslet by lenslet whatever its layout
//! (rectangular grid, hexagonal grid, linear array) or its lenslets'
//! apertures (circles, rectangles, rings): a point belongs to the nearest
//! lenslet (by its centre) whose aperture holds it, and to none where no
//! aperture does (the land between lenslets). Where apertures overlap
//! (seed 002's dimples, each reaching past its cell), the nearest centre
//! is the lenslet whose cell the point lies in: the cells of a
//! rectangular or hexagonal lattice are the points nearest their centres.

use crate::surface::analysis::Domain;

/// An array's lenslets: their centres (mm, in the array's order) and the
/// aperture each holds about its centre, bucketed so that a point finds
/// its lenslet among a few.
#[derive(Clone, Debug, PartialEq)]
pub struct Lenslets {
    centres: Vec<(f64, f64)>,
    aperture: Domain,
    /// The buckets' origin, size (mm) and counts along x and y.
    origin: (f64, f64),
    size: f64,
    nx: usize,
    ny: usize,
    /// Bucket b's lenslets are `items[starts[b]..starts[b + 1]]`: every
    /// lenslet whose aperture's bounding box reaches the bucket.
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// The most buckets a side: a bucket then holds a handful of lenslets
/// even for an array of ten thousand.
const MOST_BUCKETS: usize = 512;

impl Lenslets {
    /// The lenslets centred at `centres`, each holding `aperture` about
    /// its centre; `None` without a centre or with an aperture of no
    /// finite extent.
    pub fn new(centres: Vec<(f64, f64)>, aperture: Domain) -> Option<Lenslets> {
        let ((ax0, ax1), (ay0, ay1)) = aperture.bounds();
        let reach = [ax0, ax1, ay0, ay1]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if centres.is_empty() || !(reach > 0.0 && reach.is_finite()) {
            return None;
        }
        let (mut x, mut y) = (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        );
        for &(cx, cy) in &centres {
            x = (x.0.min(cx + ax0), x.1.max(cx + ax1));
            y = (y.0.min(cy + ay0), y.1.max(cy + ay1));
        }
        if !(x.0.is_finite() && x.1.is_finite() && y.0.is_finite() && y.1.is_finite()) {
            return None;
        }
        // Buckets the aperture's reach wide, no more than MOST_BUCKETS a side.
        let span = (x.1 - x.0).max(y.1 - y.0);
        let size = reach.max(span / MOST_BUCKETS as f64);
        let count = |w: f64| ((w / size).floor() as usize + 1).min(MOST_BUCKETS + 1);
        let (nx, ny) = (count(x.1 - x.0), count(y.1 - y.0));
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
        for (k, &(cx, cy)) in centres.iter().enumerate() {
            let (i0, i1) = (
                bucket(cx + ax0, x.0, size, nx),
                bucket(cx + ax1, x.0, size, nx),
            );
            let (j0, j1) = (
                bucket(cy + ay0, y.0, size, ny),
                bucket(cy + ay1, y.0, size, ny),
            );
            for j in j0..=j1 {
                for i in i0..=i1 {
                    lists[j * nx + i].push(k as u32);
                }
            }
        }
        let mut starts = Vec::with_capacity(lists.len() + 1);
        let mut items = Vec::new();
        for l in &lists {
            starts.push(items.len() as u32);
            items.extend_from_slice(l);
        }
        starts.push(items.len() as u32);
        Some(Lenslets {
            centres,
            aperture,
            origin: (x.0, y.0),
            size,
            nx,
            ny,
            starts,
            items,
        })
    }

    /// The same lenslets, each holding its aperture widened `factor`
    /// times about its centre (a ring's hole filled): a lenslet with a
    /// margin of the land about it, where the land tells its place.
    pub fn widened(&self, factor: f64) -> Option<Lenslets> {
        let aperture = match self.aperture {
            Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => Domain::Circle {
                radius: radius * factor,
            },
            Domain::Rect { x, y } => Domain::Rect {
                x: (x.0 * factor, x.1 * factor),
                y: (y.0 * factor, y.1 * factor),
            },
        };
        Lenslets::new(self.centres.clone(), aperture)
    }

    /// The number of lenslets.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// Lenslet `k`'s centre (mm).
    pub fn centre(&self, k: usize) -> (f64, f64) {
        self.centres[k]
    }

    /// The centres, in the array's order.
    pub fn centres(&self) -> &[(f64, f64)] {
        &self.centres
    }

    /// The aperture each lenslet holds about its centre.
    pub fn aperture(&self) -> Domain {
        self.aperture
    }

    /// The lenslet (x, y) belongs to: of those whose aperture holds it,
    /// the one whose centre is nearest (the first of equals); `None` on
    /// the land, outside every aperture.
    pub fn which(&self, x: f64, y: f64) -> Option<usize> {
        let fx = (x - self.origin.0) / self.size;
        let fy = (y - self.origin.1) / self.size;
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (i, j) = (fx as usize, fy as usize);
        if i >= self.nx || j >= self.ny {
            return None;
        }
        let b = j * self.nx + i;
        let list = &self.items[self.starts[b] as usize..self.starts[b + 1] as usize];
        let mut best: Option<(f64, usize)> = None;
        for &k in list {
            let (cx, cy) = self.centres[k as usize];
            let (u, v) = (x - cx, y - cy);
            if !self.aperture.contains(u, v) {
                continue;
            }
            let d = u * u + v * v;
            if best.is_none_or(|(bd, bk)| d < bd || (d == bd && (k as usize) < bk)) {
                best = Some((d, k as usize));
            }
        }
        best.map(|(_, k)| k)
    }
}

/// The bucket (clamped to 0 ..= n − 1) of coordinate `t` on buckets
/// `size` wide from `origin`.
fn bucket(t: f64, origin: f64, size: f64, n: usize) -> usize {
    (((t - origin) / size).floor().max(0.0) as usize).min(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: of every lenslet whose aperture holds the point, the
    /// nearest.
    fn nearest(l: &Lenslets, x: f64, y: f64) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        for (k, &(cx, cy)) in l.centres().iter().enumerate() {
            if !l.aperture().contains(x - cx, y - cy) {
                continue;
            }
            let d = (x - cx).powi(2) + (y - cy).powi(2);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, k));
            }
        }
        best.map(|(_, k)| k)
    }

    fn grid(px: f64, py: f64, nx: usize, ny: usize) -> Vec<(f64, f64)> {
        let mut c = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                c.push((
                    (i as f64 - (nx as f64 - 1.0) / 2.0) * px,
                    (j as f64 - (ny as f64 - 1.0) / 2.0) * py,
                ));
            }
        }
        c
    }

    /// Buckets change nothing: every point of a fine grid over circles on
    /// a land, overlapping circles (seed 002's dimples) and rectangles
    /// finds the lenslet brute force finds.
    #[test]
    fn buckets_find_what_brute_force_finds() {
        let cases = [
            (grid(3.5, 3.5, 4, 3), Domain::Circle { radius: 0.85 }),
            (grid(0.1, 0.196, 6, 9), Domain::Circle { radius: 0.12 }),
            (
                grid(0.554, 0.0, 10, 1),
                Domain::Rect {
                    x: (-0.267, 0.267),
                    y: (-1.0, 1.0),
                },
            ),
            (
                grid(1.0, 1.0, 3, 3),
                Domain::Annulus {
                    inner: 0.1,
                    outer: 0.45,
                },
            ),
        ];
        for (centres, ap) in cases {
            let l = Lenslets::new(centres, ap).expect("lenslets");
            let ((x0, x1), (y0, y1)) = (
                (l.origin.0 - 0.1, l.origin.0 + l.size * l.nx as f64),
                (l.origin.1 - 0.1, l.origin.1 + l.size * l.ny as f64),
            );
            let mut found = 0;
            for a in 0..=173 {
                for b in 0..=171 {
                    let x = x0 + (x1 - x0) * a as f64 / 173.0;
                    let y = y0 + (y1 - y0) * b as f64 / 171.0;
                    let want = nearest(&l, x, y);
                    assert_eq!(l.which(x, y), want, "({x}, {y}) in {ap:?}");
                    found += usize::from(want.is_some());
                }
            }
            assert!(found > 1000, "{ap:?}: {found}");
        }
    }

    /// Overlapping apertures go to the cell the point lies in.
    #[test]
    fn overlapping_dimples_go_to_their_cells() {
        let l = Lenslets::new(grid(0.1, 0.2, 3, 3), Domain::Circle { radius: 0.12 }).unwrap();
        // Centres (−0.1, −0.2) … (0.1, 0.2); index 4 the middle.
        assert_eq!(l.which(0.0, 0.0), Some(4));
        assert_eq!(l.which(0.049, 0.0), Some(4));
        assert_eq!(l.which(0.051, 0.0), Some(5));
        assert_eq!(l.which(0.0, 0.099), Some(4));
        assert_eq!(l.which(0.0, 0.101), Some(7));
        assert_eq!(l.which(0.3, 0.0), None);
    }
}
