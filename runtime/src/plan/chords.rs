//! Where a path's programmed points sit across its curve: on the exact
//! tool-centre path, or moved off it so the straight moves between them
//! (the chords) straddle it or stay clear of the material.
//!
//! Between two points the machine moves straight, so wherever the exact
//! path curves around the part (its height, out of the material, bulges
//! above the chord: a convex stretch) the chord cuts below the design by
//! its sag s, up to the chord tolerance. A chord's sag here is signed:
//! the exact path's height above the chord at the chord's middle, positive
//! where the chord gouges, negative where it leaves material.
//!
//! - `OnPath`: every point on the exact path; each chord errs by its sag,
//!   the gouging ones by up to the tolerance.
//! - `Straddle`: each point moved out of the material by half its chords'
//!   sag (the mean of the two chords it joins), so a chord errs by about
//!   +s/2 at its ends and −s/2 at its middle: ±tolerance/2 for the same
//!   points (on a concave stretch the points move into the material, by
//!   half the sag there).
//! - `Clear`: each point raised by the most the path rises above either
//!   chord it joins (0 where neither gouges), so both ends of every chord
//!   are at least that far above the exact path and no chord enters the
//!   material, plus a margin (half the machine's resolution, so rounding
//!   a coordinate to it cannot bring a point back down); the part is left
//!   up to the tolerance proud instead.

/// Where the programmed points sit (the strategy's `chords`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ChordPlacement {
    /// On the exact path: convex stretches gouge by up to the tolerance.
    #[default]
    OnPath,
    /// Off the path by half the sag: every chord within ±tolerance/2.
    Straddle,
    /// Above the path by the sag and `margin` (mm): no chord enters the
    /// material, even once the points are rounded to the resolution.
    Clear { margin: f64 },
}

impl ChordPlacement {
    /// Its word in a strategy.
    pub fn word(self) -> &'static str {
        match self {
            ChordPlacement::OnPath => "on_path",
            ChordPlacement::Straddle => "straddle",
            ChordPlacement::Clear { .. } => "clear",
        }
    }

    /// The placement a strategy's word names; `clear` with `margin` (mm).
    pub fn from_word(word: &str, margin: f64) -> Option<ChordPlacement> {
        match word {
            "on_path" => Some(ChordPlacement::OnPath),
            "straddle" => Some(ChordPlacement::Straddle),
            "clear" => Some(ChordPlacement::Clear { margin }),
            _ => None,
        }
    }

    /// The deepest a chord of sag up to `sag` cuts below the exact path
    /// (mm) with this placement: the sag, half of it, or nothing.
    pub fn promised_gouge(self, sag: f64) -> f64 {
        match self {
            ChordPlacement::OnPath => sag,
            ChordPlacement::Straddle => 0.5 * sag,
            ChordPlacement::Clear { .. } => 0.0,
        }
    }

    /// The first placement, in the order of least displacement, whose
    /// promised gouge for chords of sag up to `sag` is within `max_gouge`
    /// (mm): all three place the same points, so this is the default that
    /// meets a job's `max_gouge` (`Clear` with `margin` when nothing else
    /// does).
    pub fn least_for(sag: f64, max_gouge: f64, margin: f64) -> ChordPlacement {
        [ChordPlacement::OnPath, ChordPlacement::Straddle]
            .into_iter()
            .find(|p| p.promised_gouge(sag) <= max_gouge)
            .unwrap_or(ChordPlacement::Clear { margin })
    }

    /// How far (mm, out of the material) to move a point that ends the
    /// chord `before` and starts the chord `after` (a path's first and last
    /// points have only one), each given by its `Band`: for `Straddle` the
    /// middle of the band the two span together, so every chord's errors
    /// split evenly about the path as far as its neighbour allows; for
    /// `Clear` the most the path rises above either, so both ends of every
    /// chord rise at least as far as the path rises above it.
    pub fn offset(self, before: Option<Band>, after: Option<Band>) -> f64 {
        let both = before.into_iter().chain(after);
        let (hi, lo) = both.fold((0.0f64, 0.0f64), |(h, l), b| (h.max(b.hi), l.min(b.lo)));
        match self {
            ChordPlacement::OnPath => 0.0,
            ChordPlacement::Straddle => 0.5 * (hi + lo),
            ChordPlacement::Clear { margin } => hi + margin,
        }
    }
}

/// How far the exact path lies above a chord (mm): at most `hi`, at least
/// `lo`, the chord's ends (on the path) included, so hi ≥ 0 ≥ lo.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Band {
    pub hi: f64,
    pub lo: f64,
}

impl Band {
    /// The band of heights `d` (mm) of the path above the chord at points
    /// inside it.
    pub fn of(d: &[f64]) -> Band {
        Band {
            hi: d.iter().fold(0.0, |a, &v| a.max(v)),
            lo: d.iter().fold(0.0, |a, &v| a.min(v)),
        }
    }

    /// The band of a chord whose path is `q` (mm) above it at a quarter,
    /// the middle and three quarters of its length: the quartic through
    /// those and its ends, read at 33 points, so a peak between the
    /// quarters (a chord across a change of curvature) is not missed.
    pub fn from_quarters(q: [f64; 3]) -> Band {
        let (a, b, c) = (q[0], q[1], q[2]);
        // Lagrange on t = 0, ¼, ½, ¾, 1 with zeros at both ends.
        let at = |t: f64| {
            let (u0, u1, u2, u3, u4) = (t, t - 0.25, t - 0.5, t - 0.75, t - 1.0);
            a * u0 * u2 * u3 * u4 / (0.25 * -0.25 * -0.5 * -0.75)
                + b * u0 * u1 * u3 * u4 / (0.5 * 0.25 * -0.25 * -0.5)
                + c * u0 * u1 * u2 * u4 / (0.75 * 0.5 * 0.25 * -0.25)
        };
        let d: Vec<f64> = (1..32).map(|k| at(k as f64 / 32.0)).chain(q).collect();
        Band::of(&d)
    }

    /// The larger of two bands (`hi` the higher, `lo` the lower): one
    /// chord in place of two.
    pub fn union(self, other: Band) -> Band {
        Band {
            hi: self.hi.max(other.hi),
            lo: self.lo.min(other.lo),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact path's height above the middle of the chord from v₀ to v₁
    /// between equally spaced points, estimated at each end's curvature: a
    /// chord of length h on a path of second derivative v″ sags by −h² v″ / 8,
    /// and h² v″ is the second difference there. `heights` holds the chord's
    /// ends and one point beyond each, `[v₋₁, v₀, v₁, v₂]`.
    fn uniform_band(heights: [f64; 4]) -> Band {
        let [a, b, c, d] = heights;
        Band::of(&[-(a - 2.0 * b + c) / 8.0, -(b - 2.0 * c + d) / 8.0])
    }

    /// Points on a parabola v = −k u² / 2 (convex: it bulges up), one
    /// unit apart; the exact chord sag is k / 8 everywhere.
    fn parabola(k: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| -k * (i as f64).powi(2) / 2.0).collect()
    }

    /// The largest gouge (exact above the moved chord) and the largest
    /// excess (moved chord above exact) over the chords of `v`, sampled
    /// finely, with each interior point moved by its placement's offset.
    fn errors(placement: ChordPlacement, v: &[f64], k: f64) -> (f64, f64) {
        let n = v.len();
        let bands: Vec<Band> = (1..n - 2)
            .map(|j| uniform_band([v[j - 1], v[j], v[j + 1], v[j + 2]]))
            .collect();
        let (mut gouge, mut excess) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        // Chords 2 ..= n − 4 have both neighbours' bands.
        for j in 2..n - 3 {
            let o0 = placement.offset(Some(bands[j - 2]), Some(bands[j - 1]));
            let o1 = placement.offset(Some(bands[j - 1]), Some(bands[j]));
            for s in 0..=100 {
                let t = s as f64 / 100.0;
                let u = j as f64 + t;
                let exact = -k * u * u / 2.0;
                let chord = (1.0 - t) * (v[j] + o0) + t * (v[j + 1] + o1);
                gouge = gouge.max(exact - chord);
                excess = excess.max(chord - exact);
            }
        }
        (gouge, excess)
    }

    #[test]
    fn each_placement_errs_as_it_promises_on_a_convex_path() {
        let k = 8.0e-6; // sag k/8 = 1 nm (in mm)
        let v = parabola(k, 12);
        let sag = k / 8.0;
        let (g, e) = errors(ChordPlacement::OnPath, &v, k);
        assert!((g - sag).abs() < 1e-12 && e.abs() < 1e-12, "{g} {e}");
        let (g, e) = errors(ChordPlacement::Straddle, &v, k);
        assert!(
            (g - sag / 2.0).abs() < 1e-12 && (e - sag / 2.0).abs() < 1e-12,
            "{g} {e}"
        );
        let (g, e) = errors(ChordPlacement::Clear { margin: 0.0 }, &v, k);
        assert!(g.abs() < 1e-12 && (e - sag).abs() < 1e-12, "{g} {e}");
    }

    #[test]
    fn clear_leaves_a_concave_path_where_it_is() {
        let k = -8.0e-6;
        let v = parabola(k, 12);
        let (g, e) = errors(ChordPlacement::Clear { margin: 0.0 }, &v, k);
        assert!(g.abs() < 1e-12 && (e + k / 8.0).abs() < 1e-12, "{g} {e}");
    }

    #[test]
    fn a_peak_between_the_quarters_is_found() {
        // The path d(t) = t (1 − t) (t − 0.4) · 100 above a chord: zero at
        // 0.4, its peak (0.5794 · 0.4206 · ... ) off every quarter.
        let d = |t: f64| 100.0 * t * (1.0 - t) * (t - 0.4);
        let band = Band::from_quarters([d(0.25), d(0.5), d(0.75)]);
        let fine = Band::of(&(0..=1000).map(|k| d(k as f64 / 1000.0)).collect::<Vec<_>>());
        assert!(
            (band.hi - fine.hi).abs() < 0.01 * fine.hi,
            "{band:?} {fine:?}"
        );
        assert!(
            (band.lo - fine.lo).abs() < 0.01 * -fine.lo,
            "{band:?} {fine:?}"
        );
    }

    #[test]
    fn the_default_is_the_least_displacement_that_meets_max_gouge() {
        let least = ChordPlacement::least_for;
        assert_eq!(least(2.5e-6, 5e-6, 0.0), ChordPlacement::OnPath);
        assert_eq!(least(8e-6, 5e-6, 0.0), ChordPlacement::Straddle);
        assert_eq!(
            least(2.5e-6, 0.0, 5e-7),
            ChordPlacement::Clear { margin: 5e-7 }
        );
        for w in ["on_path", "straddle", "clear"] {
            assert_eq!(ChordPlacement::from_word(w, 0.0).unwrap().word(), w);
        }
    }
}
