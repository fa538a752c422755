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
//!   half the sag there). Where a chord bending one way meets one bending
//!   the other no shared offset splits both, so `straddle` splits the
//!   chords left beyond ±tolerance/2 until none is.
//! - `StraddleLong`: the chords sampled to twice the tolerance (about √2
//!   longer, fewer points), then straddled: ±tolerance, as on the path.
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
    /// Chords sampled to twice the sag (about √2 longer, fewer points),
    /// straddling: every chord within ±tolerance, the largest error of
    /// points on the path, with about 1/√2 of their number.
    StraddleLong,
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
            ChordPlacement::StraddleLong => "straddle_long",
            ChordPlacement::Clear { .. } => "clear",
        }
    }

    /// The placement a strategy's word names; `clear` with `margin` (mm).
    pub fn from_word(word: &str, margin: f64) -> Option<ChordPlacement> {
        match word {
            "on_path" => Some(ChordPlacement::OnPath),
            "straddle" => Some(ChordPlacement::Straddle),
            "straddle_long" => Some(ChordPlacement::StraddleLong),
            "clear" => Some(ChordPlacement::Clear { margin }),
            _ => None,
        }
    }

    /// How many times the chords' share its chords are sampled to: 2 for
    /// `StraddleLong`, else 1.
    pub fn sag_factor(self) -> f64 {
        if self == ChordPlacement::StraddleLong {
            2.0
        } else {
            1.0
        }
    }

    /// Whether the points straddle the path (`chords::straddle`).
    pub fn straddles(self) -> bool {
        matches!(
            self,
            ChordPlacement::Straddle | ChordPlacement::StraddleLong
        )
    }

    /// What this placement guarantees of the path it writes, for chords
    /// whose sag on the exact path is at most `sag` (mm) and lines and
    /// arcs then fitted within `fit` (mm) of the placed points
    /// (`plan::optimise`; 0 where nothing is fitted). On the path a chord
    /// cuts below it by its sag on a convex stretch and passes above it by
    /// its sag on a concave one; straddling, half of that either way;
    /// straddling long chords (sampled to twice the sag), the sag either
    /// way; clear, nothing below and up to the sag and the margin above. A
    /// fit may pass `fit` further either way, except that a clear path's
    /// fits are held above its points.
    pub fn promise(self, sag: f64, fit: f64) -> Promise {
        let (below, above) = match self {
            ChordPlacement::OnPath | ChordPlacement::StraddleLong => (sag + fit, sag + fit),
            ChordPlacement::Straddle => (0.5 * sag + fit, 0.5 * sag + fit),
            ChordPlacement::Clear { margin } => (0.0, sag + margin + fit),
        };
        Promise { below, above }
    }

    /// The first placement, in the order of least displacement, whose
    /// promised gouge for chords of sag up to `sag` is within `max_gouge`
    /// (mm): all three place the same points, so this is the default that
    /// meets a job's `max_gouge` (`Clear` with `margin` when nothing else
    /// does).
    pub fn least_for(sag: f64, max_gouge: f64, margin: f64) -> ChordPlacement {
        ChordPlacement::least_for_fitted(sag, 0.0, max_gouge, margin)
    }

    /// `least_for`, for a path whose lines and arcs are then fitted within
    /// `fit` (mm) of the placed points (`plan::optimise`): on the path or
    /// straddling, a fit may pass that much further into the material;
    /// clear, no fit passes below the placed points.
    pub fn least_for_fitted(sag: f64, fit: f64, max_gouge: f64, margin: f64) -> ChordPlacement {
        [ChordPlacement::OnPath, ChordPlacement::Straddle]
            .into_iter()
            .find(|p| p.promise(sag, fit).below <= max_gouge)
            .unwrap_or(ChordPlacement::Clear { margin })
    }

    /// The default placement: the one with the fewest points whose promise
    /// (`promise`) meets every one of `limits`. Straddling long chords
    /// (where `long_chords` allows them: not on a roller helix, whose
    /// points are a fixed C step apart) samples about 1/√2 of the points;
    /// the other three sample the same points (straddling may split a few
    /// at inflections) and are taken in the order of least displacement:
    /// on the path, straddling, clear. Where no placement's promise meets
    /// them all, the least displacement whose promise meets `max_gouge`
    /// (the simulation then measures the rest, and the gate judges).
    pub fn fewest_points_meeting(
        sag: f64,
        fit: f64,
        limits: &FormLimits,
        margin: f64,
        long_chords: bool,
    ) -> ChordPlacement {
        let long = long_chords.then_some(ChordPlacement::StraddleLong);
        let same_points = [
            ChordPlacement::OnPath,
            ChordPlacement::Straddle,
            ChordPlacement::Clear { margin },
        ];
        long.into_iter()
            .chain(same_points)
            .find(|p| limits.met_by(&p.promise(sag, fit)))
            .unwrap_or_else(|| ChordPlacement::least_for_fitted(sag, fit, limits.max_gouge, margin))
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
            ChordPlacement::Straddle | ChordPlacement::StraddleLong => 0.5 * (hi + lo),
            ChordPlacement::Clear { margin } => hi + margin,
        }
    }
}

/// What a placement guarantees of the path it writes (mm): how far below
/// the exact path (into the material) and how far above it any point of
/// its chords and fits can lie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Promise {
    /// The deepest below the path: the largest gouge.
    pub below: f64,
    /// The highest above it: the largest residual.
    pub above: f64,
}

impl Promise {
    /// The peak-to-valley of the error: at most the band's width.
    pub fn pv(&self) -> f64 {
        self.below + self.above
    }

    /// The RMS of the error about its mean: at most half the band's width
    /// (Popoviciu's inequality: a quantity within [a, b] varies about its
    /// mean by at most (b − a)/2), whatever the chords' lengths.
    pub fn rms(&self) -> f64 {
        0.5 * self.pv()
    }
}

/// The limits a job holds its form to (mm), as the placement's promise is
/// judged against them: `f64::INFINITY` where it sets none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormLimits {
    pub max_gouge: f64,
    pub max_residual: f64,
    pub form_pv: f64,
    pub form_rms: f64,
}

impl FormLimits {
    /// Whether `promise` is within every limit (a figure equal to its
    /// limit but for the last digits of the units' scaling, 25 nm against
    /// `25 nm`, is within it).
    pub fn met_by(&self, promise: &Promise) -> bool {
        let within = |figure: f64, limit: f64| figure <= limit * (1.0 + 1e-12);
        within(promise.below, self.max_gouge)
            && within(promise.above, self.max_residual)
            && within(promise.pv(), self.form_pv)
            && within(promise.rms(), self.form_rms)
    }
}

/// Moves each point of a path that is a graph z(u) (`pts`, its points
/// (u, z) in order) out of the material by its placement's offset, given
/// the band of each chord (`bands[j]` of the chord from point j to j + 1).
/// The path's first and last points have one chord each.
pub fn place_graph(placement: ChordPlacement, pts: &mut [(f64, f64)], bands: &[Band]) {
    if placement == ChordPlacement::OnPath {
        return;
    }
    let offsets: Vec<f64> = (0..pts.len())
        .map(|i| {
            let before = i.checked_sub(1).and_then(|j| bands.get(j)).copied();
            placement.offset(before, bands.get(i).copied())
        })
        .collect();
    for (p, o) in pts.iter_mut().zip(offsets) {
        p.1 += o;
    }
}

/// A programmed point of a path that is a graph z(u): at parameter `s`
/// of the exact path, at (u, z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knot {
    pub s: f64,
    pub u: f64,
    pub z: f64,
}

/// How many heights `Band::samples` reads along a chord.
const SAMPLES: usize = 34;

/// A chord between two knots, with the exact path at a quarter, half and
/// three quarters of the way between their parameters, the heights read
/// off the quartic through them, and the last check of its error.
#[derive(Clone, Copy, Debug)]
struct Span {
    inner: [Knot; 3],
    band: Band,
    samples: [(f64, f64); SAMPLES],
    /// The end offsets last checked and the error they gave.
    checked: Option<(f64, f64, f64)>,
}

impl Span {
    fn new(a: &Knot, b: &Knot, inner: [Knot; 3]) -> Span {
        let samples = Band::samples((a.u, a.z), (b.u, b.z), inner.map(|k| (k.u, k.z)));
        Span {
            inner,
            band: Band::of(&samples.map(|s| s.1)),
            samples,
            checked: None,
        }
    }

    /// The largest error either way of the chord with its ends moved up by
    /// `o0` and `o1`: the path's height above it, read off the quartic
    /// through the three inner points and the ends.
    fn worst(&mut self, o0: f64, o1: f64) -> f64 {
        if let Some((c0, c1, e)) = self.checked
            && c0 == o0
            && c1 == o1
        {
            return e;
        }
        let e = self
            .samples
            .iter()
            .map(|&(t, d)| (d - ((1.0 - t) * o0 + t * o1)).abs())
            .fold(o0.abs().max(o1.abs()), f64::max);
        self.checked = Some((o0, o1, e));
        e
    }
}

/// What straddling a path did: the chords split where their neighbours
/// bent the other way, and the largest error left either way (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Straddled {
    pub splits: usize,
    pub worst: f64,
}

/// Rounds of splitting before straddling gives up on a chord (each halves
/// the chords it splits, quartering their sag).
const SPLIT_ROUNDS: usize = 24;

/// The most knots straddling may add to a path, as a multiple of the knots
/// it was given (plus a few): where the exact path is not smooth enough for
/// halving to bring its chords within the bound (a cliff at a lenslet's
/// rim with no settling), every round would double the chords there, and
/// 24 rounds of doubling are millions of knots. Smooth paths add a few
/// percent (seed 003's array none, the waves 7 %).
const MAX_ADDED_KNOTS_PER_KNOT: usize = 1;

/// Places the knots of a path (on the exact path, in order) so that every
/// chord errs by at most `bound` (mm) either way: each knot moved up by the
/// middle of the band its chords span together (`ChordPlacement::offset`),
/// the first and last by `pins` where given (a knot another run shares).
/// Where chords bending opposite ways meet, no shared offset splits both
/// (a chord of sag s beside one of sag −s needs its end at +s/2 and −s/2
/// at once): each chord left beyond the bound is split at its middle, as
/// is any neighbour whose band exceeds the bound, and the offsets are found
/// again, until every chord is within it or `can_split` refuses (a servo's
/// data period), or the knots would more than double (a path no halving
/// brings within the bound: `Straddled::worst` then says how far it is
/// left). `exact(s)` is the exact path's (u, z) at parameter s.
pub fn straddle(
    knots: &[Knot],
    pins: (Option<f64>, Option<f64>),
    bound: f64,
    exact: &mut dyn FnMut(f64) -> (f64, f64),
    can_split: &dyn Fn(&Knot, &Knot) -> bool,
) -> (Vec<Knot>, Straddled) {
    let mut at = |s: f64| {
        let (u, z) = exact(s);
        Knot { s, u, z }
    };
    let mut knots = knots.to_vec();
    if knots.len() < 2 {
        return (knots, Straddled::default());
    }
    let quarters = |a: &Knot, b: &Knot, at: &mut dyn FnMut(f64) -> Knot| {
        [0.25, 0.5, 0.75].map(|f| at(a.s + f * (b.s - a.s)))
    };
    let mut spans: Vec<Span> = knots
        .windows(2)
        .map(|w| Span::new(&w[0], &w[1], quarters(&w[0], &w[1], &mut at)))
        .collect();
    let mut summary = Straddled::default();
    let mut offsets = Vec::new();
    let max_knots = knots.len() * (1 + MAX_ADDED_KNOTS_PER_KNOT) + 64;
    for round in 0..=SPLIT_ROUNDS {
        let n = knots.len();
        offsets = (0..n)
            .map(|i| {
                let before = i.checked_sub(1).map(|j| spans[j].band);
                let after = spans.get(i).map(|sp| sp.band);
                match (i, pins) {
                    (0, (Some(o), _)) => o,
                    (i, (_, Some(o))) if i == n - 1 => o,
                    _ => ChordPlacement::Straddle.offset(before, after),
                }
            })
            .collect();
        let errors: Vec<f64> = (0..n - 1)
            .map(|j| spans[j].worst(offsets[j], offsets[j + 1]))
            .collect();
        let over = |e: f64| e > bound * (1.0 + 1e-9);
        let wide = |b: Band| over(b.hi.max(-b.lo));
        let mut split = vec![false; n - 1];
        for j in (0..n - 1).filter(|&j| over(errors[j])) {
            split[j] = true;
            if j > 0 && wide(spans[j - 1].band) {
                split[j - 1] = true;
            }
            if j + 2 < n && wide(spans[j + 1].band) {
                split[j + 1] = true;
            }
        }
        for (j, s) in split.iter_mut().enumerate() {
            *s = *s && can_split(&knots[j], &knots[j + 1]);
        }
        let splits = split.iter().filter(|&&s| s).count();
        let too_many = n + splits > max_knots;
        if round == SPLIT_ROUNDS || splits == 0 || too_many {
            summary.worst = errors.into_iter().fold(0.0, f64::max);
            break;
        }
        let mut new_knots = Vec::with_capacity(n + 8);
        let mut new_spans = Vec::with_capacity(n + 8);
        for j in 0..n - 1 {
            let (a, b) = (knots[j], knots[j + 1]);
            new_knots.push(a);
            if split[j] {
                let sp = spans[j];
                let mid = sp.inner[1];
                let eighth = |f: f64, at: &mut dyn FnMut(f64) -> Knot| at(a.s + f * (b.s - a.s));
                let left = [eighth(0.125, &mut at), sp.inner[0], eighth(0.375, &mut at)];
                let right = [eighth(0.625, &mut at), sp.inner[2], eighth(0.875, &mut at)];
                new_spans.push(Span::new(&a, &mid, left));
                new_knots.push(mid);
                new_spans.push(Span::new(&mid, &b, right));
                summary.splits += 1;
            } else {
                new_spans.push(spans[j]);
            }
        }
        new_knots.push(knots[n - 1]);
        knots = new_knots;
        spans = new_spans;
    }
    for (k, o) in knots.iter_mut().zip(offsets) {
        k.z += o;
    }
    (knots, summary)
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

    /// The band of the chord from `a` to `b`, points (u, z) of a path
    /// that is a graph z(u), given three points of the exact path between
    /// them in order along u: each one's height above the chord at its own
    /// u, read off the quartic through those and the chord's ends (zero
    /// there) at 33 points. Where the points do not advance along u (a
    /// chord standing upright), their heights alone.
    pub fn between(a: (f64, f64), b: (f64, f64), inner: [(f64, f64); 3]) -> Band {
        Band::of(&Band::samples(a, b, inner).map(|s| s.1))
    }

    /// The heights (t, d) `between` reads: the fraction t of the chord
    /// along u and the path's height d above it there.
    fn samples(a: (f64, f64), b: (f64, f64), inner: [(f64, f64); 3]) -> [(f64, f64); SAMPLES] {
        let span = b.0 - a.0;
        let t = inner.map(|p| (p.0 - a.0) / span);
        let d: [f64; 3] = std::array::from_fn(|k| inner[k].1 - (a.1 + t[k] * (b.1 - a.1)));
        let nodes = [0.0, t[0], t[1], t[2], 1.0];
        let values = [0.0, d[0], d[1], d[2], 0.0];
        let advancing = span != 0.0
            && span.is_finite()
            && nodes.windows(2).all(|w| w[1] > w[0])
            && d.iter().all(|v| v.is_finite());
        // The chord's ends (the path on them) fill what is not read.
        let mut out = [(0.0, 0.0); SAMPLES];
        if !advancing {
            for k in 0..3 {
                let tk = if t[k].is_finite() {
                    t[k].clamp(0.0, 1.0)
                } else {
                    0.5
                };
                out[k] = (tk, if d[k].is_finite() { d[k] } else { 0.0 });
            }
            return out;
        }
        let at = |x: f64| {
            let mut sum = 0.0;
            for k in 1..4 {
                let mut w = values[k];
                for m in 0..5 {
                    if m != k {
                        w *= (x - nodes[m]) / (nodes[k] - nodes[m]);
                    }
                }
                sum += w;
            }
            sum
        };
        for k in 1..32 {
            let x = k as f64 / 32.0;
            out[k - 1] = (x, at(x));
        }
        for k in 0..3 {
            out[31 + k] = (t[k], d[k]);
        }
        out
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

    /// The largest error either way of the chords between `knots` against
    /// the exact path `z(u)`, at 201 points along each.
    fn graph_errors(knots: &[Knot], z: impl Fn(f64) -> f64) -> f64 {
        knots
            .windows(2)
            .flat_map(|w| {
                (0..=200).map(move |k| {
                    let t = k as f64 / 200.0;
                    let u = w[0].u + t * (w[1].u - w[0].u);
                    (w[0].z + t * (w[1].z - w[0].z), u)
                })
            })
            .map(|(chord, u)| (chord - z(u)).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn straddling_a_rough_path_stops_before_the_knots_more_than_double() {
        // A path rough at every scale (heights up to 1 µm, a hash of u): no
        // halving brings its chords within 1 nm, so every round would split
        // every chord again (down to 1e-4 here, about 10,000 knots; a
        // fast-tool-servo revolution at a few rpm allows millions). The
        // knots stop at twice those given (plus a few), and the worst
        // error left is reported.
        let rough = |u: f64| 1e-3 * ((u * 12_345.678).sin() * 43_758.545_3).rem_euclid(1.0);
        let knots: Vec<Knot> = (0..=20)
            .map(|i| {
                let u = f64::from(i) / 20.0;
                Knot {
                    s: u,
                    u,
                    z: rough(u),
                }
            })
            .collect();
        let mut exact = |u: f64| (u, rough(u));
        let (placed, summary) = straddle(&knots, (None, None), 1e-6, &mut exact, &|a, b| {
            b.s - a.s > 1e-4
        });
        assert!(placed.len() <= 2 * knots.len() + 64, "{}", placed.len());
        assert!(summary.splits > 0 && summary.worst > 1e-6, "{summary:?}");
        assert!(placed.iter().all(|k| k.z.is_finite()));
    }

    #[test]
    fn straddling_holds_half_the_sag_through_inflections() {
        // A sine 1 µm high, sampled as the planners sample: chords halved
        // until their middles are within 40 nm, so around the inflections,
        // where the sine is nearly straight, they are long and sag as much
        // as at the crests, one way beside the other.
        let amp = 1e-3;
        let z = |u: f64| amp * u.sin();
        let sag = 40e-6;
        let mut knots = vec![Knot {
            s: 0.0,
            u: 0.0,
            z: 0.0,
        }];
        // Seeds twice the crests' chord apart (√(8 · sag / amp) = 0.566).
        let width = 2.0 * (8.0 * sag / amp).sqrt() * 0.999;
        for seed in 0..18 {
            let a = seed as f64 * width;
            let mut stack = vec![(a, a + width)];
            while let Some((a, b)) = stack.pop() {
                let m = 0.5 * (a + b);
                if (z(m) - 0.5 * (z(a) + z(b))).abs() > sag {
                    stack.push((m, b));
                    stack.push((a, m));
                } else {
                    knots.push(Knot {
                        s: b,
                        u: b,
                        z: z(b),
                    });
                }
            }
        }
        assert!(graph_errors(&knots, z) > 0.9 * sag);
        // Each point moved by the middle of its chords' band alone: beyond
        // half the sag at the inflections (22.3 nm, 0.56 of it).
        let bands: Vec<Band> = knots
            .windows(2)
            .map(|w| {
                let inner = [0.25, 0.5, 0.75].map(|f| {
                    let u = w[0].u + f * (w[1].u - w[0].u);
                    (u, z(u))
                });
                Band::between((w[0].u, w[0].z), (w[1].u, w[1].z), inner)
            })
            .collect();
        let mut graph: Vec<(f64, f64)> = knots.iter().map(|k| (k.u, k.z)).collect();
        place_graph(ChordPlacement::Straddle, &mut graph, &bands);
        let moved: Vec<Knot> = graph.iter().map(|&(u, z)| Knot { s: u, u, z }).collect();
        let unsplit = graph_errors(&moved, z);
        assert!(unsplit > 0.55 * sag, "{unsplit}");
        // Straddled, chords split where that cannot hold: within half the
        // sag everywhere.
        let mut exact = |s: f64| (s, z(s));
        let (placed, summary) = straddle(&knots, (None, None), 0.5 * sag, &mut exact, &|_, _| true);
        let err = graph_errors(&placed, z);
        assert!(err <= 0.5 * sag * 1.001, "{err} {summary:?}");
        assert!(
            (summary.worst - err).abs() < 0.01 * sag,
            "{err} {summary:?}"
        );
        assert!(summary.splits > 0 && placed.len() == knots.len() + summary.splits);
        // Pinned ends stay where they are pinned.
        let (pinned, _) = straddle(
            &knots,
            (Some(0.0), Some(0.0)),
            0.5 * sag,
            &mut exact,
            &|_, _| true,
        );
        assert_eq!(pinned[0], knots[0]);
        assert_eq!(pinned[pinned.len() - 1], knots[knots.len() - 1]);
        assert!(graph_errors(&pinned, z) <= 0.5 * sag * 1.001);
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
        for w in ["on_path", "straddle", "straddle_long", "clear"] {
            assert_eq!(ChordPlacement::from_word(w, 0.0).unwrap().word(), w);
        }
    }

    /// Limits in nm, as `FormLimits` in mm.
    fn limits_nm(gouge: f64, residual: f64, pv: f64, rms: f64) -> FormLimits {
        FormLimits {
            max_gouge: gouge * 1e-6,
            max_residual: residual * 1e-6,
            form_pv: pv * 1e-6,
            form_rms: rms * 1e-6,
        }
    }

    #[test]
    fn each_promise_is_the_band_its_chords_keep_to() {
        let nm = |p: Promise| [p.below, p.above, p.pv(), p.rms()].map(|v| v * 1e6);
        let sag = 40e-6;
        let fit = 60e-6;
        let margin = 0.5e-6;
        let close = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
        assert!(close(
            nm(ChordPlacement::OnPath.promise(sag, fit)),
            [100.0, 100.0, 200.0, 100.0]
        ));
        assert!(close(
            nm(ChordPlacement::Straddle.promise(sag, fit)),
            [80.0, 80.0, 160.0, 80.0]
        ));
        assert!(close(
            nm(ChordPlacement::StraddleLong.promise(sag, fit)),
            [100.0, 100.0, 200.0, 100.0]
        ));
        assert!(close(
            nm(ChordPlacement::Clear { margin }.promise(sag, fit)),
            [0.0, 100.5, 100.5, 50.25]
        ));
    }

    #[test]
    fn the_default_is_the_fewest_points_whose_promise_meets_every_criterion() {
        let choose = |limits: FormLimits, long| {
            ChordPlacement::fewest_points_meeting(50e-6, 0.0, &limits, 5e-7, long)
        };
        // A servo spiral whose chords take 50 nm of a 200 nm tolerance, at
        // the default limits (T + r = 201 nm): long straddled chords
        // promise ±50 nm, within all of them.
        let defaults = limits_nm(201.0, 201.0, 402.0, 100.5);
        assert_eq!(choose(defaults, true), ChordPlacement::StraddleLong);
        // Where they are not offered, the least displacement.
        assert_eq!(choose(defaults, false), ChordPlacement::OnPath);
        // A 30 nm gouge limit: only straddling (±25 nm) or clear meet it.
        let gouge_30 = FormLimits {
            max_gouge: 30e-6,
            ..defaults
        };
        assert_eq!(choose(gouge_30, true), ChordPlacement::Straddle);
        // A 25 nm RMS: half the band of ±25 nm, straddled; 20 nm, none
        // promises it (clear's band is 50.5 nm), so on the path.
        let rms = |nm: f64| FormLimits {
            form_rms: nm * 1e-6,
            ..defaults
        };
        assert_eq!(choose(rms(25.0), true), ChordPlacement::Straddle);
        assert_eq!(choose(rms(20.0), true), ChordPlacement::OnPath);
        // No gouge: clear, whose promise meets the rest too.
        let no_gouge = FormLimits {
            max_gouge: 0.0,
            ..defaults
        };
        assert_eq!(
            choose(no_gouge, true),
            ChordPlacement::Clear { margin: 5e-7 }
        );
        // Seed 003's stated 5 nm PV, 1 nm RMS and 5 nm gouge on chords of
        // 2.5 nm: no promise holds 1 nm RMS, so the least displacement
        // whose gouge is within 5 nm, on the path (the simulation measures
        // 0.36 nm RMS, and the gate judges).
        let seed_003 = limits_nm(5.0, 11.0, 5.0, 1.0);
        assert_eq!(
            ChordPlacement::fewest_points_meeting(2.5e-6, 0.0, &seed_003, 5e-7, true),
            ChordPlacement::OnPath
        );
    }
}
