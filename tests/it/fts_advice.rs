//! E0147's advice is a true bound: for every fast-tool-servo example (its
//! servo weakened until the job is refused), the small array of
//! tests/jobs/ and the refused jobs of tests/bad_builds/, the job built at
//! the advised speed passes (its servo's lag within the job's limit, or,
//! where the advice says it lags more, within the limit the advice says
//! to state), and the speed the advice names as refused,
//! within 5 % above it, is refused by the planner itself or by the
//! build's checks of the led commands it writes: the advice is neither
//! optimistic nor absurdly conservative.

use std::path::Path;

use crate::common::{examples, root};
use lensc_build::driver::{Request, check_path, plan_and_emit};
use lensc_build::strategy::JobSpec;
use lensc_build::strategy::spiral::{Prepared, advice};
use lensc_lang::check::trim_num;
use lensc_lang::loader::RealFs;
use lensc_runtime::plan::spiral::{FtsError, SpeedAdvice};

/// The fast tool servo the examples use, with `max_acceleration` weakened.
const WEAK_FTS5000: &str = "machine nanoform_x_fts5000 = fts_lathe {
    dialect: linuxcnc
    resolution: 1 nm
    travel: { x: -10 mm .. 220 mm, z: -150 mm .. 150 mm }
    max_feed: 1000 mm/min
    spindle: { max_speed: 1000 rpm }
    fast_axis: { stroke: 5 mm, max_acceleration: 3 G, resonance: 1367 Hz, resonant_peak: 1.0, data_rate: 20 kHz }
}";

/// The job's single spiral, lowered as a build lowers it.
fn spiral_of(file: &Path) -> lensc_build::strategy::spiral::SpiralSpec {
    let checked = check_path(&RealFs, file).expect("readable");
    assert!(!checked.has_errors(), "{}", file.display());
    let job = &checked.checked.jobs[0];
    let (spec, _) = lensc_build::pipeline::lower(job, None, &Default::default())
        .unwrap_or_else(|d| panic!("{}: {d:?}", file.display()));
    match spec {
        JobSpec::Spiral(s) => s,
        _ => panic!("{} is not a spiral job", file.display()),
    }
}

/// The refusal's acceleration (mm/s²) when the job is planned as written.
fn refused_at(file: &Path) -> Option<f64> {
    let spec = spiral_of(file);
    match Prepared::of(&spec).planner().check(&spec.fast_axis) {
        Ok(_) => None,
        Err(FtsError::AccelerationExceeded { acceleration, .. }) => Some(acceleration),
        Err(e) => panic!("{}: {e:?}", file.display()),
    }
}

/// `text` with its strategy's speed (`spindle_speed: … rpm` or
/// `surface_speed: … m/min`) set to `value` in the same unit.
fn with_speed(text: &str, value: &str) -> String {
    for key in ["spindle_speed: ", "surface_speed: "] {
        if let Some(at) = text.find(key) {
            let start = at + key.len();
            let end = start + text[start..].find(' ').expect("a unit follows");
            return format!("{}{value}{}", &text[..start], &text[end..]);
        }
    }
    panic!("no speed in {text}")
}

/// A speed (rad/s or mm/s) as E0147's help writes it, in the job's unit.
fn written(text: &str, v: f64) -> String {
    trim_num(if text.contains("spindle_speed: ") {
        v * 60.0 / (2.0 * std::f64::consts::PI)
    } else {
        v * 60.0 / 1000.0
    })
}

/// Finds the advice for the refused job `text`, builds it at the advised
/// speed (it must pass; `judged`: its part's acceptance criteria too) and
/// plans it at the speed named as refused (it must be refused, within 5 %
/// above). Returns both, in the job's unit.
fn advice_holds(name: &str, text: &str, judged: bool) -> (String, String) {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join(format!("{name}.lens"));
    std::fs::write(&file, text).expect("write");
    let acceleration =
        refused_at(&file).unwrap_or_else(|| panic!("{name} is not refused as written"));
    let SpeedAdvice::Found { passes, fails, lag } = advice::search(&spiral_of(&file), acceleration)
    else {
        panic!("{name}: no speed found")
    };
    let (passes, fails) = (written(text, passes), written(text, fails));
    let number = |s: &str| s.parse::<f64>().expect("a number");
    assert!(
        number(&fails) <= 1.05 * number(&passes),
        "{name}: {passes} passes, {fails} fails: too conservative"
    );
    // Refused at the speed named as refused: by the planner itself, or,
    // where the program leads the servo, by the build's checks of what
    // it writes (the lead's acceleration, a move over the machine's feed).
    std::fs::write(&file, with_speed(text, &fails)).expect("write");
    assert!(
        refused_at(&file).is_some() || advice::refused_as_written(&spiral_of(&file)),
        "{name}: {fails} passes"
    );
    // Built at the advised speed: the servo follows, with no error at
    // all, its lag within the job's limit, or (the advice says so) within
    // the limit the advice names. The part's form is not what the advice
    // is about: unless `judged`, its criteria only warn (a coarse feed's
    // rim misses the default limits a 50 nm tolerance gives), so only the
    // planner's own errors and the servo's count.
    let mut text = with_speed(text, &passes);
    if let Some(l) = lag {
        let accepted = trim_num(advice::accepted_lag_nm(l.lag));
        eprintln!("{name}: the servo lags {} nm at {passes}", l.lag * 1e6);
        text = with_accepted_lag(&text, &accepted);
    }
    std::fs::write(&file, &text).expect("write");
    let mode = if judged {
        lensc_build::accept::Mode::Gate
    } else {
        lensc_build::accept::Mode::Warn
    };
    let (built, diags) = build(name, &file, mode);
    assert!(
        !diags.iter().any(|d| d.is_error()),
        "{name} at {passes}: {diags:?}"
    );
    assert_eq!(built.len(), 1);
    let following = following_error(&built[0].report);
    assert!(following.passed, "{name} at {passes}: {following:?}");
    (passes, fails)
}

/// `text` with its job accepting a following error of `nm` nm, as E0147's
/// help says to write it.
fn with_accepted_lag(text: &str, nm: &str) -> String {
    let job = text
        .lines()
        .find(|l| l.starts_with("job "))
        .expect("a job line");
    let stated = format!("max_following_error: {nm} nm");
    let new_job = if let Some(at) = job.find("max_following_error: ") {
        let end = at + job[at..].find(" nm").expect("a limit in nm") + " nm".len();
        format!("{}{stated}{}", &job[..at], &job[end..])
    } else if job.contains("accept: { ") {
        job.replacen("accept: { ", &format!("accept: {{ {stated}, "), 1)
    } else {
        let block = job.trim_end().strip_suffix('}').expect("a job block");
        format!("{block}, accept: {{ {stated} }} }}")
    };
    text.replace(job, &new_job)
}

/// Builds `file` (its one job `name`) with the gate in `mode`.
fn build(
    name: &str,
    file: &Path,
    mode: lensc_build::accept::Mode,
) -> (
    Vec<lensc_build::output::Built>,
    Vec<lensc_grammar::Diagnostic>,
) {
    let checked = check_path(&RealFs, file).expect("readable");
    let spool = tempfile::tempdir().expect("tmp");
    let request = Request {
        accept: mode,
        ..Request::default()
    };
    plan_and_emit(&checked, request, name, Some(spool.path()))
}

/// The report's following-error criterion (every fast-tool-servo job
/// here has a servo model, so it is gated).
fn following_error(report: &lensc_build::report::Report) -> lensc_build::report::CriterionResult {
    report
        .acceptance
        .criteria
        .iter()
        .find(|c| c.criterion == "max_following_error")
        .cloned()
        .expect("the following error is judged")
}

#[test]
fn every_fts_example_builds_at_its_advised_speed() {
    let mut tried = 0;
    for path in examples() {
        let text = std::fs::read_to_string(&path).expect("read");
        if !text.contains("fts_spiral") {
            continue;
        }
        let servo = "use std::machines::nanoform_x_fts5000";
        assert!(
            text.contains(servo),
            "{}: teach this test its machine",
            path.display()
        );
        let weak = text.replace(servo, WEAK_FTS5000);
        let name = path.file_stem().expect("stem").to_string_lossy();
        let (passes, fails) = advice_holds(&name, &weak, false);
        eprintln!("{name} (servo at 3 G): {passes} passes, {fails} fails");
        tried += 1;
    }
    assert!(tried >= 1, "no fast-tool-servo example");
}

#[test]
fn the_small_array_builds_at_its_advised_speed() {
    let text = std::fs::read_to_string(root().join("tests/jobs/fts_small_array.lens"))
        .expect("read")
        .replace("use std::machines::nanoform_x_fts5000", WEAK_FTS5000);
    let (passes, fails) = advice_holds("fts_small_array", &text, false);
    eprintln!("fts_small_array (servo at 3 G): {passes} passes, {fails} fails");
}

#[test]
fn refused_bad_builds_build_at_their_advised_speed() {
    // The hex array's whole part passes its default limits at its advised
    // speed: judged lenslet by lenslet, as every array is (issue #29: with
    // no lenslet centres for a hex grid its land was judged, where the
    // settled spiral holds the tool 10.85 um above it by design: 10.9 um
    // PV "missed").
    for (name, judged) in [
        ("fts_hex_array_too_fast", true),
        ("fts_acceleration_exceeded", false),
    ] {
        let text = std::fs::read_to_string(root().join(format!("tests/bad_builds/{name}.lens")))
            .expect("read");
        let (passes, fails) = advice_holds(name, &text, judged);
        eprintln!("{name}: {passes} passes, {fails} fails");
    }
}
