//! The length of a straight move, from the axes' positions at its start
//! and end (X, Y and Z; C is a rotation): what the whole reader (`motion`)
//! and the fast path (`modal::fast`) both hold against the machine's feed,
//! so the two measure a move alike.

/// The distance from `start` to `end` over X, Y and Z; `None` when an axis
/// moves from a position the program has not stated yet.
pub(super) fn chord(start: &[Option<f64>; 4], end: &[Option<f64>; 4]) -> Option<f64> {
    let mut sum = 0.0;
    for i in 0..3 {
        match (start[i], end[i]) {
            (Some(p), Some(q)) => sum += (q - p) * (q - p),
            (None, Some(_)) => return None,
            _ => {}
        }
    }
    Some(sum.sqrt())
}
