//! ISO 25178-71 surface data files, the text variant (`aISO-1.0`,
//! `aISO-2.0`, `aBCR-1.0`): a header of `key = value` lines ended by `*`
//! (`NumPoints` per profile, `NumProfiles`, `Xscale`, `Yscale`, `Zscale`
//! in metres, `DataType` 5 int16, 6 int32 or 7 double, `Compression` 0),
//! then the values, profile after profile, each times `Zscale`, ended by
//! `*`. A non-measured point is `BAD` (the standard's mark) or `NaN`.
//! Binary SDF (`bISO`, `bBCR`) is refused by name.

use crate::error::{ReadError, malformed};
use crate::map::{Format, HeightMap, Measured, Measurement, Profile2d};

pub fn read(bytes: &[u8]) -> Result<Measurement, ReadError> {
    if bytes.first() == Some(&b'b') {
        return Err(ReadError::Unsupported {
            what: "binary SDF (bISO, bBCR); export the text variant (aISO)".into(),
        });
    }
    let text = super::utf8(bytes)?;
    let mut at = 0;
    let mut header = std::collections::HashMap::new();
    let mut body_start = None;
    for line in text.split_inclusive('\n') {
        let start = at;
        at += line.len();
        let l = line.trim();
        if start == 0 {
            continue; // the version line
        }
        if l == "*" {
            body_start = Some(at);
            break;
        }
        if let Some((k, v)) = l.split_once('=') {
            header.insert(k.trim().to_owned(), (v.trim().to_owned(), start));
        }
    }
    let body_start = body_start.ok_or_else(|| malformed("no `*` line ends the header", None))?;
    let get = |key: &str| -> Result<f64, ReadError> {
        let (v, at) = header
            .get(key)
            .ok_or_else(|| malformed(format!("the header has no `{key}`"), None))?;
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| malformed(format!("`{key} = {v}` is not a number"), Some(*at)))
    };
    let nx = get("NumPoints")? as usize;
    let ny = get("NumProfiles")? as usize;
    let (xs, ys, zs) = (get("Xscale")?, get("Yscale")?, get("Zscale")?);
    if get("Compression").unwrap_or(0.0) != 0.0 {
        return Err(ReadError::Unsupported {
            what: "compressed SDF data".into(),
        });
    }
    let dtype = get("DataType")? as i64;
    if !matches!(dtype, 5..=7) {
        return Err(malformed(
            format!("data type {dtype} is not 5 (int16), 6 (int32) or 7 (double)"),
            None,
        ));
    }
    let n = nx.saturating_mul(ny);
    if n == 0 || xs.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || zs == 0.0 {
        return Err(malformed(
            format!("{nx} × {ny} points, x scale {xs} m, z scale {zs} m"),
            None,
        ));
    }
    let mut z = Vec::with_capacity(n.min(super::RESERVE));
    let mut pos = body_start;
    for line in text[body_start..].split_inclusive('\n') {
        if line.trim() == "*" {
            break;
        }
        for tok in line.split_whitespace() {
            if z.len() == n {
                return Err(malformed(
                    format!("more than {n} values before the closing `*`"),
                    Some(pos),
                ));
            }
            let v = if tok.eq_ignore_ascii_case("BAD") || tok.eq_ignore_ascii_case("NaN") {
                f64::NAN
            } else {
                let v: f64 = tok
                    .parse()
                    .map_err(|_| malformed(format!("`{tok}` is not a number"), Some(pos)))?;
                v * zs * 1000.0
            };
            z.push(v);
        }
        pos += line.len();
    }
    if z.len() != n {
        return Err(ReadError::Truncated {
            expected: n,
            found: z.len(),
            what: format!("values for {nx} × {ny} points"),
        });
    }
    let data = if ny == 1 {
        let x: Vec<f64> = (0..nx).map(|i| i as f64 * xs * 1000.0).collect();
        let (x, z) = x.into_iter().zip(z).filter(|(_, z)| z.is_finite()).unzip();
        Measured::Profile(Profile2d { x, z })
    } else {
        Measured::Map(HeightMap::from_heights(
            nx,
            ny,
            (xs * 1000.0, ys * 1000.0),
            z,
        ))
    };
    Ok(Measurement {
        format: Format::Sdf,
        data,
        instrument: header.get("ManufacID").map(|(v, _)| v.clone()),
    })
}
