use super::*;

fn lathe() -> MachineLimits {
    MachineLimits {
        lathe: true,
        travel: [Some((-10.0, 150.0)), None, Some((-100.0, 100.0)), None],
        max_feed: Some(2000.0),
        max_spindle_rpm: Some(3000.0),
        servo: None,
    }
}

/// The rules broken, in order of their lines.
fn rules(text: &str, d: &Dialect, m: &MachineLimits) -> Vec<Rule> {
    read(text, d, m).into_iter().map(|f| f.rule).collect()
}

const GOOD: &str = "(units mm; X is the radius, Z along the spindle axis, +Z out of the material)
G18 G21 G90 G8 G40 G49 G80
T1 M6
G97 S500 M3
G0 X3 Z1.5
G95 G1 Z0.1 F0.002
G2 X0 Z0.469317 I-3 K-12
G0 Z1.5
M5
M2
";

#[test]
fn a_complete_program_reads_clean() {
    assert_eq!(rules(GOOD, &Dialect::linuxcnc(), &lathe()), vec![]);
}

#[test]
fn each_change_breaks_its_rule() {
    let d = Dialect::linuxcnc();
    let cases: &[(&str, &str, Rule)] = &[
        ("T1 M6\n", "", Rule::NoTool),
        ("G97 S500 M3\n", "G97 S500\n", Rule::SpindleStopped),
        ("G97 S500 M3\n", "S500 M3\n", Rule::SpindleSpeedMode),
        ("G95 G1 Z0.1 F0.002", "G1 Z0.1 F0.002", Rule::NoFeedMode),
        ("G95 G1 Z0.1 F0.002", "G95 G1 Z0.1", Rule::NoFeedRate),
        ("G0 X3 Z1.5", "G0 X3 Z151.5", Rule::OutsideTravel),
        ("F0.002", "F5", Rule::FeedTooHigh),
        ("G0 Z1.5\nM5", "G0 Z1.5 X5\nG0 Z0\nM5", Rule::RapidIntoPart),
        ("Z0.469317", "Z0.6", Rule::ArcRadiusMismatch),
        ("I-3 K-12", "I-3 J-12", Rule::ArcWords),
        ("G18 G21 G90", "G18 G90", Rule::ModalStateUnstated),
        ("M2\n", "", Rule::ProgramEnd),
        ("M2\n", "M2\nM5\n", Rule::BlockAfterEnd),
        ("G0 X3 Z1.5", "G0 G1 X3 Z1.5", Rule::SameModalGroup),
        ("G0 X3 Z1.5", "G0 X3 X3 Z1.5", Rule::RepeatedWord),
        ("G97 S500", "G97 S5000", Rule::SpindleTooFast),
        ("G97 S500", "G96 S50", Rule::NoSpeedCap),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 (approach", Rule::UnclosedComment),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 (a (b) c)", Rule::NestedComment),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 E3", Rule::UnknownWord),
        ("M5", "M5.5", Rule::DecimalPoint),
    ];
    for (from, to, rule) in cases {
        let text = GOOD.replacen(from, to, 1);
        assert_ne!(text, GOOD, "{from}");
        let found = rules(&text, &d, &lathe());
        assert!(found.contains(rule), "{to}: {found:?}");
    }
}

#[test]
fn fanuc_reads_x_as_a_diameter_and_s_as_a_whole_number() {
    let mut d = Dialect::linuxcnc();
    d.start = vec!["%".into(), "O{number} ({JOB})".into()];
    d.lathe_setup = vec!["G18 G21 G40 G80 G90".into()];
    d.lathe_x_diameter = true;
    d.max_digits = Some(8);
    d.max_decimals = Some(4);
    assert_eq!(Controller::of(&d), Controller::Fanuc);
    let good = "%\nO1 (J)\nG18 G21 G40 G80 G90\nT0101\nG97 S500 M3\nG0 X6. Z1.5\nG95 G1 Z0.1 F0.002\nG2 X0. Z0.4693 I-3. K-12.\nG0 Z1.5\nM5\nM30\n%\n";
    assert_eq!(rules(good, &d, &lathe()), vec![]);
    let bad = good.replace("S500", "S500.");
    assert_eq!(rules(&bad, &d, &lathe()), vec![Rule::DecimalPoint]);
    let bad = good.replace("Z0.4693", "Z0.46932");
    assert_eq!(rules(&bad, &d, &lathe()), vec![Rule::TooManyDecimals]);
}

#[test]
fn inverse_time_needs_f_in_every_feed_block() {
    let text = "(+Z out of the material)\nG18 G21 G90 G8\nT1 M6\nG0 X2 C0\nG0 Z1\nG93 G1 Z0 F60\nG1 X1.99 C10 F100\nG1 X1.98 C20\nG0 Z1\nM2\n";
    let found = read(text, &Dialect::linuxcnc(), &lathe());
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].rule, found[0].line), (Rule::NoFeedRate, 8));
}

#[test]
fn a_finding_spans_its_words_in_the_whole_text() {
    let text = GOOD.replace("G0 X3 Z1.5\n", "G0 X3 Z1.5 E3\n");
    let found = read(&text, &Dialect::linuxcnc(), &lathe());
    let f = found
        .iter()
        .find(|f| f.rule == Rule::UnknownWord)
        .expect("found");
    assert_eq!(&text[f.span.0..f.span.1], "E3");
    assert_eq!(f.line, 5);
}

#[test]
fn the_header_names_machine_and_dialect() {
    let h = header_names("(lensc)\n(machine ultra_precision_lathe: linuxcnc lathe)\nG0 X0\n");
    assert_eq!(
        h,
        Some(HeaderNames {
            machine: "ultra_precision_lathe".into(),
            dialect: "linuxcnc".into(),
            kind: "lathe".into()
        })
    );
    let h = header_names("N9 ; machine generic_3axis_mill: heidenhain_iso 3-axis mill *\n");
    assert_eq!(h.map(|h| h.dialect), Some("heidenhain_iso".into()));
}

#[test]
fn heidenhain_reads_arc_centres_where_they_are() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    d.block_end = " *".into();
    d.line_numbers = Some(1);
    d.max_line_number = Some(99999);
    d.arc_centre_absolute = true;
    d.surface_speed = Vec::new();
    d.constant_rpm = None;
    assert_eq!(Controller::of(&d), Controller::HeidenhainIso);
    let mill = MachineLimits {
        lathe: false,
        travel: [
            Some((-250.0, 250.0)),
            Some((-200.0, 200.0)),
            Some((-150.0, 150.0)),
            None,
        ],
        max_feed: Some(5000.0),
        max_spindle_rpm: None,
        servo: None,
    };
    // The centre (X0.2, Z-10) is the circle's, not an offset from the start.
    let good = "%J G71 *\nN1 ; +Z out of the material *\nN2 G17 G90 G40 *\nN3 T1 G17 S1000 *\nN4 M3 *\nN5 G00 Z1. *\nN6 G00 X-1. Y0. *\nN7 G94 G01 Z-0.1 F100. *\nN8 G18 G03 X1.5 Z-0.1126 I0.2 K-10. *\nN9 G00 Z1. *\nN10 M30 *\nN99999999 %J G71 *\n";
    assert_eq!(rules(good, &d, &mill), vec![]);
    d.arc_centre_absolute = false;
    assert_eq!(rules(good, &d, &mill), vec![Rule::ArcRadiusMismatch]);
}

#[test]
fn a_sinumerik_feed_type_cancels_constant_surface_speed() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    assert_eq!(Controller::of(&d), Controller::Siemens);
    let text = "G18 G71 G90 DIAMOF G40 G94\nT1 D1\nS500 M3\nG0 X3. Z1.5\nG95 G1 Z0.1 F0.002\nG0 Z1.5\nM30\n";
    // G94 (group 15 with G96/G97) states the spindle-speed mode: no G97 needed.
    assert_eq!(rules(text, &d, &lathe()), vec![]);
    let both = text.replace("G95 G1", "G95 G96 G1");
    assert!(rules(&both, &d, &lathe()).contains(&Rule::SameModalGroup));
}

#[test]
fn the_moves_are_handed_over_in_machine_coordinates() {
    // The Fanuc program of the test above: X a diameter, I, K the centre
    // from the start (a radius).
    let mut d = Dialect::linuxcnc();
    d.start = vec!["%".into(), "O{number} ({JOB})".into()];
    d.lathe_setup = vec!["G18 G21 G40 G80 G90".into()];
    d.lathe_x_diameter = true;
    let text = "%\nO1 (J)\nG18 G21 G40 G80 G90\nT0101\nG97 S500 M3\nG0 X6. Z1.5\nG95 G1 Z0.1 F0.002\nG2 X0. Z0.4693 I-3. K-12.\nG0 Z1.5\nM5\nM30\n%\n";
    let (found, moves) = read_moves(text, &d, &lathe());
    assert_eq!(found, vec![]);
    let paths: Vec<Path> = moves.iter().map(|m| m.path).collect();
    assert_eq!(paths.len(), 4, "{moves:?}");
    assert_eq!(moves[0].to, [Some(3.0), None, Some(1.5), None]);
    assert_eq!((paths[1], moves[1].to[2]), (Path::Line, Some(0.1)));
    let Path::Arc {
        plane,
        centre,
        cw,
        turn,
    } = paths[2]
    else {
        panic!("{paths:?}")
    };
    assert_eq!(
        (plane, centre, cw),
        (crate::moves::Plane::Zx, (0.1 - 12.0, 0.0), true)
    );
    // From (X 3, Z 0.1) to (X 0, Z 0.4693) about (X 0, Z -11.9).
    let want = 3f64.atan2(12.0);
    assert!((turn - want).abs() < 1e-12, "{turn} {want}");
    assert_eq!(moves[2].to, [Some(0.0), None, Some(0.4693), None]);
    assert_eq!(paths[3], Path::Rapid);
}

/// `Reader::lines` hands `line` the pieces `split_inclusive('\n')` makes,
/// at their offsets: breaks at every position of the eight-byte words,
/// several together, none, a last line without one, bytes that look
/// like a break plus or minus one, and text that is not ASCII.
#[test]
fn lines_are_split_as_split_inclusive_splits_them() {
    let mut texts: Vec<String> = vec![
        String::new(),
        "\n".into(),
        "\n\n\n".into(),
        "no break".into(),
        "G1 X1\nG1 X2".into(),
        "\u{b}\t\u{9}\n\u{8a}é\n€\n\r\n".into(),
    ];
    let mut r: u64 = 0x9e37_79b9_7f4a_7c15;
    let alphabet = [
        '\n', '\n', 'G', '1', ' ', '\t', '\u{b}', '\r', 'é', '\u{10a}', 'X',
    ];
    for _ in 0..20_000 {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        let n = (r % 40) as usize;
        let mut t = String::new();
        let mut s = r;
        for _ in 0..n {
            s = s.rotate_left(5) ^ 0x5851_f42d_4c95_7f2d;
            t.push(alphabet[(s % alphabet.len() as u64) as usize]);
        }
        texts.push(t);
    }
    for text in &texts {
        let mut want = Vec::new();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            want.push((offset, line.to_string()));
            offset += line.len();
        }
        let got: Vec<(usize, String)> = pieces(text).map(|(o, l)| (o, l.to_string())).collect();
        assert_eq!(got, want, "{text:?}");
    }
}

/// `read_from` finds what reading line by line with `read_until` found
/// (each line's bytes that are not UTF-8 read as `�`, the offsets in
/// bytes), whatever the reader's buffer holds at a time: programs with
/// findings, bytes that are not UTF-8 (alone, in a line with a finding,
/// in a comment), no last line break, CR LF.
#[test]
fn a_program_read_from_a_stream_reads_as_line_by_line() {
    use std::io::BufRead as _;
    let d = Dialect::linuxcnc();
    let m = lathe();
    let base = GOOD.replace("G0 X3 Z1.5\n", "G0 X3 Z151.5 E3\r\n");
    let mut texts: Vec<Vec<u8>> = vec![
        GOOD.as_bytes().to_vec(),
        base.as_bytes().to_vec(),
        base.trim_end().as_bytes().to_vec(),
        Vec::new(),
    ];
    for (at, bad) in [(3, 0xff_u8), (40, 0xc3), (70, 0x80), (85, 0xe2)] {
        let mut t = base.as_bytes().to_vec();
        t.insert(at.min(t.len()), bad);
        texts.push(t);
    }
    for text in &texts {
        // The reading before chunks: line by line.
        let mut r = Reader::new(&d, &m);
        let mut input = std::io::Cursor::new(text);
        let (mut buf, mut offset) = (Vec::new(), 0);
        loop {
            buf.clear();
            let n = input.read_until(b'\n', &mut buf).expect("read");
            if n == 0 {
                break;
            }
            r.line(&String::from_utf8_lossy(&buf), offset);
            offset += n;
        }
        let want = r.finish();
        for capacity in [1, 2, 3, 7, 16, 64, 8192] {
            let input = std::io::BufReader::with_capacity(capacity, text.as_slice());
            let got = read_from(input, &d, &m).expect("read");
            assert_eq!(got, want, "{capacity}: {:?}", String::from_utf8_lossy(text));
        }
    }
}

/// LinuxCNC refuses a parameter word no code of its block uses, and two
/// codes that both take the axis words; the words its codes do use pass
/// (each case checked with `rs274 -g`, linuxcnc-uspace 2.9).
#[test]
fn linuxcnc_refuses_words_no_code_of_the_block_uses() {
    let d = Dialect::linuxcnc();
    let refused: &[(&str, &str, Rule)] = &[
        ("G0 X3 Z1.5", "G0 X3 Z1.5 R1", Rule::UnusedWord),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 I1", Rule::UnusedWord),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002 P1",
            Rule::UnusedWord,
        ),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002 Q1",
            Rule::UnusedWord,
        ),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002 L1",
            Rule::UnusedWord,
        ),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002 D1",
            Rule::UnusedWord,
        ),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002 H1",
            Rule::UnusedWord,
        ),
        ("G97 S500 M3", "G97 S500 M3 P1", Rule::UnusedWord),
        ("G97 S500 M3", "G97 D100 S500 M3", Rule::UnusedWord),
        ("M5\n", "M5\nK1\n", Rule::UnusedWord),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 U1", Rule::UnknownWord),
        ("G0 X3 Z1.5", "G0 X3 Z1.5 W1", Rule::UnknownWord),
        ("G0 Z1.5\nM5", "G28 G0 Z1.5\nM5", Rule::SameModalGroup),
        ("M5\n", "M5\nG3\n", Rule::ArcWords),
        ("M5\n", "M5\nG53\n", Rule::UnusedWord),
        ("G0 Z1.5\nM5", "G53 G2 X3 Z1.5 I1\nM5", Rule::UnusedWord),
    ];
    for (from, to, rule) in refused {
        let text = GOOD.replacen(from, to, 1);
        assert_ne!(text, GOOD, "{from}");
        let found = rules(&text, &d, &lathe());
        assert!(found.contains(rule), "{to}: {found:?}");
    }
    let read: &[(&str, &str)] = &[
        ("M5\n", "M5\nM19 R0 Q1 P0\n"),
        ("T1 M6\n", "T1 M6 G43 H1\nG64 P0.001 Q0.001\nG4 P0.5\n"),
        ("G97 S500 M3", "G96 D500 S50 M3"),
        ("G0 Z1.5\nM5", "G0 Z1.5\nG28\nM5"),
        ("G0 Z1.5\nM5", "G0 Z1.5\nG53 G0 Z2\nM5"),
    ];
    for (from, to) in read {
        let text = GOOD.replacen(from, to, 1);
        assert_ne!(text, GOOD, "{from}");
        assert_eq!(rules(&text, &d, &lathe()), vec![], "{to}");
    }
}

/// What LinuxCNC reads that the reader refused before (issue #28): a
/// radius-format arc, an arc with a turn count, block delete, `M3.`,
/// `S1000.5`, a line number with a point; and the arcs it makes of them.
#[test]
fn linuxcnc_reads_radius_arcs_turns_and_block_delete() {
    let d = Dialect::linuxcnc();
    // The arc of GOOD from (3, 0.1) to (0, 0.469317) about (Z -11.9, X 0):
    // radius hypot(3, 12) = 12.369317…
    let r = 3f64.hypot(12.0);
    let by_radius = GOOD.replace("I-3 K-12", &format!("R{r:.6}"));
    assert_eq!(rules(&by_radius, &d, &lathe()), vec![], "{by_radius}");
    let (_, moves) = read_moves(&by_radius, &d, &lathe());
    let (_, want) = read_moves(GOOD, &d, &lathe());
    let arc = |m: &[Executed]| {
        m.iter()
            .find_map(|m| match m.path {
                Path::Arc { centre, turn, .. } => Some((centre, turn)),
                _ => None,
            })
            .expect("an arc")
    };
    let ((cz, cx), turn) = arc(&moves);
    let ((wz, wx), wturn) = arc(&want);
    assert!(
        (cz - wz).abs() < 1e-5 && (cx - wx).abs() < 1e-5,
        "{cz} {cx}"
    );
    assert!((turn - wturn).abs() < 1e-6);
    // Two turns more with P3.
    let turns = GOOD.replace("I-3 K-12", "I-3 K-12 P3");
    let (found, moves) = read_moves(&turns, &d, &lathe());
    assert_eq!(found, vec![]);
    let (_, turn) = arc(&moves);
    assert!((turn - wturn - 2.0 * std::f64::consts::TAU).abs() < 1e-9);
    for (from, to, rule) in [
        ("I-3 K-12", "I-3 K-12 P1.5", Rule::ArcWords),
        ("I-3 K-12", "I-3 K-12 P0", Rule::ArcWords),
        ("I-3 K-12", "R1", Rule::ArcRadiusMismatch),
        ("I-3 K-12", "I-3 K-12 R12", Rule::ArcWords),
        ("M5\n", "M5.001\n", Rule::DecimalPoint),
        ("G0 X3 Z1.5", "G0 Z1.5", Rule::PositionUnknown),
        (
            "G95 G1 Z0.1 F0.002",
            "G95 G1 Z0.1 F0.002\nG95 G1 Z0.1",
            Rule::NoFeedRate,
        ),
        ("G97 S500 M3", "G97 S500 M3 G1", Rule::NoFeedRate),
    ] {
        let text = GOOD.replacen(from, to, 1);
        let found = rules(&text, &d, &lathe());
        assert!(found.contains(&rule), "{to}: {found:?}");
    }
    for (from, to) in [
        ("M5\n", "/M5\n"),
        ("M5\n", "  / M5.\n"),
        ("G97 S500 M3", "G97 S500.5 M3."),
        ("M5\n", "N10.5 M5.00001\n"),
    ] {
        let text = GOOD.replacen(from, to, 1);
        assert_eq!(rules(&text, &d, &lathe()), vec![], "{to}");
    }
}

/// A rapid down before the first cut is held against the highest point
/// the cuts then reach (issue #28: "a rapid plunge into the part before
/// the first cut" read clean); one above it reads clean.
#[test]
fn a_rapid_plunge_before_the_first_cut_is_refused() {
    let d = Dialect::linuxcnc();
    let plunge = GOOD.replacen("G0 X3 Z1.5\n", "G0 X3 Z1.5\nG0 Z0.2\n", 1);
    let found = read(&plunge, &d, &lathe());
    let f = found
        .iter()
        .find(|f| f.rule == Rule::RapidIntoPart)
        .expect("the plunge is found");
    assert_eq!(f.line, 6, "{found:?}");
    assert_eq!(&plunge[f.span.0..f.span.1], "Z0.2");
    let above = GOOD.replacen("G0 X3 Z1.5\n", "G0 X3 Z1.5\nG0 Z0.5\n", 1);
    assert_eq!(rules(&above, &d, &lathe()), vec![]);
}

/// LinuxCNC's G5 and G5.1 splines read (each case checked with `rs274
/// -g`), and are handed over as straight moves along the curve; what the
/// manual refuses is refused.
#[test]
fn linuxcnc_reads_splines_as_moves_along_the_curve() {
    let d = Dialect::linuxcnc();
    let mill = MachineLimits {
        lathe: false,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };
    let program = |moves: &str| {
        format!(
            "G17 G21 G90 G94\nT1 M6\nG97 S1000 M3\nG0 X0 Y0 Z1\nG1 Z0 F100\n{moves}\nG0 Z1\nM5\nM2\n"
        )
    };
    let good = program("G5 I0 J3 P0 Q-3 X1 Y1\nG5 P0 Q-3 X2 Y2\nG5.1 X3 I0.5 J-1");
    let (found, moves) = read_moves(&good, &d, &mill);
    assert_eq!(found, vec![], "{good}");
    let lines: Vec<&Executed> = moves.iter().filter(|m| m.path == Path::Line).collect();
    assert!(lines.len() > 100, "{} lines", lines.len());
    // Consecutive, from (0, 0) to (3, 2), through the first cubic's middle
    // (the Bézier (0,0) (0,3) (1,-2) (1,1) at t = 1/2 is (0.5, 0.5)).
    for w in lines.windows(2) {
        assert_eq!(w[0].to, w[1].from);
    }
    assert_eq!(lines[1].from[..2], [Some(0.0), Some(0.0)]);
    let last = lines.last().expect("a line").to;
    assert!((last[0].unwrap() - 3.0).abs() < 1e-12 && (last[1].unwrap() - 2.0).abs() < 1e-12);
    let near_middle = lines
        .iter()
        .map(|m| (m.to[0].unwrap() - 0.5).hypot(m.to[1].unwrap() - 0.5))
        .fold(f64::INFINITY, f64::min);
    assert!(near_middle < 0.01, "{near_middle}");
    for also in ["G5 P0 Q-3 X1 Y1", "G5.1 X3 I0 J0"] {
        assert_eq!(rules(&program(also), &d, &mill), vec![], "{also}");
    }
    for bad in [
        "G5 I0 P0 Q-3 X1 Y1",
        "G5 I0 J3 P0 X1 Y1",
        "G5 I0 J3 P0 Q-3 X1 Y1 Z1",
        "G18\nG5 I0 J3 P0 Q-3 X1 Y1",
    ] {
        let text = program(bad);
        let found = rules(&text, &d, &mill);
        assert!(!found.is_empty(), "{bad}");
    }
    // A spline code with no axis word: "All axes missing with motion
    // code" (rs274 2.9; the differential round's `G5` block found it).
    for bad in ["G5", "G5.1", "G5 P1 Q1"] {
        assert_eq!(
            rules(&program(bad), &d, &mill),
            vec![Rule::ArcWords],
            "{bad}"
        );
    }
}

/// LinuxCNC's parameters and expressions are evaluated where a word's
/// number would be; a setting takes effect after its line (checked with
/// `rs274 -g`: `#1=1.5 #<r>=[#1*2]` on one line sets #<r> to 0).
#[test]
fn linuxcnc_reads_parameters_and_expressions() {
    let d = Dialect::linuxcnc();
    let text = GOOD.replacen(
        "G0 X3 Z1.5\n",
        "#1=1.5 #<r>=[#1*2]\n#<r>=[#1*2]\nG0 X#<r> Z[#1+[0*#1]]\n",
        1,
    );
    let (found, moves) = read_moves(&text, &d, &lathe());
    assert_eq!(found, vec![], "{text}");
    let rapid = moves
        .iter()
        .find(|m| m.path == Path::Rapid)
        .expect("a rapid");
    assert_eq!(rapid.to[0], Some(3.0));
    assert_eq!(rapid.to[2], Some(1.5));
    for bad in ["G0 X#<unset> Z1.5\n", "G0 X[1+ Z1.5\n", "#1=\nG0 X3 Z1.5\n"] {
        let t = GOOD.replacen("G0 X3 Z1.5\n", bad, 1);
        assert!(
            rules(&t, &d, &lathe()).contains(&Rule::MalformedNumber),
            "{bad}"
        );
    }
}

/// Heidenhain ISO orients the spindle by G36 (cycle 13 in ISO, S the
/// angle, not a speed) and states the blank by G30 and G31 (BLK FORM):
/// the reader takes G36 as the spindle held, so a knife may cut after it,
/// and the blank's corners as no move.
#[test]
fn heidenhain_iso_reads_g36_and_the_blank() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    d.block_end = " *".into();
    d.line_numbers = Some(1);
    d.max_line_number = Some(99999);
    d.arc_centre_absolute = true;
    d.surface_speed = Vec::new();
    d.constant_rpm = None;
    d.spindle_orient = vec!["G36 S0".into()];
    assert_eq!(Controller::of(&d), Controller::HeidenhainIso);
    let mill = MachineLimits {
        lathe: false,
        travel: [
            Some((-250.0, 250.0)),
            Some((-200.0, 200.0)),
            Some((-150.0, 150.0)),
            None,
        ],
        max_feed: Some(5000.0),
        max_spindle_rpm: Some(12000.0),
        servo: None,
    };
    let good = "%J G71 *\nN1 ; +Z out of the material *\nN2 G17 G90 G40 G94 *\nN3 G30 G17 X-1 Y-1 Z-2 *\nN4 G31 G90 X1 Y1 Z0.5 *\nN5 T1 G17 *\nN6 G36 S0 *\nN7 G00 Z1. *\nN8 G00 X-1. Y0. *\nN9 G01 Z-0.1 F100. *\nN10 G01 X1. *\nN11 G00 Z1. *\nN12 M5 *\nN13 G00 Z0 M91 *\nN14 M30 *\nN99999999 %J G71 *\n";
    assert_eq!(rules(good, &d, &mill), vec![]);
    let (_, moves) = read_moves(good, &d, &mill);
    // The first move is the rapid to Z1: G30 G31 moved nothing.
    assert_eq!(moves[0].to[2], Some(1.0));
    assert_eq!(moves[0].from, [None; 4]);
    // Without G36 the knife cuts with the spindle stopped.
    let unoriented = good.replace("N6 G36 S0 *\n", "");
    assert!(rules(&unoriented, &d, &mill).contains(&Rule::SpindleStopped));
    // G36 S is an angle: no speed is set, and the spindle stays still.
    let started = good.replace("N6 G36 S0 *\n", "N6 G36 S0 *\nN6 M3 *\n");
    assert!(rules(&started, &d, &mill).contains(&Rule::NoSpindleSpeed));
}

/// A mill's limits for the parameter-word tests.
fn mill() -> MachineLimits {
    MachineLimits {
        lathe: false,
        travel: [
            Some((-250.0, 250.0)),
            Some((-200.0, 200.0)),
            Some((-150.0, 150.0)),
            None,
        ],
        max_feed: Some(5000.0),
        max_spindle_rpm: Some(12000.0),
        servo: None,
    }
}

/// Each `(from, to)` change of `good` breaks `rule`; each of `clean` reads
/// clean; `good` itself reads clean.
fn holds(d: &Dialect, good: &str, broken: &[(&str, &str)], clean: &[(&str, &str)]) {
    assert_eq!(rules(good, d, &mill()), vec![], "{good}");
    for (from, to) in broken {
        let text = good.replacen(from, to, 1);
        assert_ne!(text, good, "{from}");
        let found = rules(&text, d, &mill());
        assert!(found.contains(&Rule::UnusedWord), "{to}: {found:?}");
    }
    for (from, to) in clean {
        let text = good.replacen(from, to, 1);
        assert_ne!(text, good, "{from}");
        assert_eq!(rules(&text, d, &mill()), vec![], "{to}");
    }
}

/// Fanuc refuses a parameter word no code of its block uses: I J K R
/// away from an arc, P without G4, Q without G05.1, H without G43, D
/// without G41/G42, L (M98, G10, not read) (docs/controllers/fanuc.md:
/// assumptions, no Fanuc manual found).
#[test]
fn fanuc_refuses_words_no_code_of_the_block_uses() {
    let mut d = Dialect::linuxcnc();
    d.start = vec!["%".into(), "O{number} ({JOB})".into()];
    d.constant_rpm = None;
    d.surface_speed = Vec::new();
    assert_eq!(Controller::of(&d), Controller::Fanuc);
    let good = "%\nO1 (J)\n(+Z out of the material)\nG17 G21 G40 G49 G80 G90 G94 G54\nT1 M6\nS1000 M3\nG43 H1 G0 Z1.\nG0 X-1. Y0.\nG1 Z-0.1 F100.\nG2 X1. I1. J0.\nG0 Z1.\nM5\nM30\n%\n";
    holds(
        &d,
        good,
        &[
            ("G1 Z-0.1 F100.", "G1 Z-0.1 I1. F100."),
            ("G0 X-1. Y0.", "G0 X-1. Y0. R1."),
            ("G0 X-1. Y0.", "G0 X-1. Y0. K0."),
            ("S1000 M3", "S1000 M3 P5"),
            ("G0 Z1.\nM5", "G0 Z1. Q1\nM5"),
            ("T1 M6", "T1 M6 H1"),
            ("G1 Z-0.1 F100.", "G1 Z-0.1 D1 F100."),
            ("M5\n", "M5 L2\n"),
        ],
        &[
            ("M5\n", "M5\nG4 P500\n"),
            ("T1 M6\n", "T1 M6\nG05.1 Q1\n"),
            // An arc's words in the arc mode in force.
            ("G0 Z1.\nM5", "X-1. I-1. J0.\nG0 Z1.\nM5"),
        ],
    );
}

/// A Fanuc reads a radius-format arc (`G2 X1. R1.`) as LinuxCNC does: it
/// runs them (the reader refused it, E0319), the centre on the chord's
/// right for G2 and a positive R; R and I J together, or an R too short
/// for the chord, are refused.
#[test]
fn fanuc_reads_radius_format_arcs() {
    let mut d = Dialect::linuxcnc();
    d.start = vec!["%".into(), "O{number} ({JOB})".into()];
    d.constant_rpm = None;
    d.surface_speed = Vec::new();
    assert_eq!(Controller::of(&d), Controller::Fanuc);
    let by_centre = "%\nO1 (J)\n(+Z out of the material)\nG17 G21 G40 G49 G80 G90 G94 G54\nT1 M6\nS1000 M3\nG43 H1 G0 Z1.\nG0 X-1. Y0.\nG1 Z-0.1 F100.\nG2 X1. I1. J0.\nG0 Z1.\nM5\nM30\n%\n";
    let by_radius = by_centre.replace("G2 X1. I1. J0.", "G2 X1. R1.");
    let mill = mill();
    assert_eq!(rules(&by_radius, &d, &mill), vec![], "{by_radius}");
    let centre_of = |text: &str| {
        read_moves(text, &d, &mill)
            .1
            .iter()
            .find_map(|m| match m.path {
                Path::Arc { centre, .. } => Some(centre),
                _ => None,
            })
            .expect("an arc")
    };
    let (a, b) = (centre_of(&by_radius), centre_of(by_centre));
    assert!(
        (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9,
        "{a:?} {b:?}"
    );
    for (to, rule) in [
        ("G2 X1. I1. J0. R1.", Rule::ArcWords),
        ("G2 X1. R0.5", Rule::ArcRadiusMismatch),
    ] {
        let bad = by_centre.replace("G2 X1. I1. J0.", to);
        assert!(
            rules(&bad, &d, &mill).contains(&rule),
            "{to}: {:?}",
            rules(&bad, &d, &mill)
        );
    }
}

/// A Sinumerik refuses I J K away from an arc and P away from a
/// subprogram call's passes (an arc's turns are `TURN=`)
/// (docs/controllers/siemens.md).
#[test]
fn sinumerik_refuses_words_no_code_of_the_block_uses() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    assert_eq!(Controller::of(&d), Controller::Siemens);
    let good = "; +Z out of the material\nG17 G71 G90 G40 G94 G54\nT1 D1\nM6\nG97 S1000 M3\nG0 Z1\nG0 X-1 Y0\nG94 G1 Z-0.1 F100\nG2 X1 I1 J0\nG0 Z1\nM5\nM30\n";
    holds(
        &d,
        good,
        &[
            ("G94 G1 Z-0.1 F100", "G94 G1 Z-0.1 K1 F100"),
            ("G0 X-1 Y0", "G0 X-1 Y0 J2"),
            ("G94 G1 Z-0.1 F100", "G94 G1 Z-0.1 F100 P2"),
            ("G2 X1 I1 J0", "G2 X1 I1 J0 P1"),
        ],
        &[("G0 Z1\nM5", "X-1 I-1 J0\nG0 Z1\nM5")],
    );
}

/// Heidenhain ISO refuses I J K on a straight move; alone in a block they
/// set the circle centre (docs/controllers/heidenhain.md).
#[test]
fn heidenhain_iso_refuses_centre_words_on_a_straight_move() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    d.block_end = " *".into();
    d.line_numbers = Some(1);
    d.max_line_number = Some(99999);
    d.arc_centre_absolute = true;
    d.surface_speed = Vec::new();
    d.constant_rpm = None;
    assert_eq!(Controller::of(&d), Controller::HeidenhainIso);
    let good = "%J G71 *\nN1 ; +Z out of the material *\nN2 G17 G90 G40 G94 *\nN3 T1 G17 *\nN4 S1000 M3 *\nN5 G00 Z1. *\nN6 G00 X-1. Y0. *\nN7 G01 Z-0.1 F100. *\nN8 G02 X1. I0. J0. *\nN9 G00 Z1. *\nN10 M5 *\nN11 M30 *\nN99999999 %J G71 *\n";
    holds(
        &d,
        good,
        &[
            ("N7 G01 Z-0.1 F100.", "N7 G01 Z-0.1 I1. F100."),
            ("N6 G00 X-1. Y0.", "N6 G00 X-1. Y0. J0."),
        ],
        &[("N5 G00 Z1. *\n", "N5 G00 Z1. *\nN5 I0. J0. *\n")],
    );
}

/// A program written for the tool's tip (its header states the control
/// point's offset from the centre) is held to the machine's travel as the
/// tool centre, as the centre's program is: both read to the same
/// findings, in or out of the travel (`lensc verify` reads by `read_from`).
#[test]
fn a_tip_program_is_held_to_the_travel_as_its_centre_program() {
    let d = Dialect::linuxcnc();
    let mut m = mill();
    m.travel[2] = Some((-1.0, 150.0));
    let program = |control: &str, depth: f64| {
        format!(
            "(+Z out of the material)\n{control}G17 G21 G90 G40 G49 G80 G94 G54\nT1 M6 G43 H1\nG97 S1000 M3\nG0 Z1\nG0 X-1 Y0\nG94 G1 Z{depth} F100\nG1 X1\nG0 Z1\nM5\nM2\n"
        )
    };
    let tip = "(control point tip at X+0 Y+0 Z-0.085 mm from the tool centre: the tip)\n";
    let findings = |text: &str| {
        read_from(text.as_bytes(), &d, &m)
            .expect("read")
            .into_iter()
            .map(|f| (f.rule, f.message.replace("the tool centre's ", "")))
            .collect::<Vec<_>>()
    };
    // The centre at -0.95 mm is inside the travel; its tip at -1.035 mm.
    assert_eq!(findings(&program("", -0.95)), vec![]);
    assert_eq!(findings(&program(tip, -0.95 - 0.085)), vec![]);
    // The centre at -1.05 mm is outside, by the same figure either way.
    let centre = findings(&program("", -1.05));
    assert_eq!(centre.len(), 1, "{centre:?}");
    assert_eq!(centre[0].0, Rule::OutsideTravel);
    assert!(centre[0].1.contains("-1.05 mm"), "{centre:?}");
    assert_eq!(findings(&program(tip, -1.05 - 0.085)), centre);
}

/// LinuxCNC's M60 is the pallet change pause, a stop as M0 is (rs274
/// runs it); M99 in a main program starts it again from the top, which
/// lensc refuses as its policy (`main-program-loop`) and reads no
/// further, so blocks after it are not counted again.
#[test]
fn linuxcnc_reads_m60_as_a_pause_and_m99_as_an_endless_loop() {
    let d = Dialect::linuxcnc();
    let paused = GOOD.replacen("M5\n", "M5\nM60\n", 1);
    assert_eq!(rules(&paused, &d, &lathe()), vec![]);
    let paused_with_m0 = GOOD.replacen("M5\n", "M5\nM60 M0\n", 1);
    assert_eq!(
        rules(&paused_with_m0, &d, &lathe()),
        vec![Rule::SameModalGroup]
    );
    let looped = GOOD.replacen("M2\n", "M99\n", 1);
    assert_eq!(rules(&looped, &d, &lathe()), vec![Rule::MainProgramLoop]);
    assert!(Rule::MainProgramLoop.policy().is_some());
    let looped_early = GOOD.replacen("G0 Z1.5\nM5", "M99\nG0 Z1.5\nM5", 1);
    assert_eq!(
        rules(&looped_early, &d, &lathe()),
        vec![Rule::MainProgramLoop, Rule::BlockAfterEnd]
    );
}

/// A Fanuc mill that interpolates NURBS (G06.2).
fn fanuc_nurbs() -> Dialect {
    let mut d = Dialect::linuxcnc();
    d.start = vec!["%".into(), "O{number} ({JOB})".into()];
    d.mill_setup = vec!["G17 G21 G40 G49 G80 G90 G94".into()];
    d.max_digits = Some(8);
    d.max_decimals = Some(4);
    d.spline = Some(crate::dialect::SplineForm::Nurbs);
    d
}

fn nurbs_mill() -> MachineLimits {
    MachineLimits {
        lathe: false,
        travel: [
            Some((-100.0, 100.0)),
            Some((-100.0, 100.0)),
            Some((-50.0, 50.0)),
            None,
        ],
        max_feed: Some(5000.0),
        max_spindle_rpm: Some(20000.0),
        servo: None,
    }
}

/// A rank-3 NURBS over three control points in X and Z, a quarter of the
/// unit circle about (0, 0, -1) with the middle weight √2/2: the tool ends
/// at X1 Z-1 and every move read lies on the circle.
const NURBS: &str = "%\nO1 (J)\n(+Z out of the material)\nG17 G21 G40 G49 G80 G90 G94\nT1 M6\nG97 S1000 M3\nG0 X0. Y0. Z1.\nG1 Z0. F100.\nG06.2 P3 K0. X0. Y0. Z0. F100.\nK0. X1. Y0. Z0. R0.7071\nK0. X1. Y0. Z-1.\nK1.\nK1.\nK1.\nG1 X2.\nG0 Z1.\nM5\nM30\n%\n";

#[test]
fn a_nurbs_curve_is_read_as_the_control_moves_it() {
    let d = fanuc_nurbs();
    assert_eq!(Controller::of(&d), Controller::Fanuc);
    let (found, moves) = read_moves(NURBS, &d, &nurbs_mill());
    assert_eq!(found, vec![]);
    let on_curve: Vec<&Executed> = moves
        .iter()
        .filter(|m| m.from[2].is_some_and(|z| z <= 0.0) && m.to[0].is_some_and(|x| x <= 1.0))
        .collect();
    assert!(on_curve.len() > 50, "{}", on_curve.len());
    let last = on_curve[on_curve.len() - 1].to;
    assert_eq!((last[0], last[2]), (Some(1.0), Some(-1.0)));
    // R0.7071 is √2/2 to 4 decimals: on the circle to well under 1e-4.
    for m in &on_curve {
        let (x, z) = (m.to[0].unwrap(), m.to[2].unwrap());
        assert!((x.hypot(z + 1.0) - 1.0).abs() < 2e-5, "{x} {z}");
    }
    // The next G1 starts where the curve ends.
    let after = moves.iter().find(|m| m.to[0] == Some(2.0)).expect("G1 X2.");
    assert_eq!((after.from[0], after.from[2]), (Some(1.0), Some(-1.0)));
}

#[test]
fn a_nurbs_curve_the_control_refuses_is_found_with_its_span() {
    let d = fanuc_nurbs();
    let cases: &[(&str, &str, &str)] = &[
        ("G06.2 P3", "G06.2 P5", "P5"),
        ("K0. X1. Y0. Z-1.", "X1. Y0. Z-1.", "1002"),
        ("K1.\nK1.\nK1.\n", "K1.\nK1.\n", "before its last knot"),
        (
            "K0. X1. Y0. Z-1.",
            "K0.5 X1. Y0. Z-1.",
            "must each be equal",
        ),
        ("R0.7071", "R-1.", "above zero"),
        (
            "G06.2 P3 K0. X0. Y0. Z0.",
            "G06.2 P3 K0. X0.1 Y0. Z0.",
            "where the tool is",
        ),
        (
            "K0. X1. Y0. Z0. R0.7071",
            "K0. X1. Y0. Z0. R0.7071 P3",
            "only in the G06.2 block",
        ),
    ];
    for (from, to, what) in cases {
        let text = NURBS.replacen(from, to, 1);
        assert_ne!(text, NURBS, "{from}");
        let found = read(&text, &d, &nurbs_mill());
        let f = found
            .iter()
            .find(|f| f.rule == Rule::SplineRefused)
            .unwrap_or_else(|| panic!("{to}: {found:?}"));
        assert!(f.message.contains(what), "{to}: {}", f.message);
        assert!(
            f.span.1 > f.span.0 || what.contains("last knot"),
            "{to}: {f:?}"
        );
    }
    // Without the dialect's spline, G06.2 is a code the control lacks.
    let found = rules(NURBS, &Dialect { spline: None, ..d }, &nurbs_mill());
    assert!(found.contains(&Rule::UnknownWord), "{found:?}");
}

/// LinuxCNC's NURBS block (G5.2 … G5.3) read as `rs274` 2.9 runs it: the
/// manual's example (11.5.9) passes through the points LinuxCNC's own
/// evaluation gives (its Python module `gcode`: (1, 1.5) and (2, 1) at
/// u = 1 and 2 of 3), and ends at its last control point; what rs274
/// refuses is E0340 (`tests/it/nurbs_linuxcnc.rs` holds every case
/// against rs274 itself).
#[test]
fn linuxcnc_reads_a_nurbs_block_as_the_interpreter_evaluates_it() {
    let d = Dialect::linuxcnc();
    let mill = MachineLimits {
        lathe: false,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };
    let program = |moves: &str| {
        format!(
            "G17 G21 G90 G94\nT1 M6\nG97 S1000 M3\nG0 X0 Y0 Z1\nG1 Z0 F100\n{moves}\nG0 Z1\nM5\nM2\n"
        )
    };
    let good = program("G5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nX0 Y0 P2\nG5.3");
    let (found, moves) = read_moves(&good, &d, &mill);
    assert_eq!(found, vec![], "{good}");
    let lines: Vec<&Executed> = moves
        .iter()
        .filter(|m| m.path == Path::Line && m.from[2] == Some(0.0))
        .collect();
    assert!(lines.len() > 100, "{} lines", lines.len());
    for w in lines.windows(2) {
        assert_eq!(w[0].to, w[1].from);
    }
    let last = lines.last().expect("a line").to;
    assert_eq!(last[..3], [Some(0.0), Some(0.0), Some(0.0)]);
    for (x, y) in [(1.0, 1.5), (2.0, 1.0)] {
        let near = lines
            .iter()
            .map(|m| (m.to[0].unwrap() - x).hypot(m.to[1].unwrap() - y))
            .fold(f64::INFINITY, f64::min);
        assert!(near < 1e-9, "({x}, {y}): {near:e}");
    }
    for bad in [
        "G5.2 X0 Y1 P1 L5\nX2 Y2 P1\nX2 Y0 P1\nG5.3",
        "G5.2 X0 Y1 P1\nG5.3",
        "G5.2 X0 Y1 P1\nX2 Y2\nX2 Y0 P1\nG5.3",
        "G5.2 X0 Y1 P1\nX2 P1\nX2 Y0 P1\nG5.3",
        "G5.3",
    ] {
        assert_eq!(
            rules(&program(bad), &d, &mill),
            vec![Rule::SplineRefused],
            "{bad}"
        );
    }
    let open = program("G5.2 X0 Y1 P1\nX2 Y2 P1\nG1 X0 Y0");
    assert_eq!(rules(&open, &d, &mill), vec![Rule::NurbsNotCut]);
    let weightless = program("G5.2 X0 Y1\nX2 Y2 P1\nX2 Y0 P1\nG5.3");
    let found = read(&weightless, &d, &mill);
    assert_eq!(found.len(), 1);
    assert_eq!((found[0].rule, found[0].line), (Rule::NurbsWeight, 6));
}

/// Heidenhain ISO: a block of I J alone defines the circle centre and
/// moves nothing, in an arc mode too (it was read as a full circle); an
/// arc after it without I J goes about that centre (TNC 426/425/415
/// B/407 ISO Programming User's Manual, "Circle center I, J, K", pp.
/// 5-16 to 5-18).
#[test]
fn heidenhain_iso_reads_i_j_alone_as_the_circle_centre() {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    d.block_end = " *".into();
    d.line_numbers = Some(1);
    d.max_line_number = Some(99999);
    d.arc_centre_absolute = true;
    d.surface_speed = Vec::new();
    d.constant_rpm = None;
    assert_eq!(Controller::of(&d), Controller::HeidenhainIso);
    let program = |arcs: &str| {
        format!(
            "%J G71 *\nN1 ; +Z out of the material *\nN2 G17 G90 G40 G94 *\nN3 T1 G17 *\nN4 S1000 M3 *\nN5 G00 Z1. *\nN6 G00 X-1. Y0. *\nN7 G01 Z-0.1 F100. *\n{arcs}N20 G00 Z1. *\nN21 M5 *\nN22 M30 *\nN99999999 %J G71 *\n"
        )
    };
    let alone = program("N8 G02 X1. I0. J0. *\nN9 I0. J0. *\n");
    let (found, moves) = read_moves(&alone, &d, &mill());
    assert_eq!(found, vec![], "{alone}");
    let arcs = moves
        .iter()
        .filter(|m| matches!(m.path, Path::Arc { .. }))
        .count();
    assert_eq!(arcs, 1, "the I J block moves nothing");
    let about = program("N8 I0. J0. *\nN9 G02 X1. *\nN10 G02 X-1. *\n");
    let (found, moves) = read_moves(&about, &d, &mill());
    assert_eq!(found, vec![], "{about}");
    let turns: Vec<f64> = moves
        .iter()
        .filter_map(|m| match m.path {
            Path::Arc { centre, turn, .. } => {
                assert_eq!(centre, (0.0, 0.0));
                Some(turn)
            }
            _ => None,
        })
        .collect();
    assert_eq!(turns.len(), 2);
    assert!(
        turns
            .iter()
            .all(|t| (t - std::f64::consts::PI).abs() < 1e-12)
    );
    // No centre defined at all: still refused.
    let none = program("N8 G02 X1. *\n");
    assert_eq!(rules(&none, &d, &mill()), vec![Rule::ArcWords]);
}

/// A LinuxCNC fast-tool-servo spiral's opening: the slide to 0 with the
/// plunge, the servo on W (`W1` and `W2` its words), inverse time.
fn servo_program(w1: &str, w2: &str) -> String {
    format!(
        "(units mm; X is the radius, C the spindle angle, +Z out of the material)
G18 G21 G90 G8 G40 G49 G80 G94
T1 M6 G43
G0 Z2
G0 X3 C0
G93 G1 W{w1} Z0 F60
G1 X2.9 C10 F600
G1 X2.8 W{w2} C20 F600
G0 W0 Z2
M2
"
    )
}

/// The lathe with a fast tool servo on its own letter W, of velocity
/// limit `max_velocity` (mm/min) and `stroke` (mm).
fn servo_lathe(max_velocity: f64, stroke: f64) -> MachineLimits {
    MachineLimits {
        servo: Some(ServoAxis {
            letter: 'W',
            max_velocity,
            stroke,
        }),
        ..lathe()
    }
}

#[test]
fn a_servo_on_its_own_letter_moves_the_tip_and_is_held_to_its_limit() {
    let d = Dialect::linuxcnc();
    let servo = |max_velocity| servo_lathe(max_velocity, 5.0);
    // The tip is Z + W: the plunge ends at 0.5, the next move holds it
    // (the servo still), the next takes it to 0.4.
    let text = servo_program("0.5", "0.4");
    let (found, moves) = read_moves(&text, &d, &servo(1000.0));
    assert!(found.is_empty(), "{found:?}");
    let tips: Vec<Option<f64>> = moves.iter().map(|m| m.to[2]).collect();
    assert_eq!(
        tips,
        [
            Some(2.0),
            Some(2.0),
            Some(0.5),
            Some(0.5),
            Some(0.4),
            Some(2.0)
        ]
    );
    // The last move drives W 0.1 mm in 0.1 s: 60 mm/min, over a 50 mm/min
    // limit; the slides' 0.1 mm in the same time is within their 2000.
    let found = read(&text, &d, &servo(50.0));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].rule, found[0].line), (Rule::FeedTooHigh, 8));
    assert!(
        found[0]
            .message
            .contains("axis W at 60 mm/min, above its 50 mm/min"),
        "{}",
        found[0].message
    );
    // Where the machine has no such axis, W is no word of the control's.
    assert!(rules(&text, &d, &lathe()).contains(&Rule::UnknownWord));
}

/// A servo on its own letter may be given positions spanning no more
/// than its stroke, wherever its zero is: the move that widens the span
/// past it is found (over-travel), once per widening; the retract to W0
/// counts, as the servo must reach it.
#[test]
fn a_servo_on_its_own_letter_is_held_to_its_stroke() {
    let d = Dialect::linuxcnc();
    let servo = |stroke| servo_lathe(10_000.0, stroke);
    // W at 0.5, then -0.3 (0.8 mm apart), then 0 (inside the span).
    let text = servo_program("0.5", "-0.3");
    assert!(read(&text, &d, &servo(0.8)).is_empty());
    let found = read(&text, &d, &servo(0.6));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].rule, found[0].line), (Rule::OutsideTravel, 8));
    assert!(
        found[0]
            .message
            .contains("axis W to -0.3 mm: the program moves it over -0.3 .. 0.5 mm, 0.8 mm, more than its 0.6 mm stroke"),
        "{}",
        found[0].message
    );
    // Where the retract widens it: W at 0.5 and 0.4, then 0.
    let text = servo_program("0.5", "0.4");
    let found = read(&text, &d, &servo(0.3));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].line, 9, "{found:?}");
}
