//! Every reader on files other programs wrote (`tests/measure/peer/`,
//! whose README names each file's writer and source), held to the values
//! those programs state, and on broken files.

use super::*;
use crate::map::{HeightMap, Measured};

fn peer(name: &str) -> Vec<u8> {
    let path = format!(
        "{}/../tests/measure/peer/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn map(name: &str) -> HeightMap {
    match read(name, &peer(name), TextUnits::MM).expect(name).data {
        Measured::Map(m) => m,
        other => panic!("{name}: not a map: {other:?}"),
    }
}

fn close(a: f64, b: f64, rtol: f64) -> bool {
    (a - b).abs() <= rtol * b.abs()
}

/// x3ptools' pyramid.x3p was made from pyramid.stl (x3ptools'
/// `test-stl_to_x3p.R` holds them identical): every STL vertex's height
/// is the map's height at that vertex, in metres (1 m pixels).
#[test]
fn x3ptools_pyramid_matches_its_stl() {
    let m = map("pyramid.x3p");
    assert_eq!((m.nx, m.ny), (5, 5));
    assert_eq!((m.dx, m.dy), (1000.0, 1000.0));
    let stl = peer("pyramid.stl");
    let n = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    assert!(n > 0);
    for t in 0..n {
        let tri = &stl[84 + 50 * t + 12..84 + 50 * t + 48];
        for v in tri.chunks_exact(12) {
            let f = |k: usize| f32::from_le_bytes(v[4 * k..4 * k + 4].try_into().unwrap()) as f64;
            let (i, j) = (f(0) as usize - 1, f(1) as usize - 1);
            assert_eq!(m.z[j * 5 + i], f(2) * 1000.0, "vertex ({}, {})", f(0), f(1));
        }
    }
    assert_eq!(m.valid_count(), 25);
}

/// x3ptools' testing.x3p was converted from the GelSight TMD file
/// testing.tmd (`test_tmd_to_x3p.R`: identical matrices): its heights are
/// the TMD's float32 values exactly, in the TMD's order.
#[test]
fn x3ptools_testing_matches_its_tmd() {
    let m = map("testing.x3p");
    assert_eq!((m.nx, m.ny), (30, 20));
    assert!(close(m.dx, 0.0274999996026357 * 1000.0, 1e-15));
    let tmd = peer("testing.tmd");
    // "Binary TrueMap Data File v2.0\r\n\0", an empty comment, then
    // width, height (u32) and four f32 before the data.
    let at = 33;
    let w = u32::from_le_bytes(tmd[at..at + 4].try_into().unwrap()) as usize;
    let h = u32::from_le_bytes(tmd[at + 4..at + 8].try_into().unwrap()) as usize;
    assert_eq!((w, h), (30, 20));
    let data = &tmd[at + 24..];
    assert_eq!(data.len(), 4 * w * h);
    for (k, c) in data.chunks_exact(4).enumerate() {
        let v = f32::from_le_bytes(c.try_into().unwrap()) as f64;
        assert_eq!(m.z[k], v * 1000.0, "point {k}");
    }
}

/// x3ptools' sample-land.x3p nests its files in a folder beside macOS
/// resource forks and a mask image; its two MD5 checksums hold.
#[test]
fn x3ptools_nested_folder_with_mask_image() {
    let m = map("sample-land.x3p");
    assert_eq!((m.nx, m.ny), (918, 256));
    assert!(close(m.dx, 2.58e-3, 1e-15));
    let valid = m.valid_count();
    assert!(valid > 0 && valid < m.nx * m.ny, "{valid} valid points");
}

/// SurfaceTopography's x3p-2.x3p (written by MountainsMap 6.2: a
/// namespaced root, integer x and y axes, no z increment): its test
/// states 650 × 650 points, 8.29767313942749e-05 m across x and an RMS
/// height of 7.728033273597876e-08 m.
#[test]
fn mountainsmap_x3p_reads_as_surfacetopography_states() {
    let m = map("x3p-2.x3p");
    assert_eq!((m.nx, m.ny), (650, 650));
    assert!(close(
        m.nx as f64 * m.dx,
        8.29767313942749e-05 * 1000.0,
        1e-6
    ));
    assert!(close(
        m.ny as f64 * m.dy,
        0.0002044783737930349 * 1000.0,
        1e-6
    ));
    assert_eq!(m.valid_count(), 650 * 650);
    assert!(close(
        m.rms_about_mean(),
        7.728033273597876e-08 * 1000.0,
        1e-6
    ));
}

/// SurfaceTopography's metropro-1.dat (a Zygo instrument's file): its test
/// states 640 × 480 points, 0.0007028812979115173 m across x and an RMS
/// height of 7.528822204734589e-08 m.
#[test]
fn metropro_dat_reads_as_surfacetopography_states() {
    let m = map("metropro-1.dat");
    assert_eq!((m.nx, m.ny), (640, 480));
    assert!(close(
        m.nx as f64 * m.dx,
        0.0007028812979115173 * 1000.0,
        1e-6
    ));
    assert!(close(
        m.ny as f64 * m.dy,
        0.000527160973433638 * 1000.0,
        1e-6
    ));
    assert!(close(
        m.rms_about_mean(),
        7.528822204734589e-08 * 1000.0,
        1e-6
    ));
}

/// The ASCII export built from the MetroPro documentation (no public one
/// was found; `make_metropro_ascii.py`) of a window of metropro-1.dat
/// reads to the same heights as the binary file there.
#[test]
fn metropro_ascii_window_equals_the_binary_file() {
    let whole = map("metropro-1.dat");
    let w = map("metropro-1-window.asc");
    assert_eq!((w.nx, w.ny), (64, 48));
    assert_eq!(w.dx, whole.dx);
    for j in 0..48 {
        for i in 0..64 {
            let k = (200 + j) * 640 + 100 + i;
            assert_eq!(w.valid[j * 64 + i], whole.valid[k]);
            assert_eq!(w.z[j * 64 + i], whole.z[k], "({i}, {j})");
        }
    }
}

/// SurfaceTopography's sdf-1.sdf (the ISO TC 213 example): 7 × 4 points,
/// 1 µm apart, heights in µm.
#[test]
fn iso_sdf_example() {
    let m = map("sdf-1.sdf");
    assert_eq!((m.nx, m.ny), (7, 4));
    assert!(close(m.nx as f64 * m.dx, 7.0e-3, 1e-12));
    assert!(close(m.z[0], 1.0e-3, 1e-12));
    assert!(close(m.z[7 + 1], 0.99748e-3, 1e-12));
    assert!(close(m.z[27], 0.97986e-3, 1e-12));
}

#[test]
fn every_x3p_data_type_with_and_without_a_valid_points_mask() {
    for (letter, width) in [('I', 2), ('L', 4), ('F', 4), ('D', 8)] {
        for masked in [false, true] {
            let raw = [-3i32, 0, 7, 12, 100, -250];
            let mut data = Vec::new();
            for v in raw {
                match letter {
                    'I' => data.extend((v as i16).to_le_bytes()),
                    'L' => data.extend(v.to_le_bytes()),
                    'F' => data.extend((v as f32 * 1e-9).to_le_bytes()),
                    _ => data.extend((v as f64 * 1e-9).to_le_bytes()),
                }
            }
            assert_eq!(data.len(), 6 * width);
            let bytes = build_x3p(letter, &data, masked.then_some(&[0b0010_1101u8][..]), "in/");
            let m = match x3p::read(&bytes).expect("reads").data {
                Measured::Map(m) => m,
                other => panic!("{other:?}"),
            };
            assert_eq!((m.nx, m.ny), (3, 2));
            for (k, v) in raw.iter().enumerate() {
                let want_valid = !masked || (0b0010_1101 >> k) & 1 == 1;
                assert_eq!(m.valid[k], want_valid, "{letter} {k}");
                if want_valid {
                    // integers scale by the 1e-9 m increment; floats are metres
                    assert!(
                        close(m.z[k], *v as f64 * 1e-6, 1e-6) || *v == 0,
                        "{letter} {k}: {}",
                        m.z[k]
                    );
                }
            }
        }
    }
}

#[test]
fn a_changed_point_data_fails_its_checksum() {
    let mut data = Vec::new();
    for v in [1.0f64, 2.0, 3.0, 4.0, 5.0, 6.0] {
        data.extend(v.to_le_bytes());
    }
    let bytes = build_x3p_with(
        'D',
        &data,
        None,
        "",
        Some("00000000000000000000000000000000"),
    );
    assert!(matches!(x3p::read(&bytes), Err(ReadError::Checksum { .. })));
}

#[test]
fn a_truncated_dat_names_the_bytes_it_lacks() {
    let bytes = peer("metropro-1.dat");
    let e = read("cut.dat", &bytes[..bytes.len() - 100], TextUnits::MM).unwrap_err();
    assert!(
        matches!(
            e,
            ReadError::Truncated {
                expected: 1844034,
                found: 1843934,
                ..
            }
        ),
        "{e:?}"
    );
    let e = read("cut.dat", &bytes[..400], TextUnits::MM).unwrap_err();
    assert!(matches!(e, ReadError::Truncated { .. }), "{e:?}");
}

#[test]
fn a_truncated_x3p_archive_is_malformed_not_a_panic() {
    let bytes = peer("pyramid.x3p");
    for cut in [10, 200, bytes.len() / 2, bytes.len() - 5] {
        assert!(
            read("p.x3p", &bytes[..cut], TextUnits::MM).is_err(),
            "cut at {cut}"
        );
    }
}

#[test]
fn text_points_and_profiles_with_units_and_invalid_points() {
    let m = read(
        "p.xyz",
        b"x,y,z\n1,2,3\n4,5,NaN\n# note\n6;7;8\n",
        TextUnits(1e-3),
    )
    .unwrap();
    assert_eq!(
        m.data,
        Measured::Cloud(crate::map::PointCloud {
            points: vec![[1e-3, 2e-3, 3e-3], [6e-3, 7e-3, 8e-3]]
        })
    );
    let p = read("p.txt", b"0 0.5\n1\t0.25\n2 BAD\n", TextUnits::MM).unwrap();
    assert_eq!(
        p.data,
        Measured::Profile(crate::map::Profile2d {
            x: vec![0.0, 1.0],
            z: vec![0.5, 0.25]
        })
    );
    let e = read("p.txt", b"0 0.5\n1 x\n", TextUnits::MM).unwrap_err();
    assert!(
        matches!(e, ReadError::Malformed { at: Some(6), .. }),
        "{e:?}"
    );
}

#[test]
fn sdf_with_bad_points_and_too_few_values() {
    let ok = b"aISO-1.0\nNumPoints = 2\nNumProfiles = 2\nXscale = 1e-6\nYscale = 1e-6\nZscale = 1e-9\nDataType = 7\n*\n1 BAD\n3 4\n*\n";
    let m = match sdf::read(ok).unwrap().data {
        Measured::Map(m) => m,
        other => panic!("{other:?}"),
    };
    assert_eq!(m.valid, vec![true, false, true, true]);
    assert!(close(m.z[3], 4e-6, 1e-12));
    let short = b"aISO-1.0\nNumPoints = 2\nNumProfiles = 2\nXscale = 1e-6\nYscale = 1e-6\nZscale = 1e-9\nDataType = 7\n*\n1 2\n3\n*\n";
    assert!(matches!(
        sdf::read(short),
        Err(ReadError::Truncated {
            expected: 4,
            found: 3,
            ..
        })
    ));
}

fn build_x3p(letter: char, data: &[u8], valid: Option<&[u8]>, folder: &str) -> Vec<u8> {
    let md5: String = {
        use md5::{Digest, Md5};
        Md5::digest(data)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    };
    build_x3p_with(letter, data, valid, folder, Some(&md5))
}

/// A 3 × 2 X3P archive as the standard's schema lays it out, z of type
/// `letter` with a 1e-9 m increment (x and y 1 µm).
fn build_x3p_with(
    letter: char,
    data: &[u8],
    valid: Option<&[u8]>,
    folder: &str,
    md5: Option<&str>,
) -> Vec<u8> {
    use std::io::Write;
    let valid_link = if valid.is_some() {
        "<ValidPointsLink>bindata/valid.bin</ValidPointsLink>"
    } else {
        ""
    };
    let md5 = md5
        .map(|m| format!("<MD5ChecksumPointData>{m}</MD5ChecksumPointData>"))
        .unwrap_or_default();
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2"><Record1><Revision>ISO5436 - 2000</Revision><FeatureType>SUR</FeatureType><Axes>
<CX><AxisType>I</AxisType><DataType>D</DataType><Increment>1e-6</Increment><Offset>0</Offset></CX>
<CY><AxisType>I</AxisType><DataType>D</DataType><Increment>1e-6</Increment><Offset>0</Offset></CY>
<CZ><AxisType>A</AxisType><DataType>{letter}</DataType><Increment>1e-9</Increment><Offset>0</Offset></CZ></Axes></Record1>
<Record3><MatrixDimension><SizeX>3</SizeX><SizeY>2</SizeY><SizeZ>1</SizeZ></MatrixDimension>
<DataLink><PointDataLink>bindata/data.bin</PointDataLink>{md5}{valid_link}</DataLink></Record3></p:ISO5436_2>"#
    );
    let mut out = std::io::Cursor::new(Vec::new());
    let mut zip = zip::ZipWriter::new(&mut out);
    let opts = zip::write::SimpleFileOptions::default();
    zip.start_file(format!("{folder}main.xml"), opts).unwrap();
    zip.write_all(xml.as_bytes()).unwrap();
    zip.start_file(format!("{folder}bindata/data.bin"), opts)
        .unwrap();
    zip.write_all(data).unwrap();
    if let Some(v) = valid {
        zip.start_file(format!("{folder}bindata/valid.bin"), opts)
            .unwrap();
        zip.write_all(v).unwrap();
    }
    zip.finish().unwrap();
    out.into_inner()
}

/// Found by the fuzzer's measure target: an SDF height of 1e308 µm
/// (1e305 mm) was read, and its Sq came out infinite. Heights beyond
/// `REACH_MM` are refused as a damaged file, naming the number.
#[test]
fn a_height_beyond_any_instrument_is_refused() {
    let sdf = "aISO-1.0\nManufacID = ISOTC213\nNumPoints = 3\nNumProfiles = 2\nXscale = 1.0E-6\nYscale = 1.0E-6\nZscale = 1.0E-6\nCompression = 0\nDataType = 7\nCheckType = 0\n*\n1.0 0.99 0.98\n0.97 1e308 0.95\n*\n";
    let err = read("part.sdf", sdf.as_bytes(), TextUnits::MM).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("1e305 mm") && text.contains("point 4"),
        "{text}"
    );
    // Below the reach it reads (the same file with a plausible height).
    let fine = sdf.replace("1e308", "0.96");
    assert!(read("part.sdf", fine.as_bytes(), TextUnits::MM).is_ok());
    // A scale that underflows to a zero pixel spacing (found by the
    // fuzzer too: `Yscale = 1.0E-100000`).
    let zero = sdf.replace("Yscale = 1.0E-6", "Yscale = 1.0E-100000");
    let err = read("part.sdf", zero.as_bytes(), TextUnits::MM).unwrap_err();
    assert!(err.to_string().contains("along y is 0e0 mm"), "{err}");
    // A cloud and a profile are held to the same reach.
    let err = read("p.xyz", b"0 0 0\n1 1 2e4\n", TextUnits::MM).unwrap_err();
    assert!(err.to_string().contains("20000 mm"), "{err}");
    let err = read("p.txt", b"0 0\n-3e4 1\n", TextUnits::MM).unwrap_err();
    assert!(err.to_string().contains("-30000 mm"), "{err}");
}

/// The fuzzer's measure target (issue #33, item 7): header counts that no
/// file could hold are refused, not trusted with an allocation. A MetroPro
/// ASCII phase width of 2^64 overflowed `intens + w·h` (a panic, "capacity
/// overflow"); an SDF of 2^34 points asked for 137 GB and aborted.
#[test]
fn counts_no_file_could_hold_are_refused_not_allocated() {
    let asc = String::from_utf8(peer("metropro-1-window.asc")).expect("text");
    let huge = asc.replacen("100 200 64 48", "100 200 18446744073709551616 48", 1);
    assert_ne!(asc, huge);
    assert!(read("huge.asc", huge.as_bytes(), TextUnits::MM).is_err());
    let sdf = String::from_utf8(peer("sdf-1.sdf")).expect("text");
    let huge = sdf.replacen("NumPoints = 7", "NumPoints = 17179869184", 1);
    assert_ne!(sdf, huge);
    assert!(read("huge.sdf", huge.as_bytes(), TextUnits::MM).is_err());
}
