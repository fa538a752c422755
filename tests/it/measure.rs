//! `lensc measure` as a user meets it: a map made from the job's own
//! design surface, placed with a known decentre, tilt and piston and
//! written as X3P, is measured back to those values (within 5 % or 1 nm);
//! every kind of bad input is a coded error that names the file, exits 1
//! and writes nothing; and the report matches its committed schema.

use std::path::Path;

use lensc_build::driver::{self, SamplePoints};
use lensc_lang::loader::RealFs;
use lensc_measure::HeightMap;

use crate::common::{lensc, root, text};

const JOB: &str = "examples/kim2008_convex_asphere.lens";
const SURFACE: &str = "convex_asphere";

/// The design's heights at `pts` (mm), NaN outside its aperture.
fn design(pts: &[(f64, f64)]) -> Vec<f64> {
    let c = driver::check_path(&RealFs, &root().join(JOB)).expect("reads");
    driver::sample(&c, SURFACE, &SamplePoints::Points(pts.to_vec()))
        .expect("samples")
        .iter()
        .map(|r| r[2])
        .collect()
}

/// A map `n` × `n` over ±1.5 mm of the design placed with piston p,
/// tilts (tx, ty) and decentre (dx, dy); `keep` says which points the
/// instrument saw; heights times `scale` (1: mm).
fn placed_map(
    n: usize,
    [p, tx, ty, dx, dy]: [f64; 5],
    keep: &dyn Fn(usize) -> bool,
    scale: f64,
) -> HeightMap {
    let d = 3.0 / (n - 1) as f64;
    let mut xy = Vec::new();
    for j in 0..n {
        for i in 0..n {
            xy.push((-1.5 + i as f64 * d, -1.5 + j as f64 * d));
        }
    }
    let moved: Vec<(f64, f64)> = xy.iter().map(|(x, y)| (x - dx, y - dy)).collect();
    let h = design(&moved);
    let z = xy
        .iter()
        .zip(h)
        .enumerate()
        .map(|(k, ((x, y), h))| {
            if keep(k) && h.is_finite() && x * x + y * y < 1.55 * 1.55 {
                (h + p + tx * x + ty * y) * scale
            } else {
                f64::NAN
            }
        })
        .collect();
    HeightMap::from_heights(n, n, (d, d), z)
}

/// A project folder with the job and the measurement `bytes` as `name`.
fn project(name: &str, bytes: &[u8]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(root().join(JOB), dir.path().join("job.lens")).expect("copy job");
    std::fs::write(dir.path().join(name), bytes).expect("write part");
    dir
}

fn written(dir: &Path) -> Vec<String> {
    match std::fs::read_dir(dir.join("out")) {
        Ok(r) => r
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn a_placed_design_is_measured_back_to_its_placement() {
    let truth = [3e-4, 30e-6, -15e-6, 4e-3, -2.5e-3];
    let m = placed_map(201, truth, &|_| true, 1.0);
    let dir = project("part.x3p", &lensc_measure::write::x3p(&m, "test"));
    let out = lensc(
        dir.path(),
        &["measure", "job.lens", "part.x3p", "--job", "kim_convex"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let mut files = written(dir.path());
    files.sort();
    assert_eq!(
        files,
        ["kim_convex.error_map.svg", "kim_convex.measure.json"]
    );
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/kim_convex.measure.json")).unwrap(),
    )
    .unwrap();
    let r = &report["registration"];
    let close = |got: &serde_json::Value, want: f64, abs: f64| {
        let got = got.as_f64().expect("a number");
        assert!(
            (got - want).abs() <= abs.max(0.05 * want.abs()),
            "{got} against {want}: {report:#}"
        );
    };
    // µm and µrad in the report; 1 nm, and 1 nm over the 1.6 mm radius.
    close(&r["piston_um"], 0.3, 1e-3);
    close(&r["tilt_x_urad"], 30.0, 1e-3 / 1.6);
    close(&r["tilt_y_urad"], -15.0, 1e-3 / 1.6);
    close(&r["decentre_x_um"], 4.0, 1e-3);
    close(&r["decentre_y_um"], -2.5, 1e-3);
    assert!(
        r.get("clocking_urad").is_none(),
        "a surface of revolution has no clocking"
    );
    assert!(
        report["form_error"]["pv_nm"].as_f64().unwrap() < 1e-3,
        "{report:#}"
    );
    assert!(
        report["texture"]["sq_nm"].as_f64().unwrap() < 1e-3,
        "{report:#}"
    );
    // A lathe job: no set-up error in a perfect part.
    assert!(
        report["setup"]["x_offset_um"].as_f64().unwrap().abs() < 1e-3,
        "{report:#}"
    );
    assert_eq!(report["setup"]["centre_height_um"].as_f64(), Some(0.0));
    // The report holds to its schema.
    let schema: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("docs/measure.schema.json")).unwrap(),
    )
    .unwrap();
    let mut schemas = boon::Schemas::new();
    let mut compiler = boon::Compiler::new();
    compiler
        .add_resource("measure.schema.json", schema)
        .unwrap();
    let id = compiler
        .compile("measure.schema.json", &mut schemas)
        .unwrap();
    schemas
        .validate(&report, id)
        .expect("the report holds to docs/measure.schema.json");
    let svg = std::fs::read_to_string(dir.path().join("out/kim_convex.error_map.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("PV"),
        "{}",
        &svg[..200.min(svg.len())]
    );
}

/// Runs `lensc measure` on `bytes` named `name`; asserts exit 1, the
/// code, the file named, nothing written; returns stderr.
fn refused(name: &str, bytes: &[u8], code: &str, extra: &[&str]) -> String {
    let dir = project(name, bytes);
    let mut args = vec!["measure", "job.lens", name, "--job", "kim_convex"];
    args.extend_from_slice(extra);
    let out = lensc(dir.path(), &args);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("[{code}]")) && err.contains(name),
        "{err}"
    );
    assert!(written(dir.path()).is_empty(), "{:?}", written(dir.path()));
    err
}

#[test]
fn bad_measurements_are_coded_errors_naming_the_file() {
    let peer = |n: &str| std::fs::read(root().join("tests/measure/peer").join(n)).unwrap();
    // Not a measurement at all.
    refused("part.bin", b"\x00\x01 nothing here", "E0360", &[]);
    // A MetroPro file cut short.
    let dat = peer("metropro-1.dat");
    let err = refused("cut.dat", &dat[..dat.len() - 100], "E0361", &[]);
    assert!(err.contains("1844034") && err.contains("1843934"), "{err}");
    // An X3P whose point data was changed after it was written.
    let good = lensc_measure::write::x3p(&placed_map(41, [0.0; 5], &|_| true, 1.0), "test");
    let mut m = placed_map(41, [0.0; 5], &|_| true, 1.0);
    m.z[41 * 20 + 20] += 1e-3;
    let changed = lensc_measure::write::x3p(&m, "test");
    assert_ne!(good, changed);
    // (re-pack the changed data under the good file's checksums)
    refused("edited.x3p", &swap_data(&good, &changed), "E0362", &[]);
    // x3ptools' pyramid: 5 m across, not this 3.2 mm part.
    refused("pyramid.x3p", &peer("pyramid.x3p"), "E0364", &[]);
    // A mask leaving a third of the aperture.
    let sparse = placed_map(101, [0.0; 5], &|k| k % 3 == 0, 1.0);
    let err = refused(
        "sparse.x3p",
        &lensc_measure::write::x3p(&sparse, "test"),
        "E0363",
        &[],
    );
    assert!(err.contains("32.1 %") && err.contains("50.0 %"), "{err}");
    // ... which --min-valid 30 accepts.
    let dir = project("sparse.x3p", &lensc_measure::write::x3p(&sparse, "test"));
    let out = lensc(
        dir.path(),
        &[
            "measure",
            "job.lens",
            "sparse.x3p",
            "--job",
            "kim_convex",
            "--min-valid",
            "30",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // Heights a thousand times too large (µm written as mm).
    let wrong = placed_map(61, [0.0, 0.0, 0.0, 0.0, 0.0], &|_| true, 1000.0);
    refused(
        "wrong_units.x3p",
        &lensc_measure::write::x3p(&wrong, "test"),
        "E0364",
        &[],
    );
    // A text profile in µm read as mm: most of it lies off the part.
    let profile: String = (0..=300)
        .map(|i| format!("{} 0\n", -1500.0 + 10.0 * i as f64))
        .collect();
    let err = refused("profile.txt", profile.as_bytes(), "E0364", &[]);
    assert!(err.contains("--units"), "{err}");
}

/// A refusal over a binary file (an X3P, a MetroPro `.dat`), or one at
/// no byte of the file, shows no line of it (it used to draw an empty
/// `1 │` line over the binary's first byte): the message names the file
/// and the line under it the byte, where one is known. A text file's
/// refusal at a byte still shows its line.
#[test]
fn a_binary_files_refusal_names_the_byte_without_a_source_line() {
    let peer = |n: &str| std::fs::read(root().join("tests/measure/peer").join(n)).unwrap();
    // A MetroPro header whose size (bytes 6 to 9) says 835.
    let mut dat = peer("metropro-1.dat");
    dat[6..10].copy_from_slice(&835u32.to_be_bytes());
    let err = refused("header.dat", &dat, "E0360", &[]);
    assert!(err.contains("header size 835"), "{err}");
    assert!(err.contains("--> header.dat, byte 6"), "{err}");
    assert!(!err.contains('│'), "no source line: {err}");
    // Not a measurement at all, and one of another part: at no byte.
    for (name, bytes, code) in [
        ("part.bin", b"\x00\x01 nothing here".to_vec(), "E0360"),
        ("pyramid.x3p", peer("pyramid.x3p"), "E0364"),
    ] {
        let err = refused(name, &bytes, code, &[]);
        assert!(err.contains(&format!("--> {name}\n")), "{err}");
        assert!(!err.contains('│'), "no source line: {err}");
    }
    // A MetroPro ASCII export whose third header line has two numbers of five.
    let asc = String::from_utf8(peer("metropro-1-window.asc")).unwrap();
    let mut lines: Vec<&str> = asc.split_inclusive('\n').collect();
    let at: usize = lines[..2].iter().map(|l| l.len()).sum();
    lines[2] = "0 0 x\n";
    let err = refused("window.asc", lines.concat().as_bytes(), "E0360", &[]);
    assert!(
        err.contains(&format!(
            "header line 3 has 2 numbers, 5 expected (at byte {at})"
        )),
        "{err}"
    );
    assert!(err.contains("3 │ 0 0 x"), "the line shown: {err}");
}

#[test]
fn a_measurement_outside_the_project_root_is_refused() {
    let dir = tempfile::tempdir().expect("tmp");
    let project = dir.path().join("project");
    std::fs::create_dir(&project).unwrap();
    std::fs::copy(root().join(JOB), project.join("job.lens")).unwrap();
    std::fs::write(dir.path().join("part.x3p"), b"PK\x03\x04").unwrap();
    let out = lensc(
        &project,
        &["measure", "job.lens", "../part.x3p", "--job", "kim_convex"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("E0107"), "{}", text(&out.stderr));
}

/// `good`'s archive with `changed`'s point data: same main.xml (so the
/// stated MD5 is the good data's), different bytes.
fn swap_data(good: &[u8], changed: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut g = zip_entries(good);
    let c = zip_entries(changed);
    g.iter_mut()
        .find(|(n, _)| n == "bindata/data.bin")
        .unwrap()
        .1 = c
        .into_iter()
        .find(|(n, _)| n == "bindata/data.bin")
        .unwrap()
        .1;
    let mut out = std::io::Cursor::new(Vec::new());
    let mut zip = zip::ZipWriter::new(&mut out);
    for (n, b) in g {
        zip.start_file(n, zip::write::SimpleFileOptions::default())
            .unwrap();
        zip.write_all(&b).unwrap();
    }
    zip.finish().unwrap();
    out.into_inner()
}

fn zip_entries(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    use std::io::Read;
    let mut z = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    (0..z.len())
        .map(|i| {
            let mut f = z.by_index(i).unwrap();
            let mut b = Vec::new();
            f.read_to_end(&mut b).unwrap();
            (f.name().to_owned(), b)
        })
        .collect()
}

/// A point cloud (x y z text in µm) and a stylus profile (x z in mm) of
/// the placed design are registered back: ICP and the profile's fit.
#[test]
fn a_cloud_and_a_profile_are_measured_back() {
    let (dx, dy, p) = (3e-3, -2e-3, 1e-4);
    // The cloud: points on a spiral, in µm.
    let xy: Vec<(f64, f64)> = (0..3000)
        .map(|k| {
            let r = 1.5 * ((k as f64 + 0.5) / 3000.0).sqrt();
            let t = k as f64 * 2.399_963;
            (r * t.cos(), r * t.sin())
        })
        .collect();
    let moved: Vec<(f64, f64)> = xy.iter().map(|(x, y)| (x - dx, y - dy)).collect();
    let cloud: String = xy
        .iter()
        .zip(design(&moved))
        .map(|((x, y), h)| format!("{} {} {}\n", x * 1e3, y * 1e3, (h + p) * 1e3))
        .collect();
    let dir = project("cloud.xyz", cloud.as_bytes());
    let out = lensc(
        dir.path(),
        &[
            "measure",
            "job.lens",
            "cloud.xyz",
            "--job",
            "kim_convex",
            "--units",
            "um",
            "--keep-origin",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/kim_convex.measure.json")).unwrap(),
    )
    .unwrap();
    let r = &report["registration"];
    assert!(
        r["method"].as_str().unwrap().contains("closest point"),
        "{report:#}"
    );
    for (key, want) in [
        ("decentre_x_um", 3.0),
        ("decentre_y_um", -2.0),
        ("piston_um", 0.1),
    ] {
        let got = r[key].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-3f64.max(0.05 * want.abs()),
            "{key}: {got}: {report:#}"
        );
    }
    assert!(report.get("texture").is_none() && report["texture_skipped"].is_string());
    // The profile along x.
    let xs: Vec<(f64, f64)> = (0..=600).map(|i| (-1.5 + 0.005 * i as f64, 0.0)).collect();
    let moved: Vec<(f64, f64)> = xs.iter().map(|(x, _)| (x - dx, 0.0)).collect();
    let profile: String = xs
        .iter()
        .zip(design(&moved))
        .map(|((x, _), h)| format!("{x} {}\n", h + p + 20e-6 * x))
        .collect();
    let dir = project("profile.txt", profile.as_bytes());
    let out = lensc(
        dir.path(),
        &["measure", "job.lens", "profile.txt", "--job", "kim_convex"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/kim_convex.measure.json")).unwrap(),
    )
    .unwrap();
    let r = &report["registration"];
    for (key, want) in [
        ("decentre_x_um", 3.0),
        ("tilt_x_urad", 20.0),
        ("piston_um", 0.1),
    ] {
        let got = r[key].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-3f64.max(0.05 * want.abs()),
            "{key}: {got}: {report:#}"
        );
    }
}

#[test]
fn flags_out_of_range_are_usage_errors() {
    let m = placed_map(21, [0.0; 5], &|_| true, 1.0);
    let dir = project("part.x3p", &lensc_measure::write::x3p(&m, "test"));
    for bad in [
        ["--min-valid", "150"],
        ["--min-valid", "NaN"],
        ["--cutoff", "0.08"],
        ["--cutoff", "-1mm"],
    ] {
        let mut args = vec!["measure", "job.lens", "part.x3p", "--job", "kim_convex"];
        args.extend_from_slice(&bad);
        let out = lensc(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", text(&out.stderr));
        assert!(written(dir.path()).is_empty());
    }
}
