//! `lensc view`'s pages in a real browser: Debian's Chromium, headless,
//! loads each page from the disk (no network), and the page's script
//! writes what it did into `#lensc-status` — the script errors it caught,
//! the segments and map cells it drew, the canvas pixels that are not
//! background, the figures it shows. The figures must be the build
//! report's own. Without `chromium` the tests say so and pass, except
//! under CI (`.ci/run` installs it), where they fail.

use std::path::Path;

use serde_json::Value;

use crate::common::{lensc, root};

/// A small ball-end raster (a cubic phase plate 1 mm across): seconds.
const SMALL_RASTER: &str = "use std::machines::generic_3axis_mill

surface plate = xy_polynomial {
    aperture: circle(diameter: 1 mm)
    sense: concave
    X3Y0: 2e-3 mm^-2
    X0Y3: 2e-3 mm^-2
}

tool ball = ball_end { diameter: 1 mm }

strategy mill = raster { along: x, stepover: 20 um, feed: 500 mm/min, spindle_speed: 20000 rpm }

job small_plate { surface: plate, tool: ball, machine: generic_3axis_mill, strategy: mill }
";

/// Whether Chromium runs here (required under CI).
fn chromium() -> bool {
    let found = std::process::Command::new("chromium")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must install chromium for this test"
        );
        eprintln!("skipped: no chromium on PATH");
    }
    found
}

/// The page's status record once Chromium has loaded and run it.
pub fn status_in_chromium(page: &Path) -> Value {
    let profile = tempfile::tempdir().expect("tmp");
    let run = std::process::Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--dump-dom",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("file://{}", page.display()))
        .stdin(std::process::Stdio::null())
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&run.stdout);
    let Some(start) = dom.find("id=\"lensc-status\"") else {
        panic!(
            "no status in the page as Chromium left it: {}\n{}",
            String::from_utf8_lossy(&run.stderr),
            &dom[..dom.len().min(2000)]
        );
    };
    let text = &dom[start..];
    let text = &text[text.find('>').expect("tag") + 1..];
    let text = &text[..text.find("</pre>").expect("end")];
    let text = text
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("status {text:?}: {e}"))
}

/// Views `job` of `file` and builds it (for its report); returns the
/// page's status, the page's text and the report.
fn view_and_build(file: &Path, job: &str) -> (Value, String, Value) {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().to_str().expect("utf8");
    let file = file.to_str().expect("utf8");
    let viewed = lensc(&root(), &["view", file, "--job", job, "--out", out, "-q"]);
    assert!(
        viewed.status.success(),
        "{}",
        String::from_utf8_lossy(&viewed.stderr)
    );
    let built_dir = dir.path().join("built");
    let built = lensc(
        &root(),
        &[
            "build",
            file,
            "--job",
            job,
            "--out",
            built_dir.to_str().expect("utf8"),
            "-q",
        ],
    );
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let page_path = dir.path().join(format!("{job}.view.html"));
    let page = std::fs::read_to_string(&page_path).expect("the page");
    let report: Value = serde_json::from_str(
        &std::fs::read_to_string(built_dir.join(format!("{job}.report.json"))).expect("report"),
    )
    .expect("json");
    // Only the page: no program, report or spool file is left beside it.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n != "built")
        .collect();
    assert_eq!(names, vec![format!("{job}.view.html")]);
    (status_in_chromium(&page_path), page, report)
}

/// What every page must show: no script error, a scene drawn, and the
/// report's own figures.
fn holds_to_its_report(status: &Value, page: &str, report: &Value) {
    assert_eq!(status["errors"], serde_json::json!([]), "{status}");
    // Self-contained: nothing fetched.
    for fetch in ["<script src", "<link", "http://", "https://", "@import"] {
        assert!(!page.contains(fetch), "the page fetches: {fetch}");
    }
    assert!(page.len() < 8 << 20, "{} bytes", page.len());
    let segments = status["segments_drawn"].as_u64().expect("segments");
    assert!(segments > 0, "{status}");
    assert!(status["map_cells_drawn"].as_u64().expect("cells") > 0);
    // 900 × 640 canvas: a scene covers a good part of it.
    let pixels = status["pixels_drawn"].as_u64().expect("pixels");
    assert!(pixels > 20_000, "{pixels} pixels drawn");
    let f = &status["figures"];
    let a = &report["acceptance"];
    assert_eq!(f["passed"], a["passed"]);
    assert_eq!(f["judged"], a["judged"]["words"]);
    assert_eq!(
        f["cutting_time_s"].as_f64(),
        report["toolpath"]["cutting_time_s"].as_f64()
    );
    let criteria = a["criteria"].as_array().expect("criteria");
    assert!(!criteria.is_empty());
    assert_eq!(
        f["criteria"].as_object().expect("shown").len(),
        criteria.len()
    );
    for c in criteria {
        let shown = &f["criteria"][c["criterion"].as_str().expect("name")];
        for key in ["measured", "limit", "unit", "passed"] {
            // Numbers as numbers (JavaScript writes 5.0 as 5).
            match (shown[key].as_f64(), c[key].as_f64()) {
                (Some(a), Some(b)) => assert_eq!(a, b, "{}: {key}", c["criterion"]),
                _ => assert_eq!(shown[key], c[key], "{}: {key}", c["criterion"]),
            }
        }
    }
    assert!(f["setup_rows"].as_u64().expect("rows") >= 5, "{status}");
    // Every move read is counted; this small program is drawn whole.
    let m = &status["moves"];
    assert_eq!(m["step_mm"], 0.0);
    assert_eq!(
        m["rapids"].as_u64().unwrap() + m["feeds"].as_u64().unwrap(),
        segments
    );
}

#[test]
fn a_turned_jobs_page_loads_draws_and_shows_its_reports_figures() {
    if !chromium() {
        return;
    }
    let (status, page, report) = view_and_build(
        &root().join("examples/forbes_qcon_asphere.lens"),
        "condenser_finish",
    );
    holds_to_its_report(&status, &page, &report);
    assert_eq!(status["moves"]["passes"], 1);
}

#[test]
fn a_raster_jobs_page_loads_draws_and_shows_its_reports_figures() {
    if !chromium() {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("small_plate.lens");
    std::fs::write(&file, SMALL_RASTER).expect("write");
    let (status, page, report) = view_and_build(&file, "small_plate");
    holds_to_its_report(&status, &page, &report);
    // One pass per stroke of the raster.
    assert!(status["moves"]["passes"].as_u64().unwrap() > 10, "{status}");
}

/// `--dialect` views the program `build --dialect` writes (its page names
/// that dialect, its backplot read in it); a dialect the machine does not
/// offer is refused as `build` refuses it, nothing written. No browser:
/// the page's own data is read.
#[test]
fn a_page_is_of_the_program_in_the_dialect_asked() {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("small_plate.lens");
    std::fs::write(&file, SMALL_RASTER).expect("write");
    let file = file.to_str().expect("utf8");
    let view = |dialect: &str, out: &str| {
        let out = dir.path().join(out);
        let o = lensc(
            &root(),
            &[
                "view",
                file,
                "--dialect",
                dialect,
                "--out",
                out.to_str().expect("utf8"),
                "-q",
            ],
        );
        (o, out.join("small_plate.view.html"))
    };
    let (o, page) = view("heidenhain_tnc_klartext", "klartext");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = std::fs::read_to_string(page).expect("the page");
    assert!(
        page.contains(r#""dialect":"heidenhain_tnc_klartext""#),
        "the page does not name the dialect asked"
    );
    let (o, page) = view("fanuc_0i_lathe", "lathe");
    let said = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{said}");
    assert!(said.contains("[E0148]"), "{said}");
    assert!(!page.exists() && !page.parent().expect("dir").exists());
}
