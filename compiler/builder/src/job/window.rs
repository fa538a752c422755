//! A job's simulation window, and its size checked before planning: a
//! range the `simulate` block leaves out is the whole part's (the cut
//! area's extent), and the tiles the window's grid is simulated in (the
//! ones the job's builder sweeps) must not hold more cells, or longer
//! columns, than the simulation takes (E0149): tiles bound its memory,
//! not its time. A default window (the whole part, at a spacing chosen
//! for it: `height_map::window`) is always small enough.

use lensc_grammar::Diagnostic;
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::verify::window::{Window, check_cells};

use super::JobHead;
use crate::diagnostics::RuntimeError;

/// The extent of a surface's domain (x, y ranges, mm).
pub fn domain_extent(domain: &Domain) -> ((f64, f64), (f64, f64)) {
    match *domain {
        Domain::Circle { radius: r } | Domain::Annulus { outer: r, .. } => ((-r, r), (-r, r)),
        Domain::Rect { x, y } => (x, y),
    }
}

/// The extent of a roller's cut in design coordinates: the axial stretch
/// `z` of its helix within the domain, and all the way round (`design_y`).
pub fn roller_extent(
    domain: &Domain,
    z: (f64, f64),
    design_y: (f64, f64),
) -> ((f64, f64), (f64, f64)) {
    let x = domain_extent(domain).0;
    ((x.0.max(z.0.min(z.1)), x.1.min(z.0.max(z.1))), design_y)
}

/// The window a job's `simulate` block gives, its left-out ranges the
/// part's `extent`; `None` without a block.
pub fn simulated(head: &JobHead, extent: ((f64, f64), (f64, f64))) -> Option<Window> {
    let s = head.simulate?;
    Some(Window::given(
        s.x.unwrap_or(extent.0),
        s.y.unwrap_or(extent.1),
        s.spacing,
        extent,
    ))
}

/// E0149, at the `simulate` block, when the job's window (its left-out
/// ranges the part's `extent`) makes tiles (`tiles`, the strategy's)
/// tiling cannot bound; `None` when they fit, when the job gives no
/// window, or when its strategy simulates no height map.
pub(crate) fn check_grid(
    head: &JobHead,
    extent: ((f64, f64), (f64, f64)),
    tiles: impl FnOnce(&Window) -> Option<Vec<lensc_runtime::verify::window::Tile>>,
) -> Option<Diagnostic> {
    let window = simulated(head, extent)?;
    let e = check_cells(&tiles(&window)?).err()?;
    Some(RuntimeError::Simulation(e).at(head.simulate?.site))
}
