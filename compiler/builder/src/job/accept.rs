//! A job's acceptance criteria, typed: the limits its `accept` block
//! states (the checker has checked each one's dimension and sign), where
//! each was written, or `accept: none`; and the defaults for the criteria
//! a job leaves out (the lowering chooses a path's chord placement by
//! them). The comparison with the simulated part is the build's
//! (lensc-build `accept`): it needs the simulation.

use lensc_grammar::{Diagnostic, FileId, Span};

use lensc_lang::codes;
use lensc_lang::schema::{AcceptParams, JobParams};
use lensc_lang::units::Dim;

/// A figure of the simulated part an `accept` block can limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Criterion {
    /// Peak-to-valley form error at the contacts (mm).
    FormPv,
    /// RMS form error about its mean at the contacts (mm).
    FormRms,
    /// The deepest cut below the design anywhere (mm).
    MaxGouge,
    /// The most material above the design at the contacts (mm).
    MaxResidual,
    /// Area left uncut (mm², or a fraction of the area simulated).
    UncutArea,
    /// The fast tool servo model's largest following error (mm).
    MaxFollowingError,
    /// The estimated cutting time (s).
    MaxCuttingTime,
}

impl Criterion {
    /// Every criterion, in the order reports and messages list them.
    pub const ALL: [Criterion; 7] = [
        Criterion::FormPv,
        Criterion::FormRms,
        Criterion::MaxGouge,
        Criterion::MaxResidual,
        Criterion::UncutArea,
        Criterion::MaxFollowingError,
        Criterion::MaxCuttingTime,
    ];

    /// Its name in an `accept` block.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::FormPv => "form_pv",
            Criterion::FormRms => "form_rms",
            Criterion::MaxGouge => "max_gouge",
            Criterion::MaxResidual => "max_residual",
            Criterion::UncutArea => "uncut_area",
            Criterion::MaxFollowingError => "max_following_error",
            Criterion::MaxCuttingTime => "max_cutting_time",
        }
    }
}

/// A limit an `accept` block states.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limit {
    /// In base units (mm, mm², s), or a fraction for an uncut area given
    /// as a plain number.
    pub value: f64,
    /// An uncut area given as a fraction of the area simulated.
    pub fraction: bool,
    /// Where it was written.
    pub site: (FileId, Span),
}

/// What a job asks of the simulated part.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Accept {
    /// No `accept` block: every criterion at its default.
    #[default]
    Defaults,
    /// The limits stated (the rest at their defaults), and where the
    /// block was written.
    Stated {
        limits: Vec<(Criterion, Limit)>,
        site: (FileId, Span),
    },
    /// `accept: none`: no gate.
    Nothing,
}

impl Accept {
    /// The limit stated for `c`, if any.
    pub fn stated(&self, c: Criterion) -> Option<&Limit> {
        match self {
            Accept::Stated { limits, .. } => limits.iter().find(|(k, _)| *k == c).map(|(_, l)| l),
            _ => None,
        }
    }
}

/// The path tolerance the defaults are derived from for a strategy that
/// plans to none of its own (roller helix, profile grinding): the default
/// `chord_tolerance` of the others (mm).
pub const DEFAULT_TOLERANCE: f64 = super::DEFAULT_PATH_TOLERANCE;

/// The default limit of `c` (in its base unit) for a strategy planned to
/// `tolerance` (mm; `None`: it has none of its own, and
/// `DEFAULT_TOLERANCE` stands in) on a machine of `resolution` (mm) whose
/// class holds `holds` (mm: the tolerance a job that states none is
/// planned to, `job::default_path_tolerance`, 10 nm or the least its
/// resolution holds): the path's chords stray up to the tolerance from
/// the exact path, and the printed coordinates up to half the resolution
/// on each axis, so the form error lies within ±(T + resolution), T the
/// path's tolerance but never more than the machine holds (a looser
/// `chord_tolerance` plans a looser path; it does not loosen what the part
/// is held to): PV twice that, RMS a quarter of the PV, a gouge, a
/// residual or a fast tool servo's following error (which the form
/// figures, simulated from the commands, leave out) at most that. Nothing
/// is left uncut. The cutting time has no default (a job states it).
pub fn default_limit(
    c: Criterion,
    tolerance: Option<f64>,
    resolution: f64,
    holds: f64,
) -> Option<f64> {
    let band = tolerance.unwrap_or(DEFAULT_TOLERANCE).min(holds) + resolution;
    match c {
        Criterion::FormPv => Some(2.0 * band),
        Criterion::FormRms => Some(band / 2.0),
        Criterion::MaxGouge | Criterion::MaxResidual | Criterion::MaxFollowingError => Some(band),
        Criterion::UncutArea => Some(0.0),
        Criterion::MaxCuttingTime => None,
    }
}

impl Accept {
    /// The limit the gate holds `c` to (base unit): the one stated, else
    /// its default (`default_limit`); none under `accept: none`. An uncut
    /// area stated as a fraction is returned as that fraction.
    pub fn limit(
        &self,
        c: Criterion,
        tolerance: Option<f64>,
        resolution: f64,
        holds: f64,
    ) -> Option<f64> {
        match self {
            Accept::Nothing => None,
            _ => match self.stated(c) {
                Some(l) => Some(l.value),
                None => default_limit(c, tolerance, resolution, holds),
            },
        }
    }
}

/// The job's `accept` block, typed; E0123 for an uncut fraction above 1
/// (the checker has refused wrong dimensions, negative limits and unknown
/// names).
pub(crate) fn lower(params: &JobParams) -> Result<Accept, Diagnostic> {
    let (criteria, block_site) = match &params.accept {
        AcceptParams::Defaults => return Ok(Accept::Defaults),
        AcceptParams::Nothing => return Ok(Accept::Nothing),
        AcceptParams::Stated { criteria, site } => (criteria, *site),
    };
    let mut limits = Vec::new();
    for c in Criterion::ALL {
        let Some((_, stated)) = criteria.iter().find(|(name, _)| *name == c.name()) else {
            continue;
        };
        let ((v, dim), (file, span)) = (stated.value, stated.site);
        let fraction = c == Criterion::UncutArea && dim == Dim::NONE;
        if fraction && v > 1.0 {
            return Err(Diagnostic::error(
                codes::OUT_OF_RANGE,
                format!(
                    "`uncut_area` as a plain number is a fraction of the area simulated, at most 1, but it is {}",
                    lensc_lang::check::trim_num(v)
                ),
                file,
                span,
            )
            .with_label("more than the whole")
            .with_help("give a fraction from 0 to 1, or an area with its unit, as in `0.01 mm^2`"));
        }
        limits.push((
            c,
            Limit {
                value: v,
                fraction,
                site: (file, span),
            },
        ));
    }
    Ok(Accept::Stated {
        limits,
        site: block_site,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const NM: f64 = 1e-6;

    #[test]
    fn a_looser_tolerance_does_not_widen_the_defaults() {
        // A lathe at 1 nm holds 10 nm: a 10 mm tolerance (the sphere
        // turned as a cone of issue #29) is held to 2 × (10 + 1) nm PV,
        // as a job that states none; a tighter 4 nm tightens them.
        let pv = |t: Option<f64>| default_limit(Criterion::FormPv, t, NM, 10.0 * NM).unwrap();
        assert!((pv(Some(10.0)) - 22.0 * NM).abs() < 1e-12);
        assert!((pv(Some(200.0 * NM)) - 22.0 * NM).abs() < 1e-12);
        assert_eq!(pv(None), pv(Some(10.0)));
        assert!((pv(Some(4.0 * NM)) - 10.0 * NM).abs() < 1e-12);
        // A machine that holds only 142 nm (0.1 µm, two axes): that band.
        let coarse = default_limit(Criterion::MaxGouge, Some(1.0), 100.0 * NM, 142.0 * NM);
        assert!((coarse.unwrap() - 242.0 * NM).abs() < 1e-12);
    }

    #[test]
    fn the_following_error_has_a_default_and_the_cutting_time_none() {
        let fe = default_limit(Criterion::MaxFollowingError, Some(50.0 * NM), NM, 10.0 * NM);
        assert!((fe.unwrap() - 11.0 * NM).abs() < 1e-12);
        assert_eq!(
            default_limit(Criterion::MaxCuttingTime, None, NM, 10.0 * NM),
            None
        );
        // `accept: none` holds nothing, a stated limit wins.
        assert_eq!(
            Accept::Nothing.limit(Criterion::FormPv, None, NM, 10.0 * NM),
            None
        );
    }
}
