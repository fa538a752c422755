//! A strategy's `chords`: where its points sit across the curve of the
//! path (`plan::chords`), as stated or, by default, the placement with the
//! fewest points whose promise meets the job's acceptance criteria (those
//! it states, the rest at their defaults); `clear` with half the machine's
//! resolution to spare for the rounding of the printed points.

use lensc_runtime::plan::chords::{ChordPlacement, FormLimits};

use super::Parts;
use super::accept::{Accept, Criterion};

/// What the placement is chosen for: the path's tolerance, what its chords
/// and fits may spend of it, and whether its chords may be sampled longer.
pub(crate) struct ChordPath {
    /// The strategy's path tolerance (mm), `None` where it has none (the
    /// criteria's defaults then use `accept::DEFAULT_TOLERANCE`).
    pub tolerance: Option<f64>,
    /// The largest sag of a chord on the exact path (mm).
    pub sag: f64,
    /// How far the lines and arcs fitted to the placed points may stray
    /// from them (mm; 0 where nothing is fitted).
    pub fit: f64,
    /// Whether sampling the chords longer (`straddle_long`) writes fewer
    /// blocks: on a path written point by point (a servo spiral), about
    /// 1/√2 of them. Not where lines and arcs are fitted to the points
    /// (a raster, profile turning): the fits run longest through points on
    /// the exact path, and long straddled chords lengthen the program
    /// (seed 000's scraping rasters: 836–2,322 lines on the path, 3,123–
    /// 4,010 straddling long chords); nor on a roller helix, whose points
    /// are a fixed C step apart.
    pub long_chords: bool,
    /// The tolerance the machine's class holds (`Parts::holds`): the
    /// default limits never loosen beyond it.
    pub holds: f64,
}

/// The placement the strategy states, or the default: the fewest points
/// whose promise (`ChordPlacement::promise`: the band its chords and fits
/// keep to about the exact path, so its largest gouge and residual, its PV
/// and a bound on its RMS) meets every form criterion the gate will judge
/// (`ChordPlacement::fewest_points_meeting`). The defaults are ± the
/// tolerance the machine holds (or a tighter path tolerance) and the
/// resolution: at a path tolerance no looser than that, long straddled
/// chords meet them wherever they write fewer blocks; a job that states a
/// tighter `form_rms`, `form_pv` or `max_gouge` keeps every point, on the
/// path, straddling or clear.
pub(crate) fn placement(p: &Parts, path: ChordPath) -> ChordPlacement {
    let resolution = p.machine_params.resolution;
    let margin = 0.5 * resolution;
    if let Some(stated) = p.path.chords {
        // The checker has allowed only the four words.
        return ChordPlacement::from_word(stated.value, margin).unwrap_or_default();
    }
    let accept = super::accept::lower(&p.params).unwrap_or_default();
    let limits = form_limits(&accept, path.tolerance, resolution, path.holds);
    ChordPlacement::fewest_points_meeting(path.sag, path.fit, &limits, margin, path.long_chords)
}

/// The job's limits on the form, stated or default; none under `accept:
/// none`.
fn form_limits(accept: &Accept, tolerance: Option<f64>, resolution: f64, holds: f64) -> FormLimits {
    let limit = |c| {
        accept
            .limit(c, tolerance, resolution, holds)
            .unwrap_or(f64::INFINITY)
    };
    FormLimits {
        max_gouge: limit(Criterion::MaxGouge),
        max_residual: limit(Criterion::MaxResidual),
        form_pv: limit(Criterion::FormPv),
        form_rms: limit(Criterion::FormRms),
    }
}
