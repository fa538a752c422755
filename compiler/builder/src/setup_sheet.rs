//! The set-up sheet written beside every program (`JOB.setup.txt`), as a
//! CAM system prints one: what the machinist sets up before cycle start —
//! the tool and what each of its offsets is measured to, the work offset,
//! the stock, the control point (and a lathe tool's tip direction), the
//! spindle and coolant, how the program ends, the expected cycle time, and
//! a list of what to check. It is written in the same unit as the program
//! and its report (`output::put_in_place`), from the job's head and the
//! program's own header, so it states what the program does.

use std::io::BufRead;

use crate::job::JobHead;
use crate::output::{Built, ProgramText};
use lensc_runtime::moves::{Coolant, Rotation};

/// The sheet's name after the job's (`JOB.setup.txt`): reserved, as the
/// report's is (E0188).
pub const EXTENSION: &str = "setup.txt";

/// The sheet's file name for `job`.
pub fn name(job: &str) -> String {
    format!("{job}.{EXTENSION}")
}

/// The program's first lines (its header and set-up blocks).
fn first_lines(program: &ProgramText) -> Vec<String> {
    match program {
        ProgramText::Memory(t) => t.lines().take(80).map(str::to_string).collect(),
        ProgramText::Spooled { file, .. } => std::fs::File::open(file.path())
            .map(|f| {
                std::io::BufReader::new(f)
                    .lines()
                    .take(80)
                    .map_while(Result::ok)
                    .collect()
            })
            .unwrap_or_default(),
    }
}

/// The workpiece blank the program states for the control's graphic
/// test run, in words: Heidenhain ISO's `G30` (least corner) and `G31`
/// (greatest), Klartext's `BLK FORM 0.1` and `BLK FORM 0.2`, each with
/// X Y Z; `None` where the program states none.
fn stated_blank(lines: &[String]) -> Option<String> {
    let corner = |starts: &dyn Fn(&[&str]) -> bool| -> Option<[f64; 3]> {
        lines.iter().find_map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            if !starts(&words) {
                return None;
            }
            let mut c = [None; 3];
            for w in &words {
                let (letter, number) = w.split_at_checked(1)?;
                let i = ["X", "Y", "Z"].iter().position(|a| *a == letter);
                if let (Some(i), Ok(v)) = (i, number.parse::<f64>()) {
                    c[i] = Some(v);
                }
            }
            Some([c[0]?, c[1]?, c[2]?])
        })
    };
    let has = |code: &'static str| move |w: &[&str]| w.contains(&code);
    let blk = |n: &'static str| move |w: &[&str]| w.windows(3).any(|t| t == ["BLK", "FORM", n]);
    let (low, high, how) = match (corner(&has("G30")), corner(&has("G31"))) {
        (Some(l), Some(h)) => (l, h, "G30/G31"),
        _ => (corner(&blk("0.1"))?, corner(&blk("0.2"))?, "BLK FORM"),
    };
    let n = lensc_runtime::post::header::num;
    Some(format!(
        "X {} .. {}, Y {} .. {}, Z {} .. {} mm, as the program's blank form ({how}) states it for the control's graphic test run: a box holding every cut, 1 mm below the deepest; this is a finishing program, the blank must be roughed to within the strategy's cut of the surface",
        n(low[0]),
        n(high[0]),
        n(low[1]),
        n(high[1]),
        n(low[2]),
        n(high[2])
    ))
}

/// The comments of the program's header (its first lines), folded lines
/// joined, in their order.
fn header_comments(lines: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for line in lines {
        let Some(text) = lensc_runtime::reader::comment_text(line) else {
            continue;
        };
        // A line folded at ", " ends in ","; one folded between words
        // does not: either way the next starts with two spaces.
        match (out.last_mut(), text.strip_prefix("  ")) {
            (Some(last), Some(rest)) => {
                last.push(' ');
                last.push_str(rest.trim_start());
            }
            _ => out.push(text.trim().to_string()),
        }
    }
    out
}

/// The work offset the dialect's setup selects (`G54`…`G59`, `G500`…,
/// `G54.1 P…`), if it selects one.
fn work_offset(head: &JobHead, lathe: bool) -> Option<String> {
    let setup = if lathe {
        &head.dialect.lathe_setup
    } else {
        &head.dialect.mill_setup
    };
    setup
        .iter()
        .flat_map(|l| l.split_whitespace())
        .find_map(|w| {
            let n: u32 = w.strip_prefix('G')?.split('.').next()?.parse().ok()?;
            ((54..=59).contains(&n) || (500..=599).contains(&n)).then(|| w.to_string())
        })
}

/// The set-up sheet of the job `head` built as `built` (its report
/// complete: estimate and acceptance filled in).
pub fn sheet(head: &JobHead, built: &Built) -> String {
    let first = first_lines(&built.program);
    let comments = header_comments(&first);
    let starting = |p: &str| comments.iter().find(|c| c.starts_with(p)).cloned();
    let after = |p: &str| starting(p).map(|c| c[p.len()..].trim().to_string());
    let lathe = comments
        .iter()
        .any(|c| c.starts_with("machine ") && !c.contains("mill"));
    let start = &head.start;
    let control = &head.control;
    let offset = start.control;
    let mut s = String::new();
    // A label and its text; neither: a blank line between sections.
    let mut line = |label: &str, text: &str| {
        if label.is_empty() {
            s.push('\n');
        } else {
            s.push_str(&format!("{label:<15}{text}\n"));
        }
    };
    line("SET-UP SHEET", &format!("job {}", head.name));
    line(
        "program",
        &format!(
            "{}, dialect {}, {} lines; report {}",
            built.program_name,
            head.dialect.name,
            built.program.lines(),
            built.report_name
        ),
    );
    if let Some(src) = after("source ") {
        line("source", &src);
    }
    line(
        "machine",
        &after("machine ").unwrap_or_else(|| head.names.machine.clone()),
    );
    line(
        "surface",
        &after("surface ").unwrap_or_else(|| head.names.surface.clone()),
    );
    line("", "");
    line(
        "work offset",
        &match work_offset(head, lathe) {
            Some(w) => format!(
                "{w}: X0 Y0 Z0 at the surface's vertex (design origin){}, +Z out of the material",
                if lathe { " on the spindle axis" } else { "" }
            ),
            None => "the datum the control has active (the program selects none): X0 Y0 Z0 at the surface's vertex (design origin), +Z out of the material".to_string(),
        },
    );
    line(
        "stock",
        &match (
            comments.iter().find(|c| c.contains("stock")),
            stated_blank(&first),
        ) {
            (Some(c), _) => format!("as the program's strategy states it: {c}"),
            (None, Some(blank)) => blank,
            (None, None) => "the job states none: this is a finishing program; the blank must be roughed to within the strategy's cut of the surface".to_string(),
        },
    );
    line("", "");
    line(
        "tool",
        &format!(
            "T{} with offset register {}: {}",
            start.tool,
            start.offset,
            after("tool ").unwrap_or_else(|| head.names.tool.clone())
        ),
    );
    line(
        "control point",
        &format!(
            "{} ({}): the program's coordinates are this point of the tool",
            control.name(),
            control.whose()
        ),
    );
    line("offsets to", &control.measured_to);
    line(
        "from centre",
        &format!(
            "the control point is X{:+} Y{:+} Z{:+} mm from the tool's centre (the point the path is planned for)",
            offset.x, offset.y, offset.z
        ),
    );
    if lathe {
        line(
            "tip direction",
            if control.tip {
                "3 (imaginary tip on the nose's -X and -Z sides); compensation is off (G40): the control does not use it"
            } else {
                "0 (the nose centre); compensation is off (G40): the control does not use it"
            },
        );
    }
    line(
        "spindle",
        &format!(
            "{}; coolant {}",
            match start.rotation {
                Rotation::Clockwise => "clockwise (M3) when it turns",
                Rotation::CounterClockwise => "counter-clockwise (M4) when it turns",
            },
            match start.coolant {
                Coolant::Off => "off",
                Coolant::Flood => "flood",
                Coolant::Mist => "mist",
            }
        ),
    );
    if let Some(i) = after("interpolation: ") {
        line("interpolation", &i);
    }
    line(
        "program ends",
        &format!("{} (the dialect's end blocks)", head.dialect.end.join(", ")),
    );
    line(
        "cycle time",
        &format!(
            "{} estimated cutting time (the cut at its feeds; rapids, tool change and dwells not counted)",
            lensc_runtime::post::header::duration(built.cutting_time)
        ),
    );
    s.push('\n');
    s.push_str("before cycle start:\n");
    let mut check = |text: String| s.push_str(&format!("[ ] {text}\n"));
    check(format!(
        "offset register {} holds the length{} measured to the {}",
        start.offset,
        if lathe { " and X" } else { "" },
        match (control.tip, lathe) {
            (true, true) => "imaginary tip (X on a diameter, Z on the face)",
            (true, false) => "tip of the tool (its lowest point)",
            (false, _) => "tool's centre",
        }
    ));
    check(
        "no cutter or nose-radius compensation is applied: the tool table's radius is not used"
            .to_string(),
    );
    check(format!(
        "{} is set at the surface's vertex{}",
        work_offset(head, lathe).unwrap_or_else(|| "the active datum".to_string()),
        if lathe {
            "; X0 on the spindle axis (the edge on centre)"
        } else {
            ""
        }
    ));
    if lathe {
        check(
            "the turret is clear of the part: the tool call indexes where the machine stands"
                .to_string(),
        );
    } else {
        check(
            "the machine stands clear above the part: the program's first move is a rapid"
                .to_string(),
        );
    }
    check("the program runs dry (or in the control's graphics) above the part first".to_string());
    s
}

/// Adds the sheet to what `built` writes beside its program.
pub(crate) fn add(head: &JobHead, built: &mut Built) {
    let text = sheet(head, built);
    built
        .beside
        .push((name(&head.name), ProgramText::Memory(text)));
}

#[cfg(test)]
mod tests {
    use super::stated_blank;

    fn lines(text: &str) -> Vec<String> {
        text.lines().map(str::to_string).collect()
    }

    /// The blank as Heidenhain ISO (`G30`/`G31`) and Klartext (`BLK
    /// FORM`) programs state it; none where a program states none.
    #[test]
    fn the_blank_the_program_states_is_read() {
        let iso = lines(
            "N13 G17 G90 G40 G94 *\nN14 G30 G17 X-1. Y-1.02 Z-1.1286 *\nN15 G31 G90 X1. Y1.02 Z0.0009 *\nN16 T1 G17 *",
        );
        let s = stated_blank(&iso).expect("a blank");
        assert!(
            s.starts_with("X -1 .. 1, Y -1.02 .. 1.02, Z -1.1286 .. 0.0009 mm, as the program's blank form (G30/G31)"),
            "{s}"
        );
        let klartext = lines(
            "13 BLK FORM 0.1 Z X-0.8 Y-0.84 Z-1.1566\n14 BLK FORM 0.2 X+0.8 Y+0.84 Z+0\n15 TOOL CALL 1 Z S12000",
        );
        let s = stated_blank(&klartext).expect("a blank");
        assert!(
            s.starts_with("X -0.8 .. 0.8, Y -0.84 .. 0.84, Z -1.1566 .. 0 mm, as the program's blank form (BLK FORM)"),
            "{s}"
        );
        let linuxcnc = lines("G17 G21 G90 G40 G49 G80 G94 G54\nT1 M6 G43 H1\nG0 Z0.5");
        assert_eq!(stated_blank(&linuxcnc), None);
        // One corner alone is no blank.
        assert_eq!(stated_blank(&iso[..2]), None);
    }
}
