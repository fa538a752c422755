//! `lensc measure --per-lenslet` (issue #30 item 2): a map of seed 003's
//! 2 × 2 corner (tests/jobs/fts_small_array.lens) made from the job's own
//! design, with one lenslet decentred and another lifted by known amounts,
//! written as X3P and measured back lenslet by lenslet: each lenslet's own
//! registration recovers its own error within 5 % or 1 nm, the others
//! none; a mask leaving too little of a lenslet is a coded finding
//! (W0036) in the report, not a failure; `--per-lenslet` on a surface that
//! is not an array is E0368.

use std::path::Path;

use lensc_build::driver::{self, SamplePoints};
use lensc_lang::loader::RealFs;
use lensc_measure::HeightMap;

use crate::common::{lensc, root, text};

const JOB: &str = "tests/jobs/fts_small_array.lens";

/// Pixels a side and their spacing (mm): ±3.5 mm, the whole 2 × 2 corner.
const N: usize = 351;
const PIXEL: f64 = 0.02;

/// Lenslet 3 (centre 1.75, 1.75 mm) decentred by this much (mm).
const DECENTRE: (f64, f64) = (2e-3, -1.5e-3);
/// Lenslet 0 (centre −1.75, −1.75 mm) lifted by this much (mm).
const PISTON: f64 = 30e-6;

/// A project folder holding the job.
fn project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(root().join(JOB), dir.path().join("job.lens")).expect("copy job");
    dir
}

/// The map of the corner as cut with lenslet 3's cell moved by
/// `DECENTRE` and lenslet 0's lifted by `PISTON`; `keep` says which pixels
/// the instrument saw.
fn map(dir: &Path, keep: &dyn Fn(f64, f64) -> bool) -> HeightMap {
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("reads");
    let half = (N - 1) as f64 * PIXEL / 2.0;
    let mut xy = Vec::new();
    let mut moved = Vec::new();
    for j in 0..N {
        for i in 0..N {
            let (x, y) = (-half + i as f64 * PIXEL, -half + j as f64 * PIXEL);
            xy.push((x, y));
            moved.push(if x > 0.0 && y > 0.0 {
                (x - DECENTRE.0, y - DECENTRE.1)
            } else {
                (x, y)
            });
        }
    }
    let h = driver::sample(&c, "corner", &SamplePoints::Points(moved))
        .expect("samples")
        .iter()
        .map(|r| r[2])
        .collect::<Vec<f64>>();
    let z = xy
        .iter()
        .zip(h)
        .map(|(&(x, y), h)| {
            let lift = if x < 0.0 && y < 0.0 { PISTON } else { 0.0 };
            if h.is_finite() && keep(x, y) {
                h + lift
            } else {
                f64::NAN
            }
        })
        .collect();
    HeightMap::from_heights(N, N, (PIXEL, PIXEL), z)
}

fn measured(dir: &Path, m: &HeightMap, extra: &[&str]) -> (serde_json::Value, String) {
    std::fs::write(dir.join("part.x3p"), lensc_measure::write::x3p(m, "test")).expect("write part");
    let mut args = vec!["measure", "job.lens", "part.x3p", "--per-lenslet"];
    args.extend_from_slice(extra);
    let out = lensc(dir, &args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("out/corner_fts.measure.json")).expect("report"),
    )
    .expect("json");
    (report, stderr)
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Within 5 % or `abs`.
fn close(got: &serde_json::Value, want: f64, abs: f64, what: &str) {
    let got = num(got);
    assert!(
        (got - want).abs() <= abs.max(0.05 * want.abs()),
        "{what}: {got} against {want}"
    );
}

#[test]
fn each_lenslet_is_registered_on_its_own_and_recovers_its_own_error() {
    let dir = project();
    let m = map(dir.path(), &|_, _| true);
    let (report, stderr) = measured(dir.path(), &m, &[]);
    let l = &report["lenslets"];
    assert_eq!(l["in_array"], 4, "{l:#}");
    assert_eq!(l["reached"], 4, "{l:#}");
    assert_eq!(l["not_registered"], 0, "{l:#}");
    let each = l["each"].as_array().expect("each");
    for e in each {
        let k = e["index"].as_u64().unwrap();
        let r = &e["registration"];
        // µm and µrad; 1 nm, and 1 nm over the lenslet's 1 mm reach.
        let (piston, dx, dy) = match k {
            0 => (PISTON * 1e3, 0.0, 0.0),
            3 => (0.0, DECENTRE.0 * 1e3, DECENTRE.1 * 1e3),
            _ => (0.0, 0.0, 0.0),
        };
        let what = |p: &str| format!("lenslet {k} {p}: {e:#}");
        close(&r["piston_um"], piston, 1e-3, &what("piston"));
        close(&r["decentre_x_um"], dx, 1e-3, &what("decentre x"));
        close(&r["decentre_y_um"], dy, 1e-3, &what("decentre y"));
        close(&r["tilt_x_urad"], 0.0, 1.0, &what("tilt x"));
        close(&r["tilt_y_urad"], 0.0, 1.0, &what("tilt y"));
        // Its own registration leaves it as designed.
        assert!(num(&e["form_error"]["pv_nm"]) < 1.0, "{}", what("PV"));
        assert!(num(&e["form_error"]["rms_nm"]) < 1.0, "{}", what("RMS"));
        let t = &e["texture"];
        assert!(
            num(&t["sq_nm"]) < 1.0 && num(&t["sdq"]) < 1e-3,
            "{}",
            what("texture")
        );
        assert!(e.get("finding").is_none(), "{}", what("finding"));
    }
    // The whole array's registration cannot hold both errors: its PV is
    // the lifted lenslet's step and the moved one's rim.
    assert!(num(&report["form_error"]["pv_nm"]) > 20.0, "{report:#}");
    assert!(
        stderr.contains("4 of the array's 4 reached, 4 registered"),
        "{stderr}"
    );
    let svg = std::fs::read_to_string(dir.path().join("out/corner_fts.error_map.svg")).unwrap();
    assert!(svg.contains("Lenslet by lenslet"), "the picture says so");
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
}

/// Known roughness on every lenslet: a cosine of 4 nm along x, 10 pixels
/// (0.2 mm) a period, measured with a cutoff of 0.8 mm that passes it
/// whole. Each lenslet's texture holds it: Sq 4/√2 nm, Sa 4 × 0.6472 nm
/// (the mean |cos| of 10 samples a period from the crest), Sdq by central
/// differences A sin(2π/10)/(Δ√2), each within 3 % (the registration
/// takes a little of it into the tilt over a lenslet's ten periods), and
/// its form error RMS the cosine's.
#[test]
fn each_lenslets_texture_is_the_roughness_added() {
    let dir = project();
    let mut m = map(dir.path(), &|_, _| true);
    let a = 4e-6;
    let cosine = |k: usize| a * (2.0 * std::f64::consts::PI * (k % N) as f64 / 10.0).cos();
    for (k, z) in m.z.iter_mut().enumerate() {
        *z += cosine(k);
    }
    let (report, _) = measured(dir.path(), &m, &["--cutoff", "0.8mm"]);
    let mean_abs = (0..10)
        .map(|i| (2.0 * std::f64::consts::PI * i as f64 / 10.0).cos().abs())
        .sum::<f64>()
        / 10.0;
    let sdq = a * (2.0 * std::f64::consts::PI / 10.0).sin() / (PIXEL * 2f64.sqrt());
    let each = report["lenslets"]["each"].as_array().expect("each");
    assert_eq!(each.len(), 4);
    for e in each {
        let t = &e["texture"];
        let share = |got: &serde_json::Value, want: f64, what: &str| {
            let got = num(got);
            assert!(
                (got - want).abs() <= 0.03 * want,
                "lenslet {} {what}: {got} against {want}: {e:#}",
                e["index"]
            );
        };
        share(&t["cutoff_mm"], 0.8, "cutoff");
        share(&t["sq_nm"], 4.0 / 2f64.sqrt(), "Sq");
        share(&t["sa_nm"], 4.0 * mean_abs, "Sa");
        share(&t["sdq"], sdq, "Sdq");
        share(&e["form_error"]["rms_nm"], 4.0 / 2f64.sqrt(), "RMS");
    }
}

#[test]
fn a_lenslet_the_mask_leaves_too_little_of_is_a_finding_not_a_failure() {
    let dir = project();
    // Lenslet 1 (centre 1.75, −1.75 mm): nine pixels in ten masked.
    let m = map(dir.path(), &|x, y| {
        !(x > 0.0 && y < 0.0) || ((x / PIXEL).round() as i64) % 10 == 0
    });
    let (report, stderr) = measured(dir.path(), &m, &[]);
    let l = &report["lenslets"];
    assert_eq!(l["not_registered"], 1, "{l:#}");
    let one = &l["each"][1];
    assert_eq!(one["index"], 1);
    assert_eq!(one["finding"]["code"], "W0036", "{one:#}");
    assert!(one.get("registration").is_none(), "{one:#}");
    assert!(num(&one["valid_share"]) < 0.15, "{one:#}");
    assert!(
        stderr.contains("W0036") && stderr.contains("lenslet 1 (centre x = 1.75, y = -1.75 mm)"),
        "{stderr}"
    );
    // The others are measured as before.
    close(
        &l["each"][3]["registration"]["decentre_x_um"],
        DECENTRE.0 * 1e3,
        1e-3,
        "lenslet 3",
    );
}

#[test]
fn per_lenslet_on_a_surface_that_is_not_an_array_is_e0368() {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(
        root().join("examples/kim2008_convex_asphere.lens"),
        dir.path().join("job.lens"),
    )
    .expect("copy");
    let m = HeightMap::from_heights(3, 3, (0.1, 0.1), vec![0.0; 9]);
    std::fs::write(
        dir.path().join("part.x3p"),
        lensc_measure::write::x3p(&m, "test"),
    )
    .unwrap();
    let out = lensc(
        dir.path(),
        &[
            "measure",
            "job.lens",
            "part.x3p",
            "--job",
            "kim_convex",
            "--per-lenslet",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("E0368") && stderr.contains("part.x3p"),
        "{stderr}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
}
