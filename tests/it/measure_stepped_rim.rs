//! `lensc measure --lenslet` and `--per-lenslet` on an array whose
//! lenslets STEP onto the land at their rims (issue #30): seed 003's 2 × 2
//! corner (tests/jobs/fts_small_array.lens) with its spherical lenslet
//! replaced by a concave biconic (radii 20 mm in x, 12 mm in y) clipped to
//! the same 1.7 mm circle. An array puts each lenslet's rim at x = R on
//! the land, so at y = ±R the lenslet stands 12.0 µm above it: a wall,
//! not a valley. A map of it made from the job's own design, with one
//! lenslet moved, tilted and lifted by known amounts, is measured back:
//! each placement recovered within 5 % or 1 nm (1 nm over the lenslet's
//! 0.85 mm radius for a tilt: 1.2 µrad), on one lenslet's field and
//! lenslet by lenslet.

use std::path::Path;

use lensc_build::driver::{self, SamplePoints};
use lensc_lang::loader::RealFs;
use lensc_measure::HeightMap;

use crate::common::{lensc, root, text};

/// The corner's job as it is: spherical lenslets whose rims meet the land
/// all round.
fn smooth_project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(
        root().join("tests/jobs/fts_small_array.lens"),
        dir.path().join("job.lens"),
    )
    .expect("copy job");
    dir
}

/// The corner's job with the biconic lenslet.
fn project() -> tempfile::TempDir {
    let src = std::fs::read_to_string(root().join("tests/jobs/fts_small_array.lens"))
        .expect("job")
        .replace(
            "surface lenslet = sphere { radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }",
            "surface lenslet = biconic { radius_x: 20 mm, radius_y: 12 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }",
        );
    assert!(src.contains("biconic"), "the job's lenslet is replaced");
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), src).expect("write job");
    dir
}

/// How one lenslet was cut: its centre moved by `decentre` (mm), its
/// plane tilted by `tilt` (rad) about its centre and lifted `piston`
/// (mm) there.
#[derive(Clone, Copy, Default)]
struct Placed {
    decentre: (f64, f64),
    tilt: (f64, f64),
    piston: f64,
}

/// The lenslets of the corner: centres (mm), lenslet 0 at the least x
/// and y, row by row.
const CENTRES: [(f64, f64); 4] = [(-1.75, -1.75), (1.75, -1.75), (-1.75, 1.75), (1.75, 1.75)];

/// The heights of the part at `xy` (mm): each point belongs to the
/// lenslet of its quadrant, cut as `placed` says.
fn heights(dir: &Path, xy: &[(f64, f64)], placed: &[Placed; 4]) -> Vec<f64> {
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("reads");
    let cell = |x: f64, y: f64| usize::from(x > 0.0) + 2 * usize::from(y > 0.0);
    let moved = xy
        .iter()
        .map(|&(x, y)| {
            let d = placed[cell(x, y)].decentre;
            (x - d.0, y - d.1)
        })
        .collect();
    let design = driver::sample(&c, "corner", &SamplePoints::Points(moved)).expect("samples");
    xy.iter()
        .zip(design)
        .map(|(&(x, y), d)| {
            let k = cell(x, y);
            let (p, o) = (placed[k], CENTRES[k]);
            d[2] + p.piston + p.tilt.0 * (x - o.0) + p.tilt.1 * (y - o.1)
        })
        .collect()
}

/// A square map of `n` pixels a side, `pixel` apart (mm), its middle
/// pixel at `middle` on the part.
fn map(dir: &Path, n: usize, pixel: f64, middle: (f64, f64), placed: &[Placed; 4]) -> HeightMap {
    let half = (n - 1) as f64 * pixel / 2.0;
    let mut xy = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            xy.push((
                middle.0 - half + i as f64 * pixel,
                middle.1 - half + j as f64 * pixel,
            ));
        }
    }
    let z = heights(dir, &xy, placed);
    HeightMap::from_heights(n, n, (pixel, pixel), z)
}

/// Runs `lensc measure job.lens part.x3p` with `args`: its exit code,
/// stderr and report.
fn measure(dir: &Path, m: &HeightMap, args: &[&str]) -> (i32, String, Option<serde_json::Value>) {
    std::fs::write(dir.join("part.x3p"), lensc_measure::write::x3p(m, "test")).expect("write");
    let mut all = vec!["measure", "job.lens", "part.x3p"];
    all.extend_from_slice(args);
    let out = lensc(dir, &all);
    let report = std::fs::read_to_string(dir.join("out/corner_fts.measure.json"))
        .ok()
        .map(|t| serde_json::from_str(&t).expect("json"));
    (out.status.code().unwrap_or(-1), text(&out.stderr), report)
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

/// The lenslet's error, as cut.
const CUT: Placed = Placed {
    decentre: (2e-3, -1.5e-3),
    tilt: (20e-6, -35e-6),
    piston: 150e-6,
};

/// Checks a registration (`--lenslet`'s or a `--per-lenslet` entry's)
/// against `want`.
fn recovers(reg: &serde_json::Value, want: Placed, what: &str) {
    let what = |p: &str| format!("{what} {p}: {reg:#}");
    close(
        &reg["decentre_x_um"],
        want.decentre.0 * 1e3,
        1e-3,
        &what("decentre x"),
    );
    close(
        &reg["decentre_y_um"],
        want.decentre.1 * 1e3,
        1e-3,
        &what("decentre y"),
    );
    close(&reg["tilt_x_urad"], want.tilt.0 * 1e6, 1.2, &what("tilt x"));
    close(&reg["tilt_y_urad"], want.tilt.1 * 1e6, 1.2, &what("tilt y"));
    close(&reg["piston_um"], want.piston * 1e3, 1e-3, &what("piston"));
}

/// The rim really steps: the design at y = ±R just inside the lenslet
/// stands 12 µm above the land just outside it (and at x = ±R lies on it).
#[test]
fn the_biconic_lenslets_rim_steps_onto_the_land() {
    let dir = project();
    let (c, r) = (CENTRES[3], 0.85);
    let z = heights(
        dir.path(),
        &[
            (c.0, c.1 + r - 1e-4),
            (c.0, c.1 + r + 1e-4),
            (c.0 + r - 1e-4, c.1),
        ],
        &[Placed::default(); 4],
    );
    assert!((z[0] - z[1] - 0.012).abs() < 2e-4, "step at y = R: {z:?}");
    assert!(z[1].abs() < 1e-9, "land: {z:?}");
    assert!(z[2].abs() < 1e-5, "no step at x = R: {z:?}");
}

/// Lenslet 1's field (1.8 mm, 400 × 400 pixels of 4.5 µm, centred on
/// it), the lenslet moved (2, −1.5) µm, tilted (20, −35) µrad and lifted
/// 150 nm: `--lenslet 1` recovers each within 5 % or 1 nm, no clocking
/// (under 1.2 µrad), and leaves the design (form error RMS under 1 nm).
#[test]
fn a_stepped_rim_lenslets_field_recovers_its_placement() {
    let dir = project();
    let mut placed = [Placed::default(); 4];
    placed[1] = CUT;
    let m = map(dir.path(), 400, 4.5e-3, CENTRES[1], &placed);
    let (code, stderr, report) = measure(dir.path(), &m, &["--lenslet", "1"]);
    assert_eq!(code, 0, "{stderr}");
    let r = report.expect("report");
    let reg = &r["registration"];
    recovers(reg, CUT, "--lenslet 1");
    // The report says what was left out.
    let method = reg["method"].as_str().expect("method");
    assert!(
        method.contains("leaving out the pixels within 13.5 µm of the lenslets' rims, which step onto the land by up to 12.1 µm"),
        "{method}"
    );
    close(
        &reg["clocking_urad"],
        0.0,
        1.2,
        &format!("clocking: {reg:#}"),
    );
    assert!(
        num(&r["form_error"]["rms_nm"]) < 1.0,
        "{:#}",
        r["form_error"]
    );
}

/// The whole corner (±3.5 mm, 701 × 701 pixels of 10 µm), lenslet 3
/// moved, tilted and lifted as above and lenslet 0 lifted 30 nm:
/// `--per-lenslet` registers each of the four and recovers each one's
/// own placement within 5 % or 1 nm.
#[test]
fn a_stepped_rim_array_is_registered_lenslet_by_lenslet() {
    let dir = project();
    let mut placed = [Placed::default(); 4];
    placed[3] = CUT;
    placed[0].piston = 30e-6;
    let m = map(dir.path(), 701, 0.01, (0.0, 0.0), &placed);
    let (code, stderr, report) = measure(dir.path(), &m, &["--per-lenslet"]);
    assert_eq!(code, 0, "{stderr}");
    let r = report.expect("report");
    let l = &r["lenslets"];
    assert_eq!(l["not_registered"], 0, "{l:#}");
    let method = l["method"].as_str().expect("method");
    assert!(
        method.contains("the pixels within three pixels (30.0 µm) of the lenslets' rims"),
        "{method}"
    );
    let whole = r["registration"]["method"].as_str().expect("method");
    assert!(
        whole.contains("within 30.0 µm of the lenslets' rims"),
        "{whole}"
    );
    let each = l["each"].as_array().expect("each");
    assert_eq!(each.len(), 4, "{l:#}");
    for e in each {
        let k = e["index"].as_u64().expect("index") as usize;
        recovers(&e["registration"], placed[k], &format!("lenslet {k}"));
        assert!(num(&e["form_error"]["rms_nm"]) < 1.0, "lenslet {k}: {e:#}");
    }
}

/// Spherical lenslets meet the land all round: no rim steps, and every
/// pixel is registered, as before (the methods say nothing of rims).
#[test]
fn rims_that_meet_the_land_leave_no_pixel_out() {
    let dir = smooth_project();
    let m = map(dir.path(), 351, 0.02, (0.0, 0.0), &[Placed::default(); 4]);
    let (code, stderr, report) = measure(dir.path(), &m, &["--per-lenslet"]);
    assert_eq!(code, 0, "{stderr}");
    let r = report.expect("report");
    for method in [&r["registration"]["method"], &r["lenslets"]["method"]] {
        let method = method.as_str().expect("method");
        assert!(!method.contains("rims"), "{method}");
    }
}
