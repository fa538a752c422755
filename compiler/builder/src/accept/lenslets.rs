//! The acceptance gate lenslet by lenslet: on an array's height map each
//! lenslet's form figures (PV and RMS at its contacts; residual at its
//! contacts or at any cell beyond its scallops; gouge at its contacts or
//! cells) against the whole part's limits, so a lenslet that misses fails
//! the job by name even when the whole part's figures pass (an RMS over
//! many good lenslets hides one bad one, and the nub a spiral leaves on
//! the spindle axis touches no contact).

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use super::{Mode, diagnostic, round_to, shown};
use crate::job::accept::Criterion;
use crate::report::{HeightMap, LensletCriterion, LensletFigure, LensletHeightMap};

/// A criterion's limit as the gate holds the whole part to it (in the
/// report's unit, nm for the form criteria), and where it was stated.
pub(super) type FormLimit = (Criterion, f64, Option<(FileId, Span)>);

/// Each form criterion of `limits` judged on every lenslet of `h` that
/// has contacts; none without lenslets.
pub(super) fn judge(h: &HeightMap, limits: &[FormLimit]) -> Vec<LensletCriterion> {
    let mut judged = Vec::new();
    for &(c, limit, _) in limits {
        let figures: Vec<LensletFigure> = h
            .lenslets
            .iter()
            .filter_map(|l| {
                figure(c, l).map(|measured| LensletFigure {
                    index: l.index,
                    centre_mm: l.centre_mm,
                    measured,
                })
            })
            .collect();
        // The largest, a NaN (a failure) above every number.
        let worst = figures.iter().copied().reduce(|w, f| {
            if f.measured > w.measured || (f.measured.is_nan() && !w.measured.is_nan()) {
                f
            } else {
                w
            }
        });
        let Some(worst) = worst else { continue };
        // A figure NaN is a failure, not a pass.
        let missed: Vec<usize> = figures
            .iter()
            .filter(|f| f.measured.is_nan() || f.measured > limit)
            .map(|f| f.index)
            .collect();
        judged.push(LensletCriterion {
            criterion: c.name(),
            limit,
            judged: figures.len(),
            worst,
            passed: missed.is_empty(),
            missed,
        });
    }
    judged
}

/// A lenslet's figure for `c` (nm): PV and RMS at its contacts; the
/// residual at its contacts or at any cell beyond the scallops beside it
/// (the nub a spiral leaves on the spindle axis has no contact), the
/// larger; gouge the deepest at its contacts or cells. `None` for a
/// criterion that is not a form figure, or a lenslet with no contact.
fn figure(c: Criterion, l: &LensletHeightMap) -> Option<f64> {
    let contact = l.contact.as_ref();
    match c {
        Criterion::FormPv => contact.map(|f| f.pv_nm),
        Criterion::FormRms => contact.map(|f| f.rms_nm),
        Criterion::MaxResidual => l.max_residual_nm(),
        Criterion::MaxGouge => l.max_gouge_nm(),
        Criterion::UncutArea | Criterion::MaxFollowingError | Criterion::MaxCuttingTime => None,
    }
}

/// E0195 (W0020): lenslets that miss a criterion, the worst named (its
/// index and centre) with by how much, and how many miss.
pub(super) fn missed(
    l: &LensletCriterion,
    limits: &[FormLimit],
    job: (FileId, Span),
    mode: Mode,
) -> Diagnostic {
    let stated = limits
        .iter()
        .find(|(c, _, _)| c.name() == l.criterion)
        .and_then(|&(_, _, site)| site);
    let w = &l.worst;
    let others = match l.missed.len() {
        1 => format!("the only one of {} lenslets to miss it", l.judged),
        n => {
            let listed: Vec<String> = l.missed.iter().take(10).map(|i| i.to_string()).collect();
            let more = if n > 10 { ", …" } else { "" };
            format!(
                "the worst of {n} of {} lenslets that miss it: {}{more}",
                l.judged,
                listed.join(", ")
            )
        }
    };
    let message = format!(
        "lenslet {} (centre x = {}, y = {} mm) misses `{}`: {}, over the limit of {} by {} ({others})",
        w.index,
        trim_num(round_to(w.centre_mm[0], 1e-4)),
        trim_num(round_to(w.centre_mm[1], 1e-4)),
        l.criterion,
        shown(w.measured, "nm"),
        shown(l.limit, "nm"),
        shown(w.measured - l.limit, "nm"),
    );
    diagnostic(
        mode,
        (codes::ACCEPTANCE_MISSED, codes::ACCEPTANCE_MISSED_WARNING),
        message,
        stated.unwrap_or(job),
        if stated.is_some() { "this limit" } else { "this job" },
    )
    .with_help("every lenslet of an array is held to the part's limits; the report's `acceptance.lenslets` lists the lenslets that miss, and the height map's `lenslets` each lenslet's figures (index from 0, row by row from the least y)")
}
