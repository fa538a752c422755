//! A job's simulation window, and its size checked before planning: a
//! range the `simulate` block leaves out is the whole part's (the cut
//! area's extent), and the tiles the window's grid is simulated in (the
//! ones the job's builder sweeps) must not hold more cells, or longer
//! columns, than the simulation takes (E0149): tiles bound its memory,
//! not its time. A default window is always small enough.

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::raster::{Axis, RasterTool};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::verify::window::{Tile, Window, check_cells, split};

use super::{JobHead, JobSpec};
use crate::lower::diagnostics::RuntimeError;

/// The extent (x, y ranges, mm) of what a job cuts: its surface's domain,
/// on a roller only the axial stretch its helix covers.
pub fn part_extent(spec: &JobSpec) -> ((f64, f64), (f64, f64)) {
    let domain = &spec.head().surface.lowered.domain;
    match spec {
        JobSpec::Roller(r) => roller_extent(domain, (r.helix.z_start, r.helix.z_end), r.design_y),
        _ => domain_extent(domain),
    }
}

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
    ))
}

/// The tiles a job's builder simulates `window` in: a raster's knife along
/// its cut (a ball-end mill is not simulated), a spiral's polar grid (its
/// lenslets one by one), a roller's angle and axial position.
pub fn tiles(spec: &JobSpec, window: &Window) -> Option<Vec<Tile>> {
    Some(match spec {
        JobSpec::Raster(r) => match r.tool {
            RasterTool::Knife { .. } => split(&window.cartesian(r.raster.along == Axis::X), None),
            RasterTool::Ball { .. } => return None,
        },
        JobSpec::Spiral(s) => window.polar_tiles(&s.lenslets),
        JobSpec::Roller(r) => split(&window.roller(r.helix.roller_radius, r.helix.y_start), None),
        JobSpec::Turning(_) | JobSpec::Grinding(_) => return None,
    })
}

/// E0149, at the `simulate` block, when the job's window makes tiles
/// tiling cannot bound; `None` when they fit, when the job gives no
/// window, or when its strategy simulates no height map.
pub(super) fn check_grid(spec: &JobSpec) -> Option<Diagnostic> {
    let head = spec.head();
    let window = simulated(head, part_extent(spec))?;
    let e = check_cells(&tiles(spec, &window)?).err()?;
    Some(RuntimeError::Simulation(e).at(head.simulate?.site))
}
