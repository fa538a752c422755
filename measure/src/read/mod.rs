//! Reading a measurement file's bytes: the format found from its first
//! bytes (and, for the plain-text formats, its name), then that format's
//! reader. Every reader gives millimetres and keeps the invalid points as
//! a mask.

pub mod metropro;
pub mod sdf;
pub mod text;
pub mod x3p;

use crate::error::ReadError;
use crate::map::{Format, Measurement};

/// The units of a plain-text file's numbers, which the file cannot state
/// (`--units`): millimetres per unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextUnits(pub f64);

impl TextUnits {
    pub const MM: TextUnits = TextUnits(1.0);
}

/// The format of a file from its first bytes, else from its name's
/// extension (`.xyz`, `.csv` points; `.txt`, `.prf` profiles).
pub fn detect(name: &str, bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"PK\x03\x04") {
        return Some(Format::X3p);
    }
    if bytes.len() >= 4 && bytes[..3] == [0x88, 0x1b, 0x03] && (0x6f..=0x71).contains(&bytes[3]) {
        return Some(Format::MetroProDat);
    }
    for magic in [&b"aISO-"[..], b"aBCR-", b"bISO-", b"bBCR-"] {
        if bytes.starts_with(magic) {
            return Some(Format::Sdf);
        }
    }
    if bytes.starts_with(b"Zygo ASCII Data File") {
        return Some(Format::MetroProAscii);
    }
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("xyz" | "csv") => Some(Format::Xyz),
        Some("txt" | "prf" | "profile") => Some(Format::Profile),
        _ => None,
    }
}

/// Reads a measurement file given its name (for its extension) and bytes.
/// The most values a reader reserves room for before it has read them: a
/// header's counts are not trusted with an allocation (a count of 2^64
/// overflowed, one of 2^34 asked for 137 GB and aborted; issue #33's
/// fuzzing), the list grows past this as values are read.
pub(crate) const RESERVE: usize = 1 << 20;

pub fn read(name: &str, bytes: &[u8], units: TextUnits) -> Result<Measurement, ReadError> {
    let m = read_format(name, bytes, units)?;
    within_reach(&m)?;
    Ok(m)
}

/// The largest height or position (mm, in magnitude) a measurement may
/// hold: 10 m, beyond any part an interferometer or profiler measures. A
/// larger number is a damaged file or a wrong scale, and left in it would
/// overflow the figures computed from it (Sq of heights of 1e305 mm is
/// infinite).
pub const REACH_MM: f64 = 1e4;

/// The smallest pixel spacing a map may have (mm): 1 pm, far below any
/// instrument's lateral resolution; zero (a scale that underflowed) or
/// less is a damaged file.
pub const MIN_PIXEL_MM: f64 = 1e-9;

/// Refuses a measurement with a valid height, position or spacing that is
/// not finite or beyond `REACH_MM`.
fn within_reach(m: &Measurement) -> Result<(), ReadError> {
    let far = |v: f64| !(v.is_finite() && v.abs() <= REACH_MM);
    let refuse = |what: &str, v: f64| {
        Err(crate::error::malformed(
            format!(
                "{what} is {} mm, beyond the {REACH_MM} mm any instrument measures: the file is damaged or its units are wrong",
                if v.abs() < 1e6 {
                    v.to_string()
                } else {
                    format!("{v:e}")
                }
            ),
            None,
        ))
    };
    match &m.data {
        crate::Measured::Map(h) => {
            for (what, v) in [
                ("the pixel spacing along x", h.dx),
                ("the pixel spacing along y", h.dy),
            ] {
                if far(v) {
                    return refuse(what, v);
                }
                if v < MIN_PIXEL_MM {
                    return Err(crate::error::malformed(
                        format!(
                            "{what} is {v:e} mm, under the {MIN_PIXEL_MM:e} mm (1 pm) any instrument resolves: the file is damaged or its scale is wrong"
                        ),
                        None,
                    ));
                }
            }
            let last_x = h.x0 + h.dx * h.nx.saturating_sub(1) as f64;
            let last_y = h.y0 + h.dy * h.ny.saturating_sub(1) as f64;
            for (what, v) in [
                ("the map's first x", h.x0),
                ("the map's first y", h.y0),
                ("the map's last x", last_x),
                ("the map's last y", last_y),
            ] {
                if far(v) {
                    return refuse(what, v);
                }
            }
            if let Some(k) = (0..h.z.len()).find(|&k| h.valid[k] && far(h.z[k])) {
                return refuse(&format!("the height at point {k}"), h.z[k]);
            }
        }
        crate::Measured::Cloud(c) => {
            if let Some((k, v)) = c
                .points
                .iter()
                .enumerate()
                .find_map(|(k, p)| p.iter().find(|v| far(**v)).map(|v| (k, *v)))
            {
                return refuse(&format!("a coordinate of point {k}"), v);
            }
        }
        crate::Measured::Profile(p) => {
            if let Some((k, v)) =
                p.x.iter()
                    .zip(&p.z)
                    .enumerate()
                    .find_map(|(k, (x, z))| [*x, *z].into_iter().find(|v| far(*v)).map(|v| (k, v)))
            {
                return refuse(&format!("a value of profile point {k}"), v);
            }
        }
    }
    Ok(())
}

/// Reads the file in the format its first bytes or name say.
fn read_format(name: &str, bytes: &[u8], units: TextUnits) -> Result<Measurement, ReadError> {
    match detect(name, bytes).ok_or(ReadError::UnknownFormat)? {
        Format::X3p => x3p::read(bytes),
        Format::MetroProDat => metropro::read_dat(bytes),
        Format::MetroProAscii => metropro::read_ascii(bytes),
        Format::Sdf => sdf::read(bytes),
        Format::Xyz => text::read_points(bytes, units),
        Format::Profile => text::read_profile(bytes, units),
    }
}

/// Text from bytes, or a malformed-file error at the first bad byte.
pub(crate) fn utf8(bytes: &[u8]) -> Result<&str, ReadError> {
    std::str::from_utf8(bytes)
        .map_err(|e| crate::error::malformed("the text is not UTF-8", Some(e.valid_up_to())))
}

#[cfg(test)]
mod tests;
