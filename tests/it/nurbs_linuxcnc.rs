//! LinuxCNC's NURBS block (G5.2 … G5.3) read by `lensc verify` against the
//! real interpreter (issue #28, item 3): hand-written programs, valid and
//! broken, get the same verdict from `lensc verify` and `rs274 -g` (or a
//! policy finding of lensc's own where rs274 runs them, each listed here
//! with its code); and on the valid ones the curve the reader moves along
//! passes within 2 nm of every point LinuxCNC's own evaluation gives.
//!
//! `rs274 -g` prints a NURBS block as `NURBS_FEED(n, ...)`, without its
//! points. Its points come from the interpreter's Python module `gcode`
//! (the AXIS preview's, same package linuxcnc-uspace, `gcodemodule.cc`),
//! whose `NURBS_FEED` calls `nurbs_point` at 15 points per control point
//! and hands each over as a straight feed: the same `nurbs_point` and
//! `knot_vector_creator` the motion controller evaluates.

use std::path::Path;
use std::process::Command;

use crate::common::{lensc, root, text};
use lensc_runtime::dialect::Dialect;
use lensc_runtime::reader::{self, MachineLimits, Path as MovePath};

/// The programs' frame: a LinuxCNC mill, the tool at X0 Y0 Z-0.1 feeding.
const HEAD: &str = "(machine generic_3axis_mill: linuxcnc 3-axis mill)
(units mm; X Y Z of the control point, +Z out of the material; no cutter compensation)
G17 G21 G90 G40 G49 G80 G94 G54
T1 M6 G43 H1
G97 S1000 M3
G0 Z1.
G0 X0. Y0.
G1 Z-0.1 F100.
";
const TAIL: &str = "G0 Z1.\nM5\nM2\n";

/// What rs274 and lensc each make of a program.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    /// Both run it.
    Runs,
    /// Both refuse it; lensc with this code first.
    Refused(&'static str),
    /// rs274 runs it; lensc refuses it as its own policy, with this code.
    Policy(&'static str),
}

/// (name, the blocks between HEAD and TAIL, the verdict).
const CASES: &[(&str, &str, Verdict)] = &[
    (
        "the manual's example (11.5.9)",
        "G5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nX0 Y0 P2\nG5.3\n",
        Verdict::Runs,
    ),
    (
        "first point on the G5.2 line, order 4",
        "G5.2 X0.5 Y1 P1 L4\nX1.5 Y1.5 P0.5\nX2 Y0.5 P1\nX3 Y1 P2\nX3 Y0 P1\nG5.3\n",
        Verdict::Runs,
    ),
    (
        "a weight for the current point",
        "G5.2 P3\nX1 Y1 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Runs,
    ),
    (
        "L2 is order 3",
        "G5.2 X0 Y1 P1 L2\nX2 Y2 P1\nG5.3\n",
        Verdict::Runs,
    ),
    (
        "incremental points, from the curve's start",
        "G1 X1. Y1.\nG91\nG5.2 X0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\nG90\n",
        Verdict::Runs,
    ),
    (
        "in the ZX plane (rs274 does not check the plane)",
        "G18\nG5.2 X0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\nG17\n",
        Verdict::Runs,
    ),
    (
        "a feed word and an M code inside",
        "G5.2 X0 Y1 P1\nX2 Y2 P1 F50.\nM8\nX2 Y0 P1\nG5.3\nM9\n",
        Verdict::Runs,
    ),
    (
        "no G5.3: the curve is never cut",
        "G5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nG1 X0 Y0\n",
        Verdict::Policy("E0337"),
    ),
    (
        "no G5.3 before the end",
        "G5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\n",
        Verdict::Policy("E0337"),
    ),
    (
        "no weight on the first G5.2 line's point (read as -1)",
        "G5.2 X0 Y1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Policy("E0338"),
    ),
    (
        "L above the points given",
        "G5.2 X0 Y1 P1 L5\nX2 Y2 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "too few points for order 3",
        "G5.2 X0 Y1 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "L negative",
        "G5.2 X0 Y1 P1 L-1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "L not whole",
        "G5.2 X0 Y1 P1 L3.5\nX2 Y2 P1\nX2 Y0 P1\nX3 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "a later point without P",
        "G5.2 X0 Y1 P1\nX2 Y2\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "a later point with P0",
        "G5.2 X0 Y1 P1\nX2 Y2 P0\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "X without Y",
        "G5.2 X0 Y1 P1\nX2 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    (
        "a second G5.2 with P and no X Y",
        "G5.2 X0 Y1 P1\nG5.2 P2\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0340"),
    ),
    ("G5.3 alone", "G5.3\n", Verdict::Refused("E0340")),
    (
        "G5.3 beside G1",
        "G5.2 X0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nG1 G5.3\n",
        Verdict::Refused("E0307"),
    ),
    (
        "a P alone in the mode",
        "G5.2 X0 Y1 P1\nP2\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0333"),
    ),
    (
        "an I word on a G5.2 block",
        "G5.2 X0 Y1 P1 I1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\n",
        Verdict::Refused("E0333"),
    ),
];

fn program(blocks: &str) -> String {
    format!("{HEAD}{blocks}{TAIL}")
}

fn rs274_runs(path: &Path) -> bool {
    let _one_at_a_time = crate::rs274::RS274
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let out = Command::new("rs274")
        .arg("-g")
        .arg(path)
        .output()
        .expect("rs274 is not installed: apt-get install linuxcnc-uspace (.ci/run does this)");
    out.status.code() == Some(0)
}

#[test]
fn g5_2_programs_get_rs274s_verdict() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut wrong = Vec::new();
    for (k, (name, blocks, verdict)) in CASES.iter().enumerate() {
        let path = dir.path().join(format!("n{k}.ngc"));
        std::fs::write(&path, program(blocks)).expect("write");
        let runs = rs274_runs(&path);
        let out = lensc(&root(), &["verify", path.to_str().expect("utf8")]);
        let stderr = text(&out.stderr);
        let first = stderr.lines().next().unwrap_or("").to_string();
        let ok = match verdict {
            Verdict::Runs => runs && out.status.code() == Some(0),
            Verdict::Refused(code) => {
                !runs && out.status.code() == Some(1) && first.starts_with(&format!("[{code}]"))
            }
            Verdict::Policy(code) => {
                runs && out.status.code() == Some(1)
                    && first.starts_with(&format!("[{code}] Error: policy"))
            }
        };
        if !ok {
            wrong.push(format!(
                "{name}: expected {verdict:?}; rs274 runs: {runs}; lensc exit {:?}: {first}",
                out.status.code()
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// LinuxCNC's own points of every NURBS block in `path` (mm), from its
/// Python module `gcode`; `None` where the module is not there.
fn linuxcnc_points(path: &Path, dir: &Path) -> Option<Vec<(f64, f64)>> {
    let script = r#"
import sys, gcode
class Canon:
    parameter_file = sys.argv[2]
    def __init__(self): self.feeds = []
    def straight_feed(self, x, y, *rest): self.feeds.append((x * 25.4, y * 25.4))
    def get_tool(self, n): return (n, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0)
    def get_external_angular_units(self): return 1.0
    def get_external_length_units(self): return 1 / 25.4
    def get_axis_mask(self): return 7
    def get_block_delete(self): return 0
    def check_abort(self): return False
    def __getattr__(self, name): return lambda *a, **k: None
c = Canon()
gcode.parse(sys.argv[1], c, "G21", "")
for x, y in c.feeds: print(repr(x), repr(y))
"#;
    let params = dir.join("params.var");
    std::fs::write(&params, "").expect("write");
    let out = Command::new("/usr/bin/python3")
        .arg("-c")
        .arg(script)
        .arg(path)
        .arg(&params)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    Some(
        text(&out.stdout)
            .lines()
            .map(|l| {
                let mut v = l.split(' ').map(|s| s.parse::<f64>().expect("number"));
                (v.next().expect("x"), v.next().expect("y"))
            })
            .collect(),
    )
}

/// Distance from `p` to the segment a–b.
fn to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 == 0.0 {
        0.0
    } else {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    };
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

#[test]
fn the_curve_read_passes_through_linuxcncs_points() {
    let dir = tempfile::tempdir().expect("temp dir");
    let machine = MachineLimits {
        lathe: false,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for (k, (name, blocks, verdict)) in CASES.iter().enumerate() {
        if *verdict != Verdict::Runs {
            continue;
        }
        // The curve alone after the frame's moves: the straight feeds of
        // the frame (G1 Z-0.1) are left out by their Y, X (both 0).
        let text = program(blocks);
        // The module crashes (SIGSEGV) on a tool change, whose tool table
        // it has not loaded: it reads the program without `T1 M6 G43 H1`,
        // which moves nothing.
        let path = dir.path().join(format!("p{k}.ngc"));
        let without_tool: String = text
            .lines()
            .filter(|l| !l.contains("M6"))
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(&path, without_tool).expect("write");
        let Some(theirs) = linuxcnc_points(&path, dir.path()) else {
            assert!(
                std::env::var_os("CI").is_none(),
                "LinuxCNC's Python module gcode is not importable by /usr/bin/python3 (package linuxcnc-uspace)"
            );
            eprintln!("skipped: LinuxCNC's Python module gcode is not here");
            return;
        };
        let (found, moves) = reader::read_moves(&text, &Dialect::linuxcnc(), &machine);
        assert_eq!(found, vec![], "{name}");
        let ours: Vec<((f64, f64), (f64, f64))> = moves
            .iter()
            .filter(|m| m.path == MovePath::Line)
            .filter_map(|m| Some(((m.from[0]?, m.from[1]?), (m.to[0]?, m.to[1]?))))
            .filter(|(a, b)| a != b)
            .collect();
        // Their points after the curve's start: the NURBS_FEED's feeds
        // (the first feed of the frame goes down Z at X0 Y0 and is skipped).
        let curve: Vec<(f64, f64)> = theirs.into_iter().skip(1).collect();
        assert!(curve.len() >= 45, "{name}: {} points", curve.len());
        for p in &curve {
            let d = ours
                .iter()
                .map(|&(a, b)| to_segment(*p, a, b))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
            assert!(
                d <= 2e-6,
                "{name}: LinuxCNC's point {p:?} is {d:e} mm from the curve read"
            );
        }
        checked += 1;
    }
    eprintln!("{checked} curves, largest distance from LinuxCNC's points {worst:e} mm");
    assert!(checked >= 6);
}
