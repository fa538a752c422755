//! Zygo MetroPro's binary `.dat` and its ASCII export.
//!
//! The binary layout followed is the one gwyddion's `metropro.c` reads
//! (the MetroPro Reference Guide, Zygo OMP-0347, section "Data file
//! format"): a big-endian header whose magic number is 0x881B036F
//! (header format 1, 834 bytes), 0x881B0370 (2) or 0x881B0371 (3, 4096
//! bytes), with at byte 48 the intensity origin, width, height, buckets,
//! range and byte count, at 64 the phase origin, width, height and byte
//! count, at 164 the interferometric scale factor S, the wavelength λ (m),
//! the numerical aperture and the obliquity factor O, at 184 the lateral
//! resolution (m per pixel), at 218 the phase resolution (0, 1 or 2: R =
//! 4096, 32768 or 131072) and at 232 whether the data is inverted. The
//! phase data (int32, big-endian, rows of `width`) follows the header and
//! the intensity data; a value of 2147483640 or more is an invalid point;
//! a height is value · S · O · λ / R (metres).
//!
//! The ASCII export (`Zygo ASCII Data File - Format 2`, the Reference
//! Guide's "ASCII Data File Format", page 449 of edition 0347-M): 14
//! header lines (line 3 the intensity origin, width, height, buckets and
//! range; line 4 the phase origin, width and height; line 8 the source, S,
//! λ, numerical aperture, O, magnification, lateral resolution and time
//! stamp; line 11 the phase resolution first and the data sign eighth),
//! a `#` line, then two blocks each ended by a `#` line: the intensity
//! values, then the phase values (raw integers), with the same scaling and
//! invalid value as the binary file.

use crate::error::{ReadError, malformed};
use crate::map::{Format, HeightMap, Measured, Measurement};

/// A phase value at or above this is an invalid point.
pub const INVALID_PHASE: i64 = 2_147_483_640;

/// R for a phase resolution code.
fn phase_resolution(code: i64, at: Option<usize>) -> Result<f64, ReadError> {
    match code {
        0 => Ok(4096.0),
        1 => Ok(32768.0),
        2 => Ok(131072.0),
        _ => Err(malformed(
            format!("phase resolution code {code} is not 0, 1 or 2"),
            at,
        )),
    }
}

struct Be<'a>(&'a [u8]);

impl Be<'_> {
    fn u16(&self, at: usize) -> u16 {
        u16::from_be_bytes([self.0[at], self.0[at + 1]])
    }
    fn u32(&self, at: usize) -> u32 {
        u32::from_be_bytes(self.0[at..at + 4].try_into().expect("4 bytes"))
    }
    fn f32(&self, at: usize) -> f64 {
        f64::from(f32::from_be_bytes(
            self.0[at..at + 4].try_into().expect("4 bytes"),
        ))
    }
}

pub fn read_dat(bytes: &[u8]) -> Result<Measurement, ReadError> {
    if bytes.len() < 834 {
        return Err(ReadError::Truncated {
            expected: 834,
            found: bytes.len(),
            what: "the MetroPro header".into(),
        });
    }
    let b = Be(bytes);
    let format = b.u16(4);
    let header = b.u32(6) as usize;
    let expected_header = match (bytes[3], format) {
        (0x6f, 1) | (0x70, 2) => 834,
        (0x71, 3) => 4096,
        _ => {
            return Err(malformed(
                format!("header format {format} does not match the magic number"),
                Some(4),
            ));
        }
    };
    if header != expected_header {
        return Err(malformed(
            format!("header size {header}, format {format} has {expected_header}"),
            Some(6),
        ));
    }
    let intens_bytes = b.u32(60) as usize;
    let (w, h) = (b.u16(68) as usize, b.u16(70) as usize);
    let phase_bytes = b.u32(72) as usize;
    if w == 0 || h == 0 {
        return Err(ReadError::Unsupported {
            what: "a MetroPro file with no phase (height) data".into(),
        });
    }
    if phase_bytes != 4 * w * h {
        return Err(malformed(
            format!("phase data of {phase_bytes} bytes for {w} × {h} points"),
            Some(72),
        ));
    }
    let start = header + intens_bytes;
    if bytes.len() < start + phase_bytes {
        return Err(ReadError::Truncated {
            expected: start + phase_bytes,
            found: bytes.len(),
            what: format!("the phase data ({w} × {h} points)"),
        });
    }
    let scale = Scale {
        s: b.f32(164),
        wavelength: b.f32(168),
        obliquity: b.f32(176),
        lateral: b.f32(184),
        r: phase_resolution(i64::from(b.u16(218)), Some(218))?,
        inverted: b.u16(232) != 0,
    };
    let raw = bytes[start..start + phase_bytes]
        .chunks_exact(4)
        .map(|c| i64::from(i32::from_be_bytes([c[0], c[1], c[2], c[3]])));
    finish(Format::MetroProDat, w, h, raw, scale, Some(184))
}

struct Scale {
    s: f64,
    wavelength: f64,
    obliquity: f64,
    lateral: f64,
    r: f64,
    inverted: bool,
}

fn finish(
    format: Format,
    w: usize,
    h: usize,
    raw: impl Iterator<Item = i64>,
    sc: Scale,
    lateral_at: Option<usize>,
) -> Result<Measurement, ReadError> {
    if !(sc.lateral.is_finite() && sc.lateral > 0.0) {
        return Err(malformed(
            format!(
                "the lateral resolution is {} m per pixel: the map has no lateral scale",
                sc.lateral
            ),
            lateral_at,
        ));
    }
    let q = sc.s * sc.obliquity * sc.wavelength / sc.r * if sc.inverted { -1.0 } else { 1.0 };
    if !(q.is_finite() && q != 0.0) {
        return Err(malformed(
            format!(
                "the height scale (S {} · O {} · λ {} m / R {}) is not a finite length",
                sc.s, sc.obliquity, sc.wavelength, sc.r
            ),
            None,
        ));
    }
    // metres to millimetres
    let z = raw
        .map(|v| {
            if v >= INVALID_PHASE {
                f64::NAN
            } else {
                v as f64 * q * 1000.0
            }
        })
        .collect();
    let d = sc.lateral * 1000.0;
    Ok(Measurement {
        format,
        data: Measured::Map(HeightMap::from_heights(w, h, (d, d), z)),
        instrument: Some("Zygo MetroPro".into()),
    })
}

pub fn read_ascii(bytes: &[u8]) -> Result<Measurement, ReadError> {
    let text = super::utf8(bytes)?;
    let lines: Vec<(usize, &str)> = text
        .split_inclusive('\n')
        .scan(0usize, |at, l| {
            let start = *at;
            *at += l.len();
            Some((start, l.trim_end_matches(['\r', '\n'])))
        })
        .collect();
    let numbers = |k: usize, want: usize| -> Result<Vec<f64>, ReadError> {
        let (at, line) = *lines.get(k).ok_or_else(|| ReadError::Truncated {
            expected: k + 1,
            found: lines.len(),
            what: "the header's lines".into(),
        })?;
        let v: Vec<f64> = line
            .split_whitespace()
            .map_while(|s| s.parse::<f64>().ok())
            .collect();
        if v.len() < want {
            return Err(malformed(
                format!(
                    "header line {} has {} numbers, {want} expected",
                    k + 1,
                    v.len()
                ),
                Some(at),
            ));
        }
        Ok(v)
    };
    let intens = numbers(2, 5)?;
    let phase = numbers(3, 4)?;
    let optics = numbers(7, 7)?;
    let res = numbers(10, 1)?;
    let data_sign = numbers(10, 8).map(|v| v[7] != 0.0).unwrap_or(false);
    let (w, h) = (phase[2] as usize, phase[3] as usize);
    let intens_count = (intens[2] * intens[3] * intens[4]) as usize;
    let phase_count = w.saturating_mul(h);
    // The data blocks: after the first `#` line, intensity then phase.
    let first = lines
        .iter()
        .position(|(_, l)| l.trim() == "#")
        .ok_or_else(|| malformed("no `#` line ends the header", None))?;
    let mut values =
        Vec::with_capacity(intens_count.saturating_add(phase_count).min(super::RESERVE));
    let mut hashes = 0;
    for &(at, line) in &lines[first + 1..] {
        if line.trim() == "#" {
            hashes += 1;
            if hashes == 2 {
                break;
            }
            continue;
        }
        for tok in line.split_whitespace() {
            let v: i64 = tok
                .parse()
                .map_err(|_| malformed(format!("`{tok}` is not a whole number"), Some(at)))?;
            values.push(v);
        }
    }
    if values.len() != intens_count.saturating_add(phase_count) {
        return Err(ReadError::Truncated {
            expected: intens_count.saturating_add(phase_count),
            found: values.len(),
            what: format!("values for {intens_count} intensity and {w} × {h} phase points"),
        });
    }
    let scale = Scale {
        s: optics[1],
        wavelength: optics[2],
        obliquity: optics[4],
        lateral: optics[6],
        r: phase_resolution(res[0] as i64, Some(lines[10].0))?,
        inverted: data_sign,
    };
    finish(
        Format::MetroProAscii,
        w,
        h,
        values[intens_count..].iter().copied(),
        scale,
        Some(lines[7].0),
    )
}
