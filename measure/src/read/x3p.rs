//! ISO 25178-72 (the XML 3D surface profile format of ISO 5436-2): a zip
//! archive holding `main.xml` (axes, sizes, data link, checksums) and the
//! binary point data. Read as the standard's schema
//! (`iso5436_2.xsd`, published with x3ptools and openGPS) lays it out:
//!
//! - `main.xml` anywhere in the archive (x3ptools nests it in a folder);
//!   the data link is relative to its folder;
//! - feature types `SUR` (a map) and `PRF` (a profile, one row); `PCL`
//!   (absolute x, y) is refused by name;
//! - data types `I` (int16), `L` (int32), `F` (float32), `D` (float64),
//!   little-endian; an integer is `Offset + Increment · value`, a float
//!   `Offset + value` (its increment states a resolution);
//! - invalid points: NaN for `F` and `D`; for every type the optional
//!   valid-points bit array (`ValidPointsLink`, point k at bit k mod 8,
//!   least significant first, of byte k / 8, 1 = valid);
//! - data inline as `DataList`/`Datum` (an empty datum is invalid);
//! - lengths in metres (the standard's unit), read as millimetres;
//! - the MD5 checksums of the point data (`MD5ChecksumPointData`) and of
//!   `main.xml` (`md5checksum.hex`) checked when present.
//!
//! x3ptools' mask image (`Record3/Mask`, a PNG of coloured annotations)
//! marks regions by their meaning, not invalid points; it is not read.

use std::io::Read;

use md5::{Digest, Md5};

use crate::error::{ReadError, malformed};
use crate::map::{Format, HeightMap, Measured, Measurement, Profile2d};

/// The largest uncompressed entry read (bytes): 1 GiB, well above a
/// 10,000 × 10,000 map of float64 (800 MB).
const MAX_ENTRY: u64 = 1 << 30;

pub fn read(bytes: &[u8]) -> Result<Measurement, ReadError> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| malformed(format!("not a readable zip archive ({e})"), None))?;
    let main = main_xml_path(&mut zip)?;
    let folder = main.rsplit_once('/').map_or("", |(f, _)| f).to_owned();
    let xml_bytes = entry(&mut zip, &main, MAX_ENTRY)?;
    check_main_checksum(&mut zip, &folder, &xml_bytes)?;
    let xml = std::str::from_utf8(&xml_bytes)
        .map_err(|e| malformed("main.xml is not UTF-8", Some(e.valid_up_to())))?;
    let doc = roxmltree::Document::parse(xml)
        .map_err(|e| malformed(format!("main.xml is not well-formed XML ({e})"), None))?;
    let root = doc.root_element();
    let r1 = need(root, "Record1")?;
    let feature = text(need(r1, "FeatureType")?);
    let axes = need(r1, "Axes")?;
    let cx = Axis::read(need(axes, "CX")?, "CX")?;
    let cy = Axis::read(need(axes, "CY")?, "CY")?;
    let cz = Axis::read(need(axes, "CZ")?, "CZ")?;
    if feature == "PCL" || cx.absolute || cy.absolute {
        return Err(ReadError::Unsupported {
            what: "an X3P point cloud (feature type PCL, absolute x and y axes)".into(),
        });
    }
    if feature != "SUR" && feature != "PRF" {
        return Err(malformed(
            format!("feature type `{feature}` is not SUR, PRF or PCL"),
            None,
        ));
    }
    let r3 = need(root, "Record3")?;
    let dims = need(r3, "MatrixDimension")?;
    let nx = count(need(dims, "SizeX")?)?;
    let ny = count(need(dims, "SizeY")?)?;
    let nz = count(need(dims, "SizeZ")?)?;
    if nz != 1 {
        return Err(ReadError::Unsupported {
            what: format!("an X3P map with {nz} layers (SizeZ)"),
        });
    }
    let n = nx
        .checked_mul(ny)
        .filter(|n| *n > 0)
        .ok_or_else(|| malformed(format!("the matrix is {nx} × {ny} points"), None))?;
    let mut z = if let Some(link) = child(r3, "DataLink") {
        let path = join(&folder, &text(need(link, "PointDataLink")?));
        let width = cz.data_type.width();
        let data = entry(&mut zip, &path, (n * width) as u64)?;
        // The checksum beside the decoding (of whole data only: a
        // damaged file is refused for its checksum first, as before).
        let stated = child(link, "MD5ChecksumPointData").map(text);
        if let (Some(stated), true) = (&stated, data.len() == n * width) {
            let (checked, z) =
                rayon::join(|| check_md5(&data, stated, &path), || decode(&data, cz));
            checked?;
            z
        } else {
            if let Some(stated) = &stated {
                check_md5(&data, stated, &path)?;
            }
            if data.len() != n * width {
                return Err(ReadError::Truncated {
                    expected: n * width,
                    found: data.len(),
                    what: format!(
                        "`{path}` ({nx} × {ny} points of type {})",
                        cz.data_type.letter()
                    ),
                });
            }
            decode(&data, cz)
        }
    } else if let Some(list) = child(r3, "DataList") {
        datum_list(list, n, cz)?
    } else {
        return Err(malformed(
            "Record3 has neither a DataLink nor a DataList",
            None,
        ));
    };
    if let Some(link) = child(r3, "DataLink").and_then(|l| child(l, "ValidPointsLink")) {
        let path = join(&folder, &text(link));
        let bits = entry(&mut zip, &path, n.div_ceil(8) as u64)?;
        if bits.len() < n.div_ceil(8) {
            return Err(ReadError::Truncated {
                expected: n.div_ceil(8),
                found: bits.len(),
                what: format!("the valid-points bit array `{path}`"),
            });
        }
        for (k, v) in z.iter_mut().enumerate() {
            if bits[k / 8] >> (k % 8) & 1 == 0 {
                *v = f64::NAN;
            }
        }
    }
    for v in &mut z {
        *v *= 1000.0; // metres to millimetres
    }
    let dx = cx.increment * 1000.0;
    let dy = if ny == 1 { dx } else { cy.increment * 1000.0 };
    for (name, d) in [("CX", dx), ("CY", dy)] {
        if !(d.is_finite() && d > 0.0) {
            return Err(malformed(
                format!(
                    "the {name} increment is {}, not a positive length",
                    d / 1000.0
                ),
                None,
            ));
        }
    }
    let instrument = child(root, "Record2")
        .and_then(|r2| child(r2, "Instrument"))
        .map(|i| {
            ["Manufacturer", "Model", "Version"]
                .iter()
                .filter_map(|k| child(i, k).map(text))
                .filter(|s| !s.is_empty())
                .collect::<Vec<_>>()
                .join(" ")
        });
    let data = if feature == "PRF" || ny == 1 {
        let x: Vec<f64> = (0..nx)
            .map(|i| cx.offset * 1000.0 + i as f64 * dx)
            .collect();
        let (x, z) = x.into_iter().zip(z).filter(|(_, z)| z.is_finite()).unzip();
        Measured::Profile(Profile2d { x, z })
    } else {
        let mut m = HeightMap::from_heights(nx, ny, (dx, dy), z);
        m.x0 = cx.offset * 1000.0;
        m.y0 = cy.offset * 1000.0;
        Measured::Map(m)
    };
    Ok(Measurement {
        format: Format::X3p,
        data,
        instrument,
    })
}

#[derive(Clone, Copy, Debug)]
enum DataType {
    I,
    L,
    F,
    D,
}

impl DataType {
    fn width(self) -> usize {
        match self {
            DataType::I => 2,
            DataType::L | DataType::F => 4,
            DataType::D => 8,
        }
    }
    fn letter(self) -> char {
        match self {
            DataType::I => 'I',
            DataType::L => 'L',
            DataType::F => 'F',
            DataType::D => 'D',
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Axis {
    absolute: bool,
    data_type: DataType,
    increment: f64,
    offset: f64,
}

impl Axis {
    fn read(node: roxmltree::Node, name: &str) -> Result<Axis, ReadError> {
        let kind = text(need(node, "AxisType")?);
        let data_type = match child(node, "DataType").map(text).as_deref() {
            Some("I") => DataType::I,
            Some("L") => DataType::L,
            Some("F") => DataType::F,
            Some("D") | None => DataType::D,
            Some(other) => {
                return Err(malformed(
                    format!("{name} has data type `{other}`, not I, L, F or D"),
                    None,
                ));
            }
        };
        let number = |tag: &str, default: f64| -> Result<f64, ReadError> {
            match child(node, tag).map(text) {
                None => Ok(default),
                Some(s) if s.is_empty() => Ok(default),
                Some(s) => s
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| malformed(format!("{name} {tag} `{s}` is not a number"), None)),
            }
        };
        Ok(Axis {
            absolute: kind == "A" && name != "CZ",
            data_type,
            increment: number("Increment", 1.0)?,
            offset: number("Offset", 0.0)?,
        })
    }
}

/// Heights in metres from the little-endian binary data (NaN invalid).
fn decode(data: &[u8], cz: Axis) -> Vec<f64> {
    let (inc, off) = (cz.increment, cz.offset);
    match cz.data_type {
        DataType::I => data
            .chunks_exact(2)
            .map(|c| off + inc * f64::from(i16::from_le_bytes([c[0], c[1]])))
            .collect(),
        DataType::L => data
            .chunks_exact(4)
            .map(|c| off + inc * f64::from(i32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect(),
        DataType::F => data
            .chunks_exact(4)
            .map(|c| off + f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect(),
        DataType::D => data
            .chunks_exact(8)
            .map(|c| off + f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect(),
    }
}

fn datum_list(list: roxmltree::Node, n: usize, cz: Axis) -> Result<Vec<f64>, ReadError> {
    let mut z = Vec::with_capacity(n);
    for d in list
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "Datum")
    {
        let s = text(d);
        if s.is_empty() {
            z.push(f64::NAN);
            continue;
        }
        let v: f64 = s.parse().map_err(|_| {
            malformed(
                format!("the datum `{s}` is not a number"),
                Some(d.range().start),
            )
        })?;
        z.push(match cz.data_type {
            DataType::I | DataType::L => cz.offset + cz.increment * v,
            DataType::F | DataType::D => cz.offset + v,
        });
    }
    if z.len() != n {
        return Err(malformed(
            format!("the DataList holds {} points, the matrix {n}", z.len()),
            None,
        ));
    }
    Ok(z)
}

fn main_xml_path(zip: &mut zip::ZipArchive<std::io::Cursor<&[u8]>>) -> Result<String, ReadError> {
    let mut found: Vec<String> = zip
        .file_names()
        .filter(|n| (*n == "main.xml" || n.ends_with("/main.xml")) && !n.starts_with("__MACOSX/"))
        .map(str::to_owned)
        .collect();
    found.sort_by_key(|n| n.len());
    found
        .into_iter()
        .next()
        .ok_or_else(|| malformed("the archive holds no main.xml", None))
}

/// The bytes of an entry, at most `limit` (+1, so a longer one is seen).
fn entry(
    zip: &mut zip::ZipArchive<std::io::Cursor<&[u8]>>,
    name: &str,
    limit: u64,
) -> Result<Vec<u8>, ReadError> {
    let f = zip
        .by_name(name)
        .map_err(|_| malformed(format!("the archive holds no `{name}`"), None))?;
    let mut out = Vec::new();
    f.take(limit.min(MAX_ENTRY) + 1)
        .read_to_end(&mut out)
        .map_err(|e| malformed(format!("`{name}` cannot be decompressed ({e})"), None))?;
    Ok(out)
}

fn check_main_checksum(
    zip: &mut zip::ZipArchive<std::io::Cursor<&[u8]>>,
    folder: &str,
    xml: &[u8],
) -> Result<(), ReadError> {
    let Ok(hex) = entry(zip, &join(folder, "md5checksum.hex"), 1024) else {
        return Ok(());
    };
    let stated = String::from_utf8_lossy(&hex);
    let Some(stated) = stated.split_whitespace().next() else {
        return Ok(());
    };
    check_md5(xml, stated, "main.xml")
}

fn check_md5(data: &[u8], stated: &str, part: &str) -> Result<(), ReadError> {
    let computed: String = Md5::digest(data)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    if computed.eq_ignore_ascii_case(stated.trim()) {
        Ok(())
    } else {
        Err(ReadError::Checksum {
            part: format!("`{part}`"),
            stated: stated.trim().to_owned(),
            computed,
        })
    }
}

fn join(folder: &str, path: &str) -> String {
    let path = path.trim().replace('\\', "/");
    if folder.is_empty() {
        path
    } else {
        format!("{folder}/{path}")
    }
}

fn child<'a, 'i>(n: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

fn need<'a, 'i>(
    n: roxmltree::Node<'a, 'i>,
    name: &str,
) -> Result<roxmltree::Node<'a, 'i>, ReadError> {
    child(n, name).ok_or_else(|| {
        malformed(
            format!("main.xml has no <{name}> in <{}>", n.tag_name().name()),
            Some(n.range().start),
        )
    })
}

fn text(n: roxmltree::Node) -> String {
    n.text().unwrap_or("").trim().to_owned()
}

fn count(n: roxmltree::Node) -> Result<usize, ReadError> {
    let s = text(n);
    s.parse::<usize>().map_err(|_| {
        malformed(
            format!("<{}> `{s}` is not a count", n.tag_name().name()),
            Some(n.range().start),
        )
    })
}
