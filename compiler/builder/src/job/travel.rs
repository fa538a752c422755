//! The part against the machine's travel before anything is planned: E0141
//! when, to cut the part, the programmed point must go beyond an axis's
//! travel whatever the path. Planning a part that cannot fit takes time
//! that grows with its size (issue #33: an array 4,300 km across hung
//! `lensc check`), and `lensc check` should say what `build` would; the
//! planned moves are still checked against the travel after planning
//! (`context::travel_error`), this check only refuses what no path can
//! cut.

use lensc_grammar::Diagnostic;
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::job::{ControlPoint, Parts};

/// A machine axis whose travel a part is checked against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TravelAxis {
    /// A lathe's X: the radius, the part's distance from the spindle axis.
    Radius,
    /// X, Y or Z on a mill, or a lathe's Z: a position along the axis.
    Along(usize),
}

impl TravelAxis {
    fn index(self) -> usize {
        match self {
            TravelAxis::Radius => 0,
            TravelAxis::Along(i) => i,
        }
    }
    fn name(self) -> &'static str {
        ["X", "Y", "Z", "C"][self.index().min(3)]
    }
}

/// E0141 when the part, spanning `part` (mm, lowest and highest) along
/// `axis`, lies beyond the machine's travel on it even with the tool's
/// reach: the tool's centre meets the part within `tool_radius` of its
/// contact (a nose's, ball's or wheel's radius), and the programmed point
/// lies within the control point's offset of the centre, so a part whose
/// end is farther beyond the travel than both together cannot be cut
/// within it. None where the machine states no travel on the axis, or the
/// part's figures are not numbers (the checks that find those say so).
pub(crate) fn part_beyond_travel(
    p: &Parts,
    axis: TravelAxis,
    part: (f64, f64),
    tool_radius: f64,
) -> Option<Diagnostic> {
    let (lo, hi) = p.machine_params.travel[axis.index()]?;
    let (_, offset) = ControlPoint::of(&p.machine_params, &p.tool_params);
    let control = [offset.x, offset.y, offset.z]
        .get(axis.index())
        .map_or(0.0, |o| o.abs());
    let reach = tool_radius.max(0.0) + control;
    let (end, nearest) = if part.1 - reach > hi {
        (part.1, part.1 - reach)
    } else if part.0 + reach < lo {
        (part.0, part.0 + reach)
    } else {
        return None;
    };
    let name = axis.name();
    let extent = match axis {
        TravelAxis::Radius if end == part.1 && part.1 > 0.0 => format!(
            "the part reaches {} mm from the spindle axis (it is {} mm across)",
            trim_num(end),
            trim_num(2.0 * end)
        ),
        TravelAxis::Radius => format!(
            "the part comes within {} mm of the spindle axis",
            trim_num(end)
        ),
        TravelAxis::Along(_) => format!(
            "the part reaches {name} {} mm (it spans {} .. {} mm)",
            trim_num(end),
            trim_num(part.0),
            trim_num(part.1)
        ),
    };
    let tool = if reach > 0.0 {
        format!(
            "; the tool's programmed point, within {} mm of it, is at {} mm at the nearest",
            trim_num(reach),
            trim_num(nearest)
        )
    } else {
        String::new()
    };
    Some(
        p.error(
            codes::OUT_OF_TRAVEL,
            format!(
                "{extent}{tool}, beyond the machine's {name} travel {} .. {} mm",
                trim_num(lo),
                trim_num(hi)
            ),
        )
        .with_help("check the part's size and its units (`diameter: 60 mm`, not `60 cm`) and where it sits; or use a machine with more travel"),
    )
}
