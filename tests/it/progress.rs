//! Progress of `build` and `report`: the JSON events of
//! `--message-format json` (their order, and counts that add up to what
//! is on disk), nothing on a stderr that is no terminal, nothing with
//! `--quiet`, and the bar on a terminal (run under `script`'s pty).

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common::{root, text};

/// Seed 002's pattern on its roller, cut over 2 mm at a fine finish
/// pitch: about 110,000 points, enough for several progress steps.
const ROLLER: &str = "surface pattern = freeform {
    z(x, y) = 0.02 mm * (sin(5 rad/mm * x) + cos(10 rad/(3 mm) * y)) - 0.04 mm
    domain: rect(x: 0 mm .. 6.283185307179586 mm, y: 0 mm .. 18.84955592153876 mm)
}
surface on_roller = wrap(pattern, onto: roller(radius: 3 mm))
use std::machines::moore_nanotech_450fg
tool diamond = round_nose { nose_radius: 1.417567 mm, clearance: 12.5 deg, included_angle: 100 deg }
strategy fine = roller_helix {
    rough: { c_step: 2 deg, pitch: 0.2 mm, finish_allowance: 10 um }
    finish: { c_step: 0.5 deg, pitch: 0.02 mm }
    z: 0.5 mm .. 2.5 mm
    spindle_speed: 60 rpm
    blank_radius: 3.01 mm
}
job roller_fine { surface: on_roller, tool: diamond, machine: moore_nanotech_450fg, strategy: fine, accept: { form_pv: 100 nm, form_rms: 30 nm, max_gouge: 100 nm, uncut_area: 0 } }
";

/// Runs lensc with `args` (the output directory appended), returning
/// the exit code, stdout and stderr.
fn run(args: &[&str], out_dir: &Path) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_lensc"))
        .current_dir(root())
        .args(args)
        .arg("--out")
        .arg(out_dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("run lensc");
    (out.status.code(), text(&out.stdout), text(&out.stderr))
}

/// The progress events among stdout's JSON lines (diagnostics have no
/// `event`); every line must be one JSON object.
fn events(stdout: &str) -> Vec<Value> {
    stdout
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .filter(|v| v.get("event").is_some())
        .collect()
}

fn u(v: &Value, key: &str) -> u64 {
    v[key]
        .as_u64()
        .unwrap_or_else(|| panic!("no count `{key}` in {v}"))
}

fn size(path: &Path) -> u64 {
    std::fs::metadata(path).expect("written file").len()
}

/// Checks one run's events against each other and the files in `dir`:
/// the order of each job's phases, counts that only grow, the last
/// planning count equal to the job's, the bytes written equal to the
/// files' sizes, and the closing totals equal to the sums. Returns the
/// planning progress events per job.
fn check_events(ev: &[Value], dir: &Path, jobs: u64) -> Vec<Vec<(u64, u64)>> {
    assert_eq!(ev[0]["event"], "start", "{ev:?}");
    assert_eq!(u(&ev[0], "jobs"), jobs);
    let done = ev.last().expect("events");
    assert_eq!(done["event"], "done");
    assert_eq!(done["ok"], true);
    let mut planned = Vec::new();
    let (mut points, mut built) = (0, 0);
    for (i, start) in ev.iter().enumerate().filter(|(_, v)| v["event"] == "job") {
        let job = start["job"].as_str().expect("job name");
        let own: Vec<&Value> = ev[i + 1..].iter().filter(|v| v["job"] == job).collect();
        let phases: Vec<&str> = own
            .iter()
            .filter(|v| v["event"] == "phase")
            .map(|v| v["phase"].as_str().expect("phase"))
            .collect();
        assert_eq!(phases[..2], ["lowering", "planning"], "{job}: {phases:?}");
        assert_eq!(phases.last(), Some(&"writing"), "{job}: {phases:?}");
        let progress: Vec<(u64, u64)> = own
            .iter()
            .filter(|v| v["event"] == "progress" && v["phase"] == "planning")
            .map(|v| (u(v, "points"), u(v, "bytes")))
            .collect();
        assert!(!progress.is_empty(), "{job}: no planning progress");
        assert!(
            progress
                .windows(2)
                .all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1),
            "{job}: counts that shrink: {progress:?}"
        );
        let job_done = own
            .iter()
            .find(|v| v["event"] == "job-done")
            .expect("job-done");
        assert_eq!(job_done["built"], true);
        assert_eq!(
            *progress.last().unwrap(),
            (u(job_done, "points"), u(job_done, "bytes"))
        );
        points += u(job_done, "points");
        built += 1;
        // The writing phase: bytes that grow to the total, which is what
        // the job's files hold on disk.
        let written = own
            .iter()
            .find(|v| v["event"] == "written")
            .expect("written");
        let total = u(written, "bytes");
        let writing: Vec<u64> = own
            .iter()
            .filter(|v| v["event"] == "progress" && v["phase"] == "writing")
            .map(|v| u(v, "bytes"))
            .collect();
        assert!(writing.windows(2).all(|w| w[0] < w[1]), "{writing:?}");
        assert_eq!(writing.last(), Some(&total));
        assert_eq!(writing.len() as u64, u(written, "files"));
        let on_disk: u64 = std::fs::read_dir(dir)
            .expect("out dir")
            .map(|e| e.expect("entry").path())
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.split('.').next() == Some(job))
            })
            .map(|p| size(&p))
            .sum();
        assert_eq!(total, on_disk, "{job}");
        planned.push(progress);
    }
    assert_eq!(built, jobs);
    assert_eq!(u(done, "built"), built);
    assert_eq!(u(done, "points"), points);
    let files: Vec<_> = std::fs::read_dir(dir).expect("out dir").collect();
    assert_eq!(u(done, "files"), files.len() as u64);
    let all: u64 = files
        .into_iter()
        .map(|e| size(&e.expect("entry").path()))
        .sum();
    assert_eq!(u(done, "bytes"), all);
    planned
}

#[test]
fn json_events_of_a_small_build_add_up_to_its_files() {
    let dir = tempfile::tempdir().expect("tmp");
    let (code, stdout, stderr) = run(
        &[
            "build",
            "examples/even_asphere_turning.lens",
            "--message-format",
            "json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{stderr}");
    let ev = events(&stdout);
    let planned = check_events(&ev, dir.path(), 2);
    // A profile is planned at once: one count, at the end.
    assert!(planned.iter().all(|p| p.len() == 1), "{planned:?}");
    let planning = ev
        .iter()
        .find(|v| v["event"] == "phase" && v["phase"] == "planning")
        .expect("planning phase");
    assert!(u(planning, "estimated_points") > 0);
}

#[test]
fn a_streamed_build_is_told_a_step_at_a_time() {
    let src = tempfile::tempdir().expect("tmp");
    let file = src.path().join("roller_fine.lens");
    std::fs::write(&file, ROLLER).expect("write job");
    let dir = tempfile::tempdir().expect("tmp");
    let file = file.to_str().expect("utf-8 path");
    let (code, stdout, stderr) = run(&["build", file, "--message-format", "json"], dir.path());
    assert_eq!(code, Some(0), "{stderr}");
    let ev = events(&stdout);
    let planned = check_events(&ev, dir.path(), 1);
    let steps = &planned[0];
    let points = steps.last().unwrap().0;
    // Told every 10,000 points or so, never a point at a time.
    let step = lensc_build::progress::MIN_STEP;
    assert!(points > 5 * step, "{points} points");
    assert!(steps.len() as u64 >= points / step / 2, "{steps:?}");
    assert!(steps.len() as u64 <= points / step + 2, "{steps:?}");
    assert!(steps.windows(2).all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1));
}

#[test]
fn report_tells_its_plots_as_it_writes_them() {
    let dir = tempfile::tempdir().expect("tmp");
    let (code, stdout, stderr) = run(
        &[
            "report",
            "examples/even_asphere_turning.lens",
            "--message-format",
            "json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{stderr}");
    let ev = events(&stdout);
    check_events(&ev, dir.path(), 2);
}

#[test]
fn nothing_on_a_stderr_that_is_no_terminal() {
    let dir = tempfile::tempdir().expect("tmp");
    let (code, stdout, stderr) = run(&["build", "examples/even_asphere_turning.lens"], dir.path());
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(stdout, "");
    // Only the summaries, a job's name then its indented lines: no bar,
    // no carriage return, no escape.
    // (After the warnings the build has, W0031 among them.)
    let summaries = stderr.rsplit("───╯\n").next().unwrap_or(&stderr);
    assert!(
        summaries
            .lines()
            .all(|l| l.starts_with("  ") || l.ends_with(": passed, written")),
        "{stderr}"
    );
    assert!(
        !stderr.contains('\r') && !stderr.contains('\x1b'),
        "{stderr:?}"
    );
    assert_eq!(stderr.lines().filter(|l| l.contains("  wrote ")).count(), 2);
}

#[test]
fn quiet_prints_no_progress_even_in_json() {
    for command in ["build", "report"] {
        let dir = tempfile::tempdir().expect("tmp");
        let (code, stdout, stderr) = run(
            &[
                command,
                "examples/even_asphere_turning.lens",
                "--message-format",
                "json",
                "--quiet",
            ],
            dir.path(),
        );
        assert_eq!(code, Some(0), "{stderr}");
        assert!(events(&stdout).is_empty(), "{command}: {stdout}");
        // The work is done all the same.
        assert!(std::fs::read_dir(dir.path()).expect("out").count() >= 2);
    }
}

#[test]
fn a_refused_job_is_done_unbuilt() {
    // The spiral's estimate is over the size limit: refused in lowering.
    let dir = tempfile::tempdir().expect("tmp");
    let (code, stdout, _) = run(
        &[
            "build",
            "tests/jobs/fts_small_array.lens",
            "--message-format",
            "json",
            "--max-program-size",
            "1kB",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(1));
    let ev = events(&stdout);
    let job_done = ev
        .iter()
        .find(|v| v["event"] == "job-done")
        .expect("job-done");
    assert_eq!(job_done["built"], false);
    assert!(
        !ev.iter()
            .any(|v| v["event"] == "phase" && v["phase"] == "planning")
    );
    let done = ev.last().expect("done");
    assert_eq!(
        (done["event"].as_str(), done["ok"].as_bool()),
        (Some("done"), Some(false))
    );
    assert_eq!((u(done, "built"), u(done, "files")), (0, 0));
    // Diagnostics and events share stdout, one object a line.
    assert!(stdout.lines().any(|l| l.contains("\"severity\"")));
}

/// On a terminal (a pty that `script` makes), a build of more than a
/// second draws its bar on stderr: the job, the phase, the points.
#[test]
fn a_terminal_sees_the_bar() {
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped: no `script` (util-linux) to make a pty");
        return;
    }
    let src = tempfile::tempdir().expect("tmp");
    let file = src.path().join("roller_fine.lens");
    std::fs::write(&file, ROLLER.replace("pitch: 0.02 mm", "pitch: 0.002 mm")).expect("write job");
    let dir = tempfile::tempdir().expect("tmp");
    let command = format!(
        "{} build {} --out {}",
        env!("CARGO_BIN_EXE_lensc"),
        file.display(),
        dir.path().display()
    );
    let run = |extra: &str| {
        let out = Command::new("script")
            .args(["-qefc", &format!("{command} {extra}"), "/dev/null"])
            .env("NO_COLOR", "1")
            .env("LENSC_PROGRESS_AFTER_MS", "0")
            .output()
            .expect("run script");
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
        text(&out.stdout)
    };
    let shown = run("");
    assert!(shown.contains("roller_fine planning "), "{shown:?}");
    assert!(shown.contains(" points, "), "{shown:?}");
    assert!(shown.contains("roller_fine writing "), "{shown:?}");
    assert!(shown.contains("wrote "), "{shown:?}");
    let quiet = run("--quiet");
    assert!(!quiet.contains("planning"), "{quiet:?}");
    assert!(quiet.contains("wrote "), "{quiet:?}");
}
