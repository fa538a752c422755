//! Plain text: x y z points (a point cloud, `.xyz`, `.csv`) and x z
//! stylus profiles, one point per line, numbers separated by spaces, tabs,
//! commas or semicolons. A first line that is not numbers is a header;
//! lines starting with `#`, `%` or `;` are comments; a point whose height
//! is `NaN`, `BAD` or empty is invalid and left out. The numbers carry no
//! unit: the caller says which (`TextUnits`).

use super::TextUnits;
use crate::error::{ReadError, malformed};
use crate::map::{Format, Measured, Measurement, PointCloud, Profile2d};

/// Rows of `want` numbers (None for an invalid height), with line offsets.
fn rows(bytes: &[u8], want: usize) -> Result<Vec<[Option<f64>; 3]>, ReadError> {
    let text = super::utf8(bytes)?;
    let mut out = Vec::new();
    let mut at = 0;
    let mut first = true;
    for line in text.split_inclusive('\n') {
        let start = at;
        at += line.len();
        let l = line.trim();
        if l.is_empty() || l.starts_with(['#', '%', ';']) {
            continue;
        }
        let cells: Vec<&str> = l
            .split([',', ';', '\t', ' '])
            .filter(|s| !s.is_empty())
            .collect();
        let parsed: Vec<Option<f64>> = cells.iter().map(|c| c.parse::<f64>().ok()).collect();
        let numeric = parsed.iter().take(want - 1).all(Option::is_some);
        if first && !numeric {
            first = false;
            continue; // a header line
        }
        first = false;
        if cells.len() < want - 1 || !numeric {
            return Err(malformed(
                format!("line `{l}` is not {want} numbers"),
                Some(start),
            ));
        }
        // Columns past `want` (an intensity) are ignored.
        let mut row = [None; 3];
        for (k, cell) in row.iter_mut().enumerate().take(want) {
            *cell = parsed.get(k).copied().flatten().filter(|v| v.is_finite());
        }
        let last = cells.get(want - 1).copied().unwrap_or("");
        if row[want - 1].is_none()
            && !(last.is_empty()
                || last.eq_ignore_ascii_case("nan")
                || last.eq_ignore_ascii_case("bad"))
        {
            return Err(malformed(format!("`{last}` is not a number"), Some(start)));
        }
        out.push(row);
    }
    if out.is_empty() {
        return Err(malformed("the file holds no points", None));
    }
    Ok(out)
}

pub fn read_points(bytes: &[u8], units: TextUnits) -> Result<Measurement, ReadError> {
    let points = rows(bytes, 3)?
        .into_iter()
        .filter_map(|r| Some([r[0]? * units.0, r[1]? * units.0, r[2]? * units.0]))
        .collect();
    Ok(Measurement {
        format: Format::Xyz,
        data: Measured::Cloud(PointCloud { points }),
        instrument: None,
    })
}

pub fn read_profile(bytes: &[u8], units: TextUnits) -> Result<Measurement, ReadError> {
    let (x, z) = rows(bytes, 2)?
        .into_iter()
        .filter_map(|r| Some((r[0]? * units.0, r[1]? * units.0)))
        .unzip();
    Ok(Measurement {
        format: Format::Profile,
        data: Measured::Profile(Profile2d { x, z }),
        instrument: None,
    })
}
