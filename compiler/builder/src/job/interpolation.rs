//! How a job's program moves the tool between planned points: straight
//! moves and arcs, or the controller's own spline (`interpolation`, the
//! job's or its dialect's default), and E0182 where the spline asked for
//! is one lensc cannot write: the dialect has none (LinuxCNC's G5–G5.2 are
//! in the XY plane only, and no lensc path lies in it; Heidenhain and the
//! ultra-precision lathes are not written yet: docs/controllers/), or the strategy's programs are not fitted yet
//! (raster and profile-turning jobs only, so far).

use lensc_grammar::Diagnostic;
use lensc_lang::codes;
use lensc_runtime::dialect::Dialect;

use super::Parts;

/// The strategies whose programs are fitted with splines.
pub const SPLINE_STRATEGIES: &[&str] = &["raster", "profile_turning"];

/// Whether the job's program is written with splines: as the job says,
/// else as its dialect's default.
pub fn spline(p: &Parts, dialect: &Dialect) -> bool {
    p.params
        .interpolation
        .as_ref()
        .map_or(dialect.spline_by_default, |s| s.value)
}

/// E0182 if the job is to be written with splines that lensc cannot
/// write for its dialect or strategy.
pub fn error(p: &Parts, dialect: &Dialect) -> Option<Diagnostic> {
    if !spline(p, dialect) {
        return None;
    }
    let strategy = p.strategy.kind.name;
    let (message, help) = if dialect.spline.is_none() {
        let with_spline = machine_spline_dialects(p);
        let choose = if with_spline.is_empty() {
            "or give the machine a dialect whose control has a spline lensc writes (`fanuc_0i_mill`: NURBS, G06.2; `siemens_840d_mill` or `_lathe`: BSPLINE) in its `other_dialects`".to_string()
        } else {
            let flags: Vec<String> = with_spline
                .iter()
                .map(|d| format!("`lensc build --dialect {d}`"))
                .collect();
            format!(
                "or build in a dialect of this machine whose control has one: {}",
                flags.join(" or ")
            )
        };
        (
            format!(
                "`interpolation: spline`, but the `{}` dialect has no spline lensc writes",
                dialect.name
            ),
            format!(
                "write `interpolation: lines_arcs`, {choose}; LinuxCNC's G5, G5.1 and G5.2 interpolate in the XY plane only, and Heidenhain's SPL is not written yet (docs/controllers/)"
            ),
        )
    } else if !SPLINE_STRATEGIES.contains(&strategy) {
        (
            format!(
                "`interpolation: spline` for a `{strategy}` job: lensc fits splines to raster and profile-turning jobs only so far"
            ),
            "write `interpolation: lines_arcs` for this job".to_string(),
        )
    } else {
        return None;
    };
    let (file, span) = p
        .params
        .interpolation
        .as_ref()
        .map_or((p.job.file, p.job.name.span), |s| s.site);
    Some(
        Diagnostic::error(codes::SPLINE_NOT_OFFERED, message, file, span)
            .with_label("no spline here")
            .with_help(help),
    )
}

/// The dialects the job's machine offers (its `dialect` and
/// `other_dialects`) in which lensc writes a spline.
fn machine_spline_dialects(p: &Parts) -> Vec<String> {
    lensc_lang::schema::offered_dialects(p.machine)
        .iter()
        .map(|o| o.name().to_string())
        .filter(|name| {
            lensc_lang::lower::dialect(p.job, Some(name)).is_ok_and(|d| d.spline.is_some())
        })
        .collect()
}
