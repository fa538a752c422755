//! `lensc report`: the SVG plots of what a program will cut, as a user
//! meets them (files, titles, axes, exit codes, nothing written on
//! failure) and the series behind them (their sizes, from the driver).

use crate::common::{lensc, root, text};
use lensc_build::driver::{self, Request};
use lensc_build::plots::{self, PlotSeries};
use lensc_lang::loader::RealFs;

/// Runs `lensc report` into a fresh directory; returns it and the output.
fn report(args: &[&str]) -> (tempfile::TempDir, std::process::Output) {
    let dir = tempfile::tempdir().expect("tmp");
    let out_dir = dir.path().to_str().expect("utf8").to_string();
    let mut all = vec!["report"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", &out_dir]);
    let out = lensc(&root(), &all);
    (dir, out)
}

/// The files in `dir`, sorted.
fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Checks what every plot must be and returns its text.
fn well_formed(path: &std::path::Path, title: &str, axes: &[&str]) -> String {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    assert!(svg.starts_with("<svg"), "{path:?} starts {:?}", &svg[..40]);
    assert!(svg.trim_end().ends_with("</svg>"), "{path:?}");
    assert!(svg.contains(title), "{path:?} lacks its title {title:?}");
    for a in axes {
        assert!(svg.contains(a), "{path:?} lacks the axis label {a:?}");
    }
    // No number that is not one: nothing in the captions spells these.
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "{path:?}");
    svg
}

/// The number of points of each polyline drawn in `colour` (#RRGGBB).
fn polylines(svg: &str, colour: &str) -> Vec<usize> {
    svg.split("<polyline")
        .skip(1)
        .filter(|p| p.contains(&format!("stroke=\"{colour}\"")))
        .map(|p| {
            let pts = p.split("points=\"").nth(1).expect("points");
            pts[..pts.find('"').expect("end")]
                .split_whitespace()
                .count()
        })
        .collect()
}

/// The plot series of every job of `file`, built as `lensc report` does.
fn series(file: &str) -> Vec<(String, PlotSeries, serde_json::Value)> {
    let c = driver::check_path(&RealFs, &root().join(file)).expect("read");
    assert!(!c.has_errors());
    let (built, diags) = driver::plan_and_emit(&c, Request::default(), file, None);
    assert!(!diags.iter().any(|d| d.is_error()), "{file}");
    built
        .into_iter()
        .map(|b| (b.report.job.clone(), b.plots, b.report.to_json()))
        .collect()
}

#[test]
fn a_profile_job_plots_design_path_cut_and_form_error() {
    let (dir, out) = report(&[
        "examples/kim2008_convex_asphere.lens",
        "--job",
        "kim_convex",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(listing(dir.path()), vec!["kim_convex.profile.svg"]);
    let svg = well_formed(
        &dir.path().join("kim_convex.profile.svg"),
        "kim_convex: profile, tool path and simulated cut",
        &[
            "radius r (mm)",
            "height z (mm)",
            "nose centre Z (mm)",
            "form error, cut − design (nm)",
            "design",
            "simulated cut",
            "nose centre path, as printed (right axis)",
        ],
    );
    // The form error (green): the 20,001 simulated radii in runs of 21,
    // each drawn by its least and largest value; the legend's sample is
    // the 2-point line.
    let run = plots::PROFILE_SAMPLES.div_ceil(plots::PROFILE_POINTS / 2);
    let want = 2 * plots::PROFILE_SAMPLES.div_ceil(run);
    assert_eq!((run, want), (21, 1906));
    assert_eq!(polylines(&svg, "#2CA02C"), vec![want, 2]);
    assert!(svg.contains(&format!("runs of {run} consecutive ones")));
}

#[test]
fn a_profile_with_seams_marks_them() {
    let (dir, out) = report(&["examples/lei2021_cylinder_array.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let svg = well_formed(
        &dir.path().join("cylinder_rings.profile.svg"),
        "cylinder_rings: profile",
        &["seam", "form error, cut − design (nm)"],
    );
    // One dashed line per seam the report lists.
    let all = series("examples/lei2021_cylinder_array.lens");
    let (_, s, report) = &all[0];
    let seams = report["toolpath"]["seams"].as_array().expect("seams").len();
    let p = s.profile.as_ref().expect("profile series");
    assert_eq!(p.seams.len(), seams);
    assert!(seams > 1);
    assert!(svg.contains(&format!("the {seams} concave corners")));
    assert_eq!(p.samples.len(), report["simulation"]["samples"]);
}

#[test]
fn profile_series_agree_with_the_report() {
    for (job, s, report) in series("examples/kim2008_convex_asphere.lens") {
        let p = s.profile.expect("a profile job has a profile series");
        assert!(s.form_error.is_none() && s.following.is_none());
        let sim = &report["simulation"];
        assert_eq!(p.samples.len(), plots::PROFILE_SAMPLES, "{job}");
        let worst = p
            .samples
            .iter()
            .map(|q| q.2)
            .fold(f64::NEG_INFINITY, f64::max);
        let want = sim["max_residual_nm"]["value"].as_f64().expect("nm");
        assert!((worst.max(0.0) * 1e6 - want).abs() < 1e-9, "{job}");
        // The tool's centre runs over the whole simulated profile.
        let radii = p.centre_path.iter().flatten().map(|q| q.0.abs());
        let (lo, hi) = radii.fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
            (lo.min(r), hi.max(r))
        });
        let (from, to) = (p.samples[0].0, p.samples[p.samples.len() - 1].0);
        assert!(
            lo <= from + 1e-9 && hi >= to - 0.01,
            "{job}: {lo} {hi} vs {from} {to}"
        );
    }
}

#[test]
fn a_roller_job_maps_its_form_error_with_a_scale() {
    let (dir, out) = report(&["tests/jobs/roller_small.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(listing(dir.path()), vec!["roller_small.form_error.svg"]);
    let svg = well_formed(
        &dir.path().join("roller_small.form_error.svg"),
        "roller_small: form error over the simulation window",
        &[
            "along the roller axis, design x (mm)",
            "around the roller, design y (mm)",
            "form error, cut − design (nm)",
        ],
    );
    // The whole part by default (issue #29): every cell of the raster,
    // one per block.
    let all = series("tests/jobs/roller_small.lens");
    let f = all[0].1.form_error.as_ref().expect("height map series");
    let (nx, ny) = (f.raster.nx, f.raster.ny);
    assert!(nx * ny > 201 * 201 / 10, "{nx} × {ny}");
    assert!(
        svg.contains(&format!("Shown on {nx} × {ny} blocks")),
        "{nx} × {ny}"
    );
    // The scale: one rectangle per colour level, and the map's colours are
    // the scale's.
    let fills = |s: &str| -> Vec<String> {
        s.split("<rect")
            .skip(2) // the page's background
            .filter_map(|r| r.split("fill=\"").nth(1).map(|f| f[..7].to_string()))
            .collect()
    };
    let all_fills = fills(&svg);
    let scale = &all_fills[all_fills.len() - plots::COLOUR_LEVELS..];
    let distinct: std::collections::BTreeSet<&String> = scale.iter().collect();
    assert_eq!(distinct.len(), plots::COLOUR_LEVELS);
    for f in &all_fills[..all_fills.len() - plots::COLOUR_LEVELS] {
        assert!(distinct.contains(f), "map colour {f} is not on the scale");
    }
    // The largest block value is the report's highest residual; the least
    // lies within the report's PV of it (a block keeps its cells' error of
    // largest magnitude, so a shallow low beside a high peak may not show
    // once blocks hold many cells, as they do over the whole part).
    let (lo, hi) = f.raster.range().expect("cut blocks");
    let hm = &all[0].2["simulation"]["height_map"]["surface"];
    let max = hm["max_residual_nm"]["value"].as_f64().expect("nm");
    let pv = hm["pv_nm"].as_f64().expect("nm");
    assert!(
        (hi * 1e6 - max).abs() < 1e-9 && (hi - lo) * 1e6 <= pv + 1e-9,
        "blocks {lo} .. {hi} mm, report max {max} nm, pv {pv} nm"
    );
}

#[test]
fn an_fts_job_plots_following_error_and_height_map() {
    let (dir, out) = report(&["tests/jobs/fts_small_array.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        listing(dir.path()),
        vec!["corner_fts.following.svg", "corner_fts.form_error.svg"],
        "the program is spooled there and dropped"
    );
    let svg = well_formed(
        &dir.path().join("corner_fts.following.svg"),
        "corner_fts: fast-tool-servo following error",
        &["radius r (mm)", "following error (nm)"],
    );
    well_formed(
        &dir.path().join("corner_fts.form_error.svg"),
        "corner_fts: form error over the simulation window",
        &["x (mm)", "y (mm)", "form error, cut − design (nm)"],
    );
    let all = series("tests/jobs/fts_small_array.lens");
    let (_, s, report) = &all[0];
    let f = s.following.as_ref().expect("following series");
    assert_eq!(f.by_radius.bins.len(), plots::FOLLOWING_BINS);
    // Every sample is simulated; only those where the nose cuts are
    // gathered (moves wholly above the part's top, the settling plateau
    // and the land, are not: issue #29), so the bins hold fewer.
    let binned: u64 = f.by_radius.bins.iter().map(|b| b.samples).sum();
    let simulated = report["simulation"]["servo_samples"]
        .as_u64()
        .expect("samples");
    assert!(binned > 0 && binned < simulated, "{binned} of {simulated}");
    // Each bin holding samples is a stroke from its least to its largest.
    let used = f.by_radius.bins.iter().filter(|b| b.samples > 0).count();
    // Only the radii where the nose cuts hold samples: the 2 × 2 corner's
    // lenslets (centres 2.475 mm from the axis, 1.7 mm across) lie at
    // 1.625 .. 3.325 mm of the spiral's 0 .. 4.95 mm.
    let width = (f.by_radius.to - f.by_radius.from) / plots::FOLLOWING_BINS as f64;
    let radii: Vec<f64> = (f.by_radius.bins.iter().enumerate())
        .filter(|(_, b)| b.samples > 0)
        .map(|(i, _)| f.by_radius.from + (i as f64 + 0.5) * width)
        .collect();
    let (inner, outer) = (radii[0], radii[radii.len() - 1]);
    assert!(
        inner > 1.6 && outer < 3.35 && used * 5 > plots::FOLLOWING_BINS,
        "{used} bins from {inner} to {outer} mm"
    );
    assert_eq!(polylines(&svg, "#1F77B4"), vec![2 * used, 2]);
    let peak = f
        .by_radius
        .bins
        .iter()
        .map(|b| b.max.max(-b.min))
        .fold(0.0, f64::max);
    let max = report["simulation"]["max_following_error_nm"]["value"]
        .as_f64()
        .expect("nm");
    assert!((peak * 1e6 - max).abs() < 1e-9, "{peak} vs {max}");
    assert!(s.form_error.is_some());
}

#[test]
fn a_job_the_file_lacks_is_a_usage_error() {
    let (dir, out) = report(&["examples/kim2008_convex_asphere.lens", "--job", "nope"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("no job `nope`"));
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn a_failing_job_leaves_no_plot_at_all() {
    // A wheel too large for the bowl fails; the lathe job beside it would
    // plot on its own.
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("two_jobs.lens");
    std::fs::write(
        &file,
        "surface bowl = conic { radius: 1.5 mm, conic: 0, sense: concave, aperture: circle(radius: 1 mm) }
use std::machines::nano_grinder
use std::tools::wheel_d4mm
strategy g = profile_grinding { interval: 2 um, feed: 10 um/s, smoothness: 0.5, spindle_speed: 30000 rpm }
job wheel { surface: bowl, tool: wheel_d4mm, machine: nano_grinder, strategy: g }
use std::machines::linuxcnc_lathe
tool small = round_nose { nose_radius: 0.1 mm, clearance: 10 deg }
machine my_lathe = linuxcnc_lathe { resolution: 2 nm }
strategy turn = profile_turning { feed: 20 um/s, spindle_speed: 1000 rpm, chord_tolerance: 10 nm }
job good { surface: bowl, tool: small, machine: my_lathe, strategy: turn }
",
    )
    .expect("write");
    let out_dir = dir.path().join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "report",
            file.to_str().expect("utf8"),
            "--out",
            out_dir.to_str().expect("utf8"),
        ];
        args.extend_from_slice(extra);
        lensc(&root(), &args)
    };
    let out = run(&[]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("wheel"));
    assert!(
        listing(&out_dir).is_empty(),
        "nothing written, no temporary file left: {:?}",
        listing(&out_dir)
    );
    let out = run(&["--job", "good"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(listing(&out_dir), vec!["good.profile.svg"]);
}

/// `--dialect` plots the program `build --dialect` writes; a dialect the
/// machine does not offer is refused as `build` refuses it, nothing
/// written.
#[test]
fn a_dialect_the_machine_offers_is_plotted_and_one_it_does_not_is_refused() {
    let file = "examples/kim2008_convex_asphere.lens";
    let job = ["--job", "kim_convex"];
    let (dir, out) = report(&[
        file,
        job[0],
        job[1],
        "--dialect",
        "siemens_840d_lathe",
        "-q",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(listing(dir.path()), vec!["kim_convex.profile.svg"]);
    let (dir, out) = report(&[file, job[0], job[1], "--dialect", "fanuc_0i_mill", "-q"]);
    let said = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("[E0148]"), "{said}");
    assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
}

#[test]
fn report_is_described_in_help() {
    let out = lensc(&root(), &["report", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    let help = text(&out.stdout);
    for word in [
        "profile.svg",
        "form_error.svg",
        "following.svg",
        "--job",
        "--dialect",
        "--out",
    ] {
        assert!(help.contains(word), "{word}: {help}");
    }
}
