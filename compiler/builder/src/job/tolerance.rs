//! Whether a strategy's path tolerance can be held at its machine's
//! resolution: E0180 before anything is planned, naming both figures and
//! the smallest tolerance that works.
//!
//! The bound. A path tolerance T is the most the program, as the machine
//! runs it, may stray from the exact tool-centre path. lensc spends half of
//! it on the path it writes (`plan::optimise`: chords T/10, fitting 3T/20,
//! blending T/4; an unoptimised spiral's chords T/4 and blending T/4) and
//! leaves the other half to the machine. The machine cannot stand between
//! its resolution steps q: each printed coordinate is the exact one rounded
//! to a step, off by up to q/2 on each of the n length axes the path moves
//! in, so a printed point may lie (q/2)·√n from the planned one (the
//! corner of an n-cube of side q), and a straight move between two such
//! points no further (each of its points is the same mix of its ends'
//! errors). The worst printed path is then T/2 + (q/2)·√n from the exact
//! one, which is at most T exactly when
//!
//! ```text
//!     T ≥ q·√n
//! ```
//!
//! so q·√n is the smallest tolerance a machine of resolution q holds: 141 nm
//! for a lathe (X, Z) at 0.1 µm, 173 nm for a 3-axis mill at 0.1 µm, 1.41
//! nm for a lathe at 1 nm. The spindle angle C of a servo spiral is not
//! counted: rounding it moves a point along the spiral, the path's own
//! direction, not off it.

use lensc_grammar::Diagnostic;

use super::Parts;
use lensc_lang::codes;

/// The smallest path tolerance (mm) a machine of `resolution` (mm) holds on
/// a path in `axes` length axes: resolution × √axes (see the module's
/// derivation).
pub fn smallest_tolerance(resolution: f64, axes: u32) -> f64 {
    resolution * f64::from(axes).sqrt()
}

/// E0180 if the strategy's stated path tolerance is
/// finer than its machine's resolution can hold on a path printed in
/// `axes` length axes (`Strategy::LENGTH_AXES`); at the tolerance where
/// the strategy (or the one it copies) states it. A default is never
/// refused: it is one the machine holds (`default_path_tolerance`).
pub(crate) fn below_resolution(p: &Parts, axes: u32) -> Option<Diagnostic> {
    let resolution = p.machine_params.resolution;
    // The default is one the machine holds (`default_path_tolerance`).
    let stated = p.path.chord_tolerance?;
    let tolerance = stated.value;
    let smallest = smallest_tolerance(resolution, axes);
    if tolerance >= smallest || !tolerance.is_finite() {
        return None;
    }
    // Figures for people: nm to 6 decimals; a vanishing one as written
    // (1e-12 nm), or in mm if nm cannot state it (5e-324 mm).
    let nm = |v: f64| {
        let exact = lensc_lang::lower::exact_in(v, "nm");
        if v * 1e6 >= 1e-3 {
            format!("{} nm", lensc_lang::check::trim_num(v * 1e6))
        } else if exact.len() <= 17 && v.is_normal() {
            format!("{exact} nm")
        } else {
            format!("{v:e} mm")
        }
    };
    // Rounded up to 0.1 nm, so that the figure suggested is held.
    let suggested = (smallest * 1e7).ceil() / 1e7;
    let message = format!(
        "a path tolerance of {} cannot be held at this machine's resolution ({}): rounding each of the {axes} axes to it can move a printed point {} nm, more than the half of the tolerance left to the machine",
        nm(tolerance),
        nm(resolution),
        lensc_lang::check::trim_num(
            (resolution / 2.0 * f64::from(axes).sqrt() * 1e7).round() / 10.0
        ),
    );
    // Rounded down to 0.001 nm, so that the resolution suggested works.
    let finest = (tolerance / f64::from(axes).sqrt() * 1e9).floor() / 1e3;
    let mut help = format!(
        "state a `chord_tolerance` of at least {} nm (the resolution × √{axes})",
        lensc_lang::check::trim_num(suggested * 1e6),
    );
    if finest > 0.0 {
        help.push_str(&format!(
            ", or use a machine whose resolution is at most {} nm (the tolerance / √{axes})",
            lensc_lang::check::trim_num(finest)
        ));
    }
    let d = Diagnostic::error(
        codes::TOLERANCE_BELOW_RESOLUTION,
        message,
        stated.site.0,
        stated.site.1,
    )
    .with_label(format!(
        "finer than {} nm",
        lensc_lang::check::trim_num(suggested * 1e6)
    ));
    Some(d.with_help(help))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_tolerance_leaves_the_machine_its_rounding() {
        // The issue's figure: 0.1 um on two axes strays up to 70.7 nm.
        let q = 1e-4;
        let t = smallest_tolerance(q, 2);
        assert!((t - 141.421_356e-6).abs() < 1e-12, "{t}");
        // At that tolerance the machine's half holds the rounding exactly.
        assert!((t / 2.0 - q / 2.0 * 2f64.sqrt()).abs() < 1e-18);
        assert!((smallest_tolerance(q, 3) - 173.205_08e-6).abs() < 1e-11);
    }
}
