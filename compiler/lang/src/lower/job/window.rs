//! The size of a job's simulation, checked before planning: the grid its
//! `simulate` window makes in the coordinates of its cut (the one the
//! job's builder sweeps) must not have more cells than the simulation
//! takes (E0149). A default window is always small enough.

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::raster::{Axis, RasterTool};
use lensc_runtime::verify::window::{Window, check_cells};

use super::JobSpec;
use crate::lower::diagnostics::RuntimeError;

/// E0149, at the `simulate` block, when the job's window makes a grid
/// larger than the simulation takes; `None` when it fits, when the job
/// gives no window, or when its strategy simulates no height map.
pub(super) fn check_grid(spec: &JobSpec) -> Option<Diagnostic> {
    let s = spec.head().simulate?;
    let window = Window::given(s.x, s.y, s.spacing);
    // The grid each builder sweeps: a raster's knife along its cut (a
    // ball-end mill is not simulated), a spiral's polar grid, a roller's
    // angle and axial position.
    let grid = match spec {
        JobSpec::Raster(r) => match r.tool {
            RasterTool::Knife { .. } => window.cartesian(r.raster.along == Axis::X),
            RasterTool::Ball { .. } => return None,
        },
        JobSpec::Spiral(_) => window.polar(),
        JobSpec::Roller(r) => window.roller(r.helix.roller_radius),
        JobSpec::Turning(_) | JobSpec::Grinding(_) => return None,
    };
    let e = check_cells(&grid).err()?;
    Some(RuntimeError::Simulation(e).at(s.site))
}
