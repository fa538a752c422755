//! A strategy's `chords`: where its points sit across the curve of the
//! path (`plan::chords`), as stated or, by default, the least displacement
//! whose promised gouge meets the job's `max_gouge`; `clear` with half the
//! machine's resolution to spare for the rounding of the printed points.

use lensc_runtime::plan::chords::ChordPlacement;

use super::Parts;
use super::accept::Criterion;
use crate::value;

/// The placement the strategy states, or the default for chords whose
/// sag on the exact path is at most `sag` (mm): `on_path` unless the
/// job's stated `max_gouge` is below that sag, then `straddle` if half of
/// it meets the limit, else `clear`. All three place the same points, so
/// the default is also the one with the fewest points that meets the
/// criterion; a job with no stated `max_gouge` keeps its points on the
/// path (the default limit is never below the chord tolerance).
pub(super) fn placement(p: &Parts, sag: f64) -> ChordPlacement {
    fitted_placement(p, sag, 0.0)
}

/// `placement`, for a path whose lines and arcs are then fitted within
/// `fit` (mm) of the placed points: on the path or straddling a fit may
/// pass that much further into the material, clear it may not.
pub(super) fn fitted_placement(p: &Parts, sag: f64, fit: f64) -> ChordPlacement {
    let margin = 0.5 * value::num(&p.machine.fields, "resolution").expect("required");
    if let Some(stated) = value::word(&p.strategy.fields, "chords") {
        // The checker has allowed only the three words.
        return ChordPlacement::from_word(stated, margin).unwrap_or_default();
    }
    let accept = super::accept::lower(p.job).unwrap_or_default();
    match accept.stated(Criterion::MaxGouge) {
        Some(limit) => ChordPlacement::least_for_fitted(sag, fit, limit.value, margin),
        None => ChordPlacement::OnPath,
    }
}
