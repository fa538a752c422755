//! Tests of the program writer: words, modal state, feeds and line text.

use super::*;
use crate::moves::{Feed as F, Move as M, Position as P};

fn written(axes: &str, stream: &[M]) -> Result<String, ProgramError> {
    written_in(&Dialect::linuxcnc(), Setup::Mill, axes, stream)
}

/// A program of `stream` after the tool call (tool 1) and a spindle start
/// at 1000 rpm; the spindle stopped at the end.
fn written_in(d: &Dialect, setup: Setup, axes: &str, stream: &[M]) -> Result<String, ProgramError> {
    let mut w = ProgramWriter::new(d, setup, "t1", &["t".into()], axes, 1e-3, 1e-3)?;
    w.call_tool(&Start::default())?;
    w.write(&M::SpindleOn(RPM_1000))?;
    w.write_all(stream)?;
    w.finish()
}

/// 1000 rpm in rad/s.
const RPM_1000: f64 = 1000.0 * 2.0 * PI / 60.0;

#[test]
fn unchanged_words_and_feeds_are_left_out() {
    let text = written(
        "XYZ",
        &[
            M::Rapid(P::xyz(1.0, 2.0, 5.0)),
            M::Linear {
                to: P::xyz(1.0, 2.0, 0.5),
                feed: Some(F::PerTime(1.0)),
            },
            M::Linear {
                to: P::xyz(1.5, 2.0, 0.5),
                feed: Some(F::PerTime(1.0)),
            },
            // Rounds to the same printed position: no line at all.
            M::Linear {
                to: P::xyz(1.5001, 2.0, 0.5),
                feed: None,
            },
            M::Linear {
                to: P::xyz(1.5, 2.5, 0.5),
                feed: Some(F::PerTime(2.0)),
            },
        ],
    )
    .expect("writes");
    assert_eq!(
        text,
        "(t)\nG17 G21 G90 G40 G49 G80 G94 G54\nG64 P0.001\nT1 M6 G43 H1\nG97 S1000 M3\nG0 X1. Y2. Z5.\nG94 G1 Z0.5 F60.\nG1 X1.5\nG1 Y2.5 F120.\nM5\nG53 G0 Z0\nM2\n"
    );
}

#[test]
fn inverse_time_writes_a_feed_on_every_move_and_c_in_degrees() {
    let text = written(
        "XZC",
        &[
            M::Linear {
                to: P::xzc(1.0, 0.0, std::f64::consts::FRAC_PI_2),
                feed: Some(F::InverseTime(0.5)),
            },
            M::Linear {
                to: P::xzc(0.9, 0.0, std::f64::consts::PI),
                feed: Some(F::InverseTime(0.5)),
            },
            M::Linear {
                to: P::xz(0.8, 0.1),
                feed: Some(F::PerRevolution(0.001)),
            },
        ],
    )
    .expect("writes");
    assert_eq!(
        text,
        "(t)\nG17 G21 G90 G40 G49 G80 G94 G54\nG64 P0.001\nT1 M6 G43 H1\nG97 S1000 M3\nG93 G1 X1. Z0. C90. F120.\nG1 X0.9 C180. F120.\nG95 G1 X0.8 Z0.1 F0.006283\nM5\nG53 G0 Z0\nM2\n"
    );
}

#[test]
fn a_dialect_given_as_data_shapes_every_line() {
    let mut d = Dialect::linuxcnc();
    d.name = "heidenhain_like".into();
    d.comment = CommentStyle::Semicolon;
    d.start = vec!["%{JOB} G71 *".into()];
    d.mill_setup = vec!["G17 G90".into()];
    d.path_tolerance = Vec::new();
    d.end = vec!["M30".into()];
    d.trailer = vec!["N99999999 %{JOB} G71 *".into()];
    d.line_numbers = Some(1);
    d.block_end = " *".into();
    d.arc_centre_absolute = true;
    let text = written_in(
        &d,
        Setup::Mill,
        "XYZ",
        &[
            M::Rapid(P::xyz(1.0, 0.0, 0.0)),
            M::Arc {
                to: P::xyz(0.0, 1.0, 0.0),
                centre: P::xyz(0.0, 0.0, f64::NAN),
                plane: Plane::Xy,
                ccw: true,
                feed: Some(F::PerTime(1.0)),
            },
        ],
    )
    .expect("writes");
    assert_eq!(
        text,
        "%T1 G71 *\nN1 ; t *\nN2 G17 G90 *\nN3 T1 M6 G43 H1 *\nN4 G97 S1000 M3 *\nN5 G0 X1. Y0. Z0. *\nN6 G94 G3 X0. Y1. I0. J0. F60. *\nN7 M5 *\nN8 M30 *\nN99999999 %T1 G71 *\n"
    );
}

#[test]
fn long_words_and_letters_beyond_ascii_are_written_whole() {
    // Words longer than a snippet's fixed room, and a C letter of two
    // bytes, take the writer's other paths.
    let mut d = Dialect::linuxcnc();
    d.linear = "G1 G90 G94 G17 G21 G40".into();
    d.block_end = " ; the end of a long block".into();
    d.c_letter = 'Ç';
    // The longest line is 77 bytes (the limit counts bytes, as before).
    d.max_line_length = Some(77);
    let text = written_in(
        &d,
        Setup::Lathe,
        "XZC",
        &[
            M::Linear {
                to: P::xzc(1.5, -0.25, std::f64::consts::PI),
                feed: Some(F::InverseTime(0.5)),
            },
            M::Linear {
                to: P::xzc(1.5, -0.25, std::f64::consts::FRAC_PI_2),
                feed: Some(F::InverseTime(0.25)),
            },
        ],
    )
    .expect("writes");
    assert!(
        text.contains(
            "G93 G1 G90 G94 G17 G21 G40 X1.5 Z-0.25 Ç180. F120. ; the end of a long block\n\
             G1 G90 G94 G17 G21 G40 Ç90. F240. ; the end of a long block\n"
        ),
        "{text}"
    );
    // One byte over the limit, the block end counted.
    d.max_line_length = Some(76);
    let Err(ProgramError::Unsupported(why)) = written_in(
        &d,
        Setup::Lathe,
        "XZC",
        &[M::Linear {
            to: P::xzc(1.5, -0.25, std::f64::consts::PI),
            feed: Some(F::InverseTime(0.5)),
        }],
    ) else {
        panic!("a line over the limit written")
    };
    assert!(why.contains("a line of 77 characters"), "{why}");
}

#[test]
fn arcs_have_incremental_centres_and_select_their_plane() {
    let text = written(
        "XYZ",
        &[
            M::Rapid(P::xyz(1.0, 0.0, 2.0)),
            M::Arc {
                to: P::xyz(3.0, 0.0, 2.0),
                centre: P::xyz(2.0, f64::NAN, 2.0),
                plane: Plane::Zx,
                ccw: false,
                feed: Some(F::PerTime(1.0)),
            },
        ],
    )
    .expect("writes");
    assert!(text.contains("G94 G18 G2 X3. I1. K0. F60.\n"), "{text}");
}

#[test]
fn an_arc_whose_radii_disagree_after_rounding_is_refused() {
    let arc = |end_x: f64| {
        written(
            "XZ",
            &[
                M::Rapid(P::xz(1.0, 0.0)),
                M::Arc {
                    to: P::xz(end_x, 0.0),
                    centre: P::xz(0.0, 0.0),
                    plane: Plane::Zx,
                    ccw: true,
                    feed: Some(F::PerTime(1.0)),
                },
            ],
        )
    };
    assert!(arc(-1.0005).is_ok());
    let Err(ProgramError::Unsupported(why)) = arc(-1.002) else {
        panic!("a 2 um mismatch written")
    };
    assert!(why.contains("0.002 mm"), "{why}");
}

#[test]
fn diameter_mode_doubles_x_and_limits_are_enforced() {
    let mut d = Dialect::linuxcnc();
    d.lathe_x_diameter = true;
    d.max_digits = Some(4);
    let text = written_in(&d, Setup::Lathe, "XZ", &[M::Rapid(P::xz(1.25, 0.0))]).expect("writes");
    assert!(text.contains("G0 X2.5 Z0.\n"), "{text}");
    assert!(matches!(
        written_in(&d, Setup::Lathe, "XZ", &[M::Rapid(P::xz(12.3455, 0.0))]),
        Err(ProgramError::Unsupported(_))
    ));
    d.per_revolution = None;
    assert!(matches!(
        written_in(
            &d,
            Setup::Lathe,
            "XZ",
            &[M::Linear {
                to: P::xz(1.0, 0.0),
                feed: Some(F::PerRevolution(0.001))
            }]
        ),
        Err(ProgramError::Unsupported(_))
    ));
    d.max_decimals = Some(2);
    assert!(written_in(&d, Setup::Lathe, "XZ", &[]).is_err());
    assert!(written_in(&Dialect::linuxcnc(), Setup::Lathe, "XZ", &[]).is_ok());
}

#[test]
fn the_final_check_refuses_bad_numbers_outside_comments() {
    let ok = "(X-0. in a comment, 1e5 too)\nG1 X-0.5 Z0. F60.\nG05.1 Q1\n";
    assert!(check_numbers(ok, CommentStyle::Parentheses).is_ok());
    for bad in [
        "G1 X-0.",
        "G1 X-0.000",
        "G1 X1.5e-3",
        "G1 XNaN",
        "G1 Z-inf",
        "G1 X1.0Y2.",
    ] {
        assert!(
            check_numbers(bad, CommentStyle::Parentheses).is_err(),
            "{bad} passed"
        );
    }
    assert!(check_numbers("; X-0. here", CommentStyle::Semicolon).is_ok());
}

#[test]
fn axes_the_machine_lacks_and_values_that_cannot_print_are_refused() {
    assert!(matches!(
        written("XZ", &[M::Rapid(P::xyz(1.0, 2.0, 3.0))]),
        Err(ProgramError::NotPrintable { word: 'Y', .. })
    ));
    assert!(matches!(
        written("XZ", &[M::Rapid(P::xz(f64::INFINITY, 0.0))]),
        Err(ProgramError::NotPrintable { word: 'X', .. })
    ));
}

/// `{:.N}` of `n` units of 10^−N, trailing zeros trimmed, the point
/// kept: the reference every printed word is held to.
fn std_word(n: i64, d: u32) -> String {
    let s = format!("{:.*}", d as usize, n as f64 / 10f64.powi(d as i32));
    if d == 0 {
        s + "."
    } else {
        s.trim_end_matches('0').to_string()
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

    /// A spiral-like stream through the writer against a model of it
    /// built from `f64::round` and `{:.N}`: the same lines, word for
    /// word, unchanged words left out, a feed on every block, no block
    /// for a move that changes no printed axis.
    #[test]
    fn the_writer_prints_what_a_plain_model_of_it_prints(
        resolution in proptest::sample::select(vec![1e-3, 1e-4, 1e-6]),
        moves in proptest::collection::vec(
            (-100.0f64..100.0, -50.0f64..50.0, -1000.0f64..1000.0, 1e-5f64..1.0, 0u8..4),
            1..200,
        ),
    ) {
        let d = decimals_for(resolution);
        let mut stream = Vec::new();
        let mut at = (0.0, 0.0, 0.0);
        for &(x, z, c, t, keep) in &moves {
            // Some moves repeat a coordinate, or come within a unit of it.
            let x = if keep & 1 == 1 { at.0 + resolution * 0.3 } else { x };
            let z = if keep & 2 == 2 { at.1 } else { z };
            at = (x, z, c);
            stream.push(M::Linear { to: P::xzc(x, z, c), feed: Some(F::InverseTime(t)) });
        }
        let dialect = Dialect::linuxcnc();
        let mut w = ProgramWriter::new(&dialect, Setup::Lathe, "t", &[], "XZC", resolution, 1e-5)
            .expect("a lathe program");
        w.call_tool(&Start::default()).expect("tool 1");
        w.write_all(&stream).expect("printable");
        let text = w.finish().expect("checked");
        proptest::prop_assert!(check_numbers(&text, CommentStyle::Parentheses).is_ok());
        let units = |v: f64, d: u32| (v * 10f64.powi(d as i32)).round() as i64;
        let mut last: [Option<i64>; 3] = [None; 3];
        let mut expected = Vec::new();
        for m in &stream {
            let M::Linear { to, feed: Some(F::InverseTime(t)) } = m else { unreachable!() };
            let mut line = String::from(if expected.is_empty() { "G93 G1" } else { "G1" });
            let mut any = false;
            for (k, (letter, v, dk)) in
                [('X', to.x, d), ('Z', to.z, d), ('C', to.c.to_degrees(), 5)].into_iter().enumerate()
            {
                let n = units(v, dk);
                if last[k] != Some(n) {
                    line += &format!(" {letter}{}", std_word(n, dk));
                    last[k] = Some(n);
                    any = true;
                }
            }
            if any {
                line += &format!(" F{}", std_word(units(60.0 / t, 3), 3));
                expected.push(line);
            }
        }
        let written: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("G93"))
            .take_while(|l| *l != "G53 G0 Z0")
            .collect();
        proptest::prop_assert_eq!(written, expected);
        proptest::prop_assert!(text.lines().all(|l| l.len() <= 255));
    }
}

/// A Fanuc-like lathe dialect: integer S and T, two-digit tool pairs.
fn fanuc_like() -> Dialect {
    let mut d = Dialect::linuxcnc();
    d.name = "fanuc_like".into();
    d.lathe_setup = vec!["G18 G21 G40 G80 G90 G94".into()];
    d.lathe_tool_call = vec!["T{tool:2}{offset:2}".into()];
    d.surface_speed = vec!["G50 S{cap}".into(), "G96 S{speed}".into()];
    d.word_formats = ["X4.4", "Z4.4", "I4.4", "K4.4", "S5", "T4", "M3"]
        .iter()
        .map(|f| WordFormat::parse(f).expect("format"))
        .collect();
    d
}

#[test]
fn an_integer_s_word_has_no_point_and_a_constant_rpm_start_cancels_g96() {
    let text = written_in(&fanuc_like(), Setup::Lathe, "XZ", &[]).expect("writes");
    assert!(text.contains("\nT0101\nG97 S1000 M3\n"), "{text}");
    assert!(!text.contains("S1000."), "{text}");
    // Constant surface speed: the clamp before G96, both integers.
    let mut w = ProgramWriter::new(&fanuc_like(), Setup::Lathe, "t", &[], "XZ", 1e-3, 1e-3)
        .expect("starts");
    w.call_tool(&Start::default()).expect("T0101");
    w.write(&M::SpindleSurfaceSpeed {
        surface_speed: 2000.0,
        cap: RPM_1000 * 3.0,
    })
    .expect("writes");
    let text = w.finish().expect("ends");
    assert!(text.contains("G50 S3000\nG96 S120\nM3\n"), "{text}");
}

/// An inverse-time F (three decimals) is held to its format's integer
/// digits as a feed per minute is (here five decimals, the format's):
/// each mode's limit in units of its own last decimal.
#[test]
fn feeds_are_held_to_their_integer_digits_in_each_mode() {
    let mut dialect = Dialect::linuxcnc();
    dialect
        .word_formats
        .push(WordFormat::parse("F3.5").expect("a format"));
    let mut w = ProgramWriter::new(&dialect, Setup::Lathe, "t", &[], "XZC", 1e-6, 1e-5)
        .expect("a lathe program");
    w.call_tool(&Start::default()).expect("tool 1");
    let mut at = 0.0;
    let mut feed = |w: &mut ProgramWriter, f: F| {
        at += 1.0;
        w.write(&M::Linear {
            to: P::xzc(at, 0.5, 0.0),
            feed: Some(f),
        })
    };
    // 60 / 0.0601 s = 998.336 a minute: three digits before the point.
    assert!(feed(&mut w, F::InverseTime(0.0601)).is_ok());
    // 60 / 0.06 s = 1000: four.
    assert!(feed(&mut w, F::InverseTime(0.06)).is_err());
    // 16.65 mm/s = 999 mm/min; 16.67 mm/s = 1000.2 mm/min.
    assert!(feed(&mut w, F::PerTime(16.65)).is_ok());
    assert!(feed(&mut w, F::PerTime(16.67)).is_err());
    let text = w.take_text().expect("text");
    assert!(text.contains(" F998.336\n"), "{text}");
    assert!(text.contains(" F999.\n"), "{text}");
}

/// A dialect's `max_decimals` holds every word without a format of its
/// own, F included, as the reader holds them (a Fanuc lathe's 18.182
/// um/rev was written `F0.018182`, six decimals, and the build's read-back
/// refused its own program, E0305; found by the fuzzer's dialect draws).
#[test]
fn a_feed_is_printed_within_the_dialects_most_decimals() {
    let mut d = fanuc_like();
    d.max_decimals = Some(4);
    let text = written_in(
        &d,
        Setup::Lathe,
        "XZ",
        &[
            M::Rapid(P::xz(1.0, 0.1)),
            M::Linear {
                to: P::xz(1.0, 0.0),
                feed: Some(F::PerRevolution(0.018182 / (2.0 * PI))),
            },
            M::Linear {
                to: P::xz(0.5, 0.0),
                feed: Some(F::PerTime(537.238_3 / 60.0)),
            },
        ],
    )
    .expect("writes");
    assert!(text.contains(" F0.0182\n"), "{text}");
    assert!(text.contains(" F537.2383\n"), "{text}");
    // Without the limit, six decimals as before.
    let text = written_in(
        &fanuc_like(),
        Setup::Lathe,
        "XZ",
        &[
            M::Rapid(P::xz(1.0, 0.1)),
            M::Linear {
                to: P::xz(1.0, 0.0),
                feed: Some(F::PerRevolution(0.018182 / (2.0 * PI))),
            },
        ],
    )
    .expect("writes");
    assert!(text.contains(" F0.018182\n"), "{text}");
}

#[test]
fn word_formats_refuse_a_point_in_an_integer_word_and_too_many_digits() {
    let d = fanuc_like();
    assert!(check_word_formats("G97 S1000 M3", &d).is_ok());
    for bad in ["S1000. M3", "T010101", "M30.", "G0 X12345.6", "G1 Z1.23456"] {
        assert!(check_word_formats(bad, &d).is_err(), "{bad} passed");
    }
    // Comments are not code.
    assert!(check_word_formats("(S1000.)", &d).is_ok());
    // A dialect line that breaks its own format is refused as written.
    let mut d = fanuc_like();
    d.end = vec!["M30.".into()];
    assert!(written_in(&d, Setup::Lathe, "XZ", &[]).is_err());
}

#[test]
fn word_formats_read_as_fanuc_manuals_write_them() {
    assert_eq!(
        WordFormat::parse("X4.4"),
        Ok(WordFormat {
            letter: 'X',
            integer_digits: 4,
            decimals: Some(4)
        })
    );
    assert_eq!(WordFormat::parse("S5").map(|f| f.decimals), Ok(None));
    for bad in ["", "s5", "S", "S.4", "X4.", "X4.44.4", "X0", "X99"] {
        assert!(WordFormat::parse(bad).is_err(), "{bad} read");
    }
}

#[test]
fn a_tool_call_is_the_dialects_and_a_number_that_does_not_fit_is_refused() {
    let d = fanuc_like();
    let start = Start {
        tool: 12,
        offset: 3,
        ..Start::default()
    };
    assert_eq!(
        tool_call_lines(&d, Setup::Lathe, &start),
        Ok(vec!["T1203".to_string()])
    );
    let too_big = Start {
        tool: 100,
        ..Start::default()
    };
    assert!(tool_call_lines(&d, Setup::Lathe, &too_big).is_err());
    let mut none = Dialect::linuxcnc();
    none.mill_tool_call.clear();
    assert!(check_dialect(&none, Setup::Mill, 1e-3).is_err());
    assert!(written_in(&none, Setup::Mill, "XYZ", &[]).is_err());
}

#[test]
fn no_move_before_the_tool_call_and_no_feed_with_the_spindle_stopped() {
    let d = Dialect::linuxcnc();
    let cut = M::Linear {
        to: P::xyz(1.0, 0.0, 0.0),
        feed: Some(F::PerTime(1.0)),
    };
    let mut w = ProgramWriter::new(&d, Setup::Mill, "t", &[], "XYZ", 1e-3, 1e-3).expect("starts");
    assert!(w.write(&M::Rapid(P::xyz(0.0, 0.0, 5.0))).is_err());
    assert!(
        ProgramWriter::new(&d, Setup::Mill, "t", &[], "XYZ", 1e-3, 1e-3)
            .expect("starts")
            .finish()
            .is_err(),
        "a program without a tool call"
    );
    w.call_tool(&Start::default()).expect("T1");
    w.write(&M::Rapid(P::xyz(0.0, 0.0, 5.0))).expect("a rapid");
    let Err(ProgramError::Unsupported(why)) = w.write(&cut) else {
        panic!("a feed move with the spindle stopped was written")
    };
    assert!(why.contains("spindle stopped"), "{why}");
    // Held still for a knife, the spindle is oriented first.
    w.write(&M::SpindleHeld).expect("M19");
    w.write(&cut).expect("a cut");
    let text = w.finish().expect("ends");
    assert!(text.contains("M19 R0\nG94 G1 X1. Z0. F60.\n"), "{text}");
    assert!(text.ends_with("M5\nG53 G0 Z0\nM2\n"), "{text}");
}

#[test]
fn the_spindle_turns_the_jobs_way_and_coolant_is_on_between_call_and_end() {
    let d = Dialect::linuxcnc();
    let mut w = ProgramWriter::new(&d, Setup::Mill, "t", &[], "XYZ", 1e-3, 1e-3).expect("starts");
    w.call_tool(&Start {
        rotation: crate::moves::Rotation::CounterClockwise,
        coolant: Coolant::Mist,
        ..Start::default()
    })
    .expect("T1 M7");
    w.write(&M::SpindleOn(RPM_1000)).expect("M4");
    let text = w.finish().expect("ends");
    assert!(
        text.ends_with("T1 M6 G43 H1\nM7\nG97 S1000 M4\nM5\nM9\nG53 G0 Z0\nM2\n"),
        "{text}"
    );
    let mut dry = Dialect::linuxcnc();
    dry.coolant_mist = None;
    assert!(coolant_word(&dry, Coolant::Mist).is_err());
}

/// A value for the block printer's property test: anywhere in a range,
/// on a rounding tie at `d` decimals, a negative that rounds to zero
/// (`-0` must print as `0.`), or at the edge of `limit` integer digits.
fn printer_value(d: u32, limit: u32) -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    let unit = 10f64.powi(-(d as i32));
    let edge = 10f64.powi(limit as i32);
    prop_oneof![
        -1000.0f64..1000.0,
        (-100_000i64..100_000).prop_map(move |k| (k as f64 + 0.5) * unit),
        (0.0f64..0.5).prop_map(move |f| -f * unit),
        Just(-0.0),
        (-3i64..3, any::<bool>())
            .prop_map(move |(k, neg)| (edge + k as f64 * unit * 0.5) * if neg { -1.0 } else { 1.0 }),
    ]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]

    /// The block printer against a straightforward reference, move by
    /// move, over random values, decimals and dialect word formats (X, Y
    /// and Z, and C in degrees from the stream's radians): each
    /// word as `f64::round` and `{:.N}` print it (ties away from zero, no
    /// `-0`), unchanged words left out, and a block refused exactly when
    /// a word has more digits before the point than its format allows or
    /// more digits in all than the dialect's limit.
    #[test]
    fn blocks_print_what_a_plain_formatter_prints(
        resolution in proptest::sample::select(vec![1e-3, 1e-4, 1e-6]),
        formats in (1u32..6, 0u32..3, 1u32..6, 0u32..3, 2u32..7, 0u32..7, 2u32..7),
        max_digits in proptest::option::of(5u32..13),
        seed in proptest::collection::vec((0u8..8, 0.01f64..2000.0), 1..40),
        values in proptest::collection::vec(
            (printer_value(3, 3), printer_value(4, 2), printer_value(6, 1), printer_value(5, 4)),
            40,
        ),
    ) {
        let d = decimals_for(resolution);
        let (xi, xd, zi, zd, fi, fd, ci) = formats;
        let mut dialect = Dialect::linuxcnc();
        dialect.max_digits = max_digits;
        let cd = dialect.c_decimals;
        for f in [format!("X{xi}.{}", d + xd), format!("Z{zi}.{}", d + zd), format!("F{fi}.{fd}"), format!("C{ci}.{cd}")] {
            dialect.word_formats.push(WordFormat::parse(&f).expect("a format"));
        }
        let mut w = ProgramWriter::new(&dialect, Setup::Mill, "t", &[], "XYZC", resolution, 1e-3)
            .expect("a mill program");
        w.call_tool(&Start::default()).expect("tool 1");
        w.write(&M::SpindleOn(RPM_1000)).expect("spindle");
        w.take_text().expect("text");
        let feed_d = fd.min(6);
        let word = |letter: char, n: i64, d: u32, integer: u32| {
            let s = std_word(n, d);
            let whole = s.trim_start_matches('-').split('.').next().unwrap_or("").len();
            let digits = s.bytes().filter(u8::is_ascii_digit).count();
            let fits = whole as u32 <= integer && max_digits.is_none_or(|m| digits <= m as usize);
            fits.then(|| format!(" {letter}{s}"))
        };
        let (mut last, mut last_feed, mut first) = ([None::<i64>; 4], None::<i64>, true);
        for (k, &(pick, feed)) in seed.iter().enumerate() {
            let (a, b, c, degrees) = values[k];
            let v = [a, b, c];
            let axes = [v[pick as usize % 3], v[(pick as usize + 1) % 3], v[(pick as usize + 2) % 3]];
            // C in the stream is in radians; the program prints degrees.
            let radians = degrees.to_radians();
            let to = P { x: axes[0], y: axes[1], z: axes[2], c: radians };
            let got = w
                .write(&M::Linear { to, feed: Some(F::PerTime(feed)) })
                .and_then(|()| w.take_text());
            // The reference.
            let mut line = String::from(if first { "G94 G1" } else { "G1" });
            let mut next = last;
            let mut refused = false;
            let printed = [axes[0], axes[1], axes[2], radians.to_degrees()];
            let words = [('X', xi, d), ('Y', u32::MAX, d), ('Z', zi, d), ('C', ci, cd)];
            for (i, (letter, integer, d)) in words.into_iter().enumerate() {
                let n = (printed[i] * 10f64.powi(d as i32)).round() as i64;
                if last[i] == Some(n) {
                    continue;
                }
                match word(letter, n, d, integer) {
                    Some(wd) => line += &wd,
                    None => refused = true,
                }
                next[i] = Some(n);
            }
            let nf = (feed * 60.0 * 10f64.powi(feed_d as i32)).round() as i64;
            if next == last {
                proptest::prop_assert_eq!(got, Ok(String::new()));
                continue;
            }
            if first || last_feed != Some(nf) {
                match word('F', nf, feed_d, fi) {
                    Some(wd) => line += &wd,
                    None => refused = true,
                }
            }
            if refused {
                proptest::prop_assert!(got.is_err(), "{:?} printed, the reference refuses it", got);
                continue;
            }
            line.push('\n');
            proptest::prop_assert_eq!(got, Ok(line));
            (last, last_feed, first) = (next, Some(nf), false);
        }
    }
}

/// A coordinate for the common block's differential test: anywhere, a
/// step of a unit or less from a few fixed values (so words repeat), a
/// rounding tie, an axis left where it is, a value no word can print,
/// or one at the edge of four integer digits.
fn coordinate() -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        4 => -500.0f64..500.0,
        4 => (0u8..3, -3i64..3).prop_map(|(k, j)| k as f64 * 7.25 + j as f64 * 4e-7),
        1 => (-100_000i64..100_000).prop_map(|k| (k as f64 + 0.5) * 1e-4),
        2 => Just(f64::NAN),
        1 => prop_oneof![Just(1e19), Just(-2e18), Just(f64::INFINITY)],
        1 => (-3i64..3, any::<bool>())
            .prop_map(|(k, neg)| (1e4 + k as f64 * 5e-5) * if neg { -1.0 } else { 1.0 }),
    ]
}

/// A move's end for the differential test.
fn position() -> impl proptest::strategy::Strategy<Value = P> {
    use proptest::prelude::*;
    (coordinate(), coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z, c)| P {
        x,
        y,
        z,
        c,
    })
}

/// A feed for the differential test, in any mode: one that prints as
/// zero or not at all among them, and a few that repeat (so the feed
/// word is left out now and then).
fn feed() -> impl proptest::strategy::Strategy<Value = Option<F>> {
    use proptest::prelude::*;
    prop_oneof![
        Just(None),
        (0u8..2).prop_map(|k| Some(F::PerTime(1.0 + k as f64))),
        (0u8..2).prop_map(|k| Some(F::PerRevolution(0.01 + k as f64 * 0.01))),
        (1e-4f64..50.0).prop_map(|v| Some(F::PerTime(v))),
        (1e-5f64..0.1).prop_map(|v| Some(F::PerRevolution(v))),
        (1e-7f64..10.0).prop_map(|t| Some(F::InverseTime(t))),
        prop_oneof![Just(0.0), Just(1e-12), Just(f64::NAN), Just(1e30)]
            .prop_map(|v| Some(F::PerTime(v))),
    ]
}

/// A move for the differential test: mostly rapids and lines in every
/// feed mode (a feed that prints as zero or not at all among them), now
/// and then an arc, or the spindle stopped or started.
fn any_move() -> impl proptest::strategy::Strategy<Value = M> {
    use proptest::prelude::*;
    prop_oneof![
        8 => (position(), feed()).prop_map(|(to, feed)| M::Linear { to, feed }),
        3 => position().prop_map(M::Rapid),
        1 => (position(), -10.0f64..10.0, -10.0f64..10.0, any::<bool>(), feed()).prop_map(
            |(to, i, k, ccw, feed)| M::Arc {
                to,
                centre: P::xz(i, k),
                plane: Plane::Zx,
                ccw,
                feed,
            }
        ),
        1 => Just(M::SpindleOff),
        1 => Just(M::SpindleOn(RPM_1000)),
    ]
}

/// The dialects of the differential test: LinuxCNC as it is, with word
/// formats and a digit limit, with a line limit that some blocks reach
/// (`line_limit`), with block
/// numbers, with a motion word and a block end too long for the common
/// block's fixed copies, and the Fanuc-like lathe.
fn differential_dialect(
    k: u8,
    max_digits: Option<u32>,
    line_limit: usize,
) -> (Dialect, Setup, &'static str) {
    let mut d = Dialect::linuxcnc();
    let (setup, axes) = match k % 3 {
        0 => (Setup::Lathe, "XZC"),
        1 => (Setup::Mill, "XYZ"),
        _ => (Setup::Mill, "XYZC"),
    };
    match k / 3 {
        0 => {}
        1 => {
            d.max_digits = max_digits;
            for f in ["X4.6", "Y3.6", "Z2.6", "F5.3", "C5.5"] {
                d.word_formats.push(WordFormat::parse(f).expect("a format"));
            }
        }
        2 => d.max_line_length = Some(line_limit),
        3 => d.line_numbers = Some(10),
        4 => {
            d.linear = "G1 G64 P0.001 Q0.001".into();
            d.block_end = " ; a block end of twenty".into();
        }
        _ => return (fanuc_like(), Setup::Lathe, "XZ"),
    }
    (d, setup, axes)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

    /// The common block (one pass) against the general path alone over
    /// random streams and dialects, the one-pass writer given them in
    /// chunks through `write_all`, the general one move by move: the same
    /// text after every chunk, the same refusals, the same program at
    /// the end.
    #[test]
    fn the_common_block_is_the_general_paths(
        dialect in 0u8..18,
        resolution in proptest::sample::select(vec![1e-3, 1e-4, 1e-6]),
        max_digits in proptest::option::of(5u32..13),
        line_limit in 20usize..50,
        stream in proptest::collection::vec(any_move(), 1..80),
        chunks in proptest::collection::vec(1usize..8, 1..6),
    ) {
        let (d, setup, axes) = differential_dialect(dialect, max_digits, line_limit);
        let start = |common: bool| {
            let mut w = ProgramWriter::new(&d, setup, "t", &[], axes, resolution, 1e-3)?;
            w.common_blocks &= common;
            w.call_tool(&Start::default())?;
            w.write(&M::SpindleOn(RPM_1000))?;
            Ok::<_, ProgramError>(w)
        };
        let (Ok(mut one_pass), Ok(mut general)) = (start(true), start(false)) else {
            // A dialect this resolution does not fit: refused alike.
            proptest::prop_assert_eq!(
                format!("{:?}", start(true).err()),
                format!("{:?}", start(false).err())
            );
            return Ok(());
        };
        proptest::prop_assert!(!general.common_blocks);
        // The one-pass writer takes the stream in chunks through
        // `write_all` (odd and even lengths: pairs of common blocks and a
        // move left over), the general one move by move, stopping where
        // the chunk stops (at its first refusal).
        let mut at = 0;
        let mut chunks = chunks.iter().cycle();
        while at < stream.len() {
            let n = (*chunks.next().unwrap_or(&1)).min(stream.len() - at);
            let chunk = &stream[at..at + n];
            at += n;
            let a = one_pass.write_all(chunk).and_then(|()| one_pass.take_text());
            let b = chunk
                .iter()
                .try_for_each(|m| general.write(m))
                .and_then(|()| general.take_text());
            // Compared as printed: a refused NaN is not equal to itself.
            proptest::prop_assert_eq!(format!("{a:?}"), format!("{b:?}"), "after {:?}", chunk);
            if a.is_err() {
                // What the refused chunk wrote before its refusal.
                proptest::prop_assert_eq!(
                    format!("{:?}", one_pass.take_text()),
                    format!("{:?}", general.take_text())
                );
            }
        }
        proptest::prop_assert_eq!(general.common_written, 0);
        proptest::prop_assert_eq!(
            format!("{:?}", one_pass.finish()),
            format!("{:?}", general.finish())
        );
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]

    /// `write_all` compiled for AVX2 (`write_all_avx2`, taken when the
    /// processor has it) against the same code compiled for any x86-64,
    /// over the differential test's random streams and dialects, in
    /// chunks: the same text after every chunk, the same refusals, the
    /// same end. On a processor without AVX2 there is nothing to compare
    /// (both writers take the plain code).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn write_all_for_avx2_writes_what_it_writes_for_any_x86_64(
        dialect in 0u8..18,
        resolution in proptest::sample::select(vec![1e-3, 1e-4, 1e-6]),
        max_digits in proptest::option::of(5u32..13),
        line_limit in 20usize..50,
        stream in proptest::collection::vec(any_move(), 1..80),
        chunks in proptest::collection::vec(1usize..8, 1..6),
    ) {
        let (d, setup, axes) = differential_dialect(dialect, max_digits, line_limit);
        let start = |avx2: bool| {
            let mut w = ProgramWriter::new(&d, setup, "t", &[], axes, resolution, 1e-3)?;
            w.avx2 &= avx2;
            w.call_tool(&Start::default())?;
            w.write(&M::SpindleOn(RPM_1000))?;
            Ok::<_, ProgramError>(w)
        };
        let (Ok(mut fast), Ok(mut plain)) = (start(true), start(false)) else {
            return Ok(());
        };
        proptest::prop_assert!(!plain.avx2);
        proptest::prop_assert_eq!(fast.avx2, has_avx2());
        let mut at = 0;
        let mut chunks = chunks.iter().cycle();
        while at < stream.len() {
            let n = (*chunks.next().unwrap_or(&1)).min(stream.len() - at);
            let chunk = &stream[at..at + n];
            at += n;
            let a = fast.write_all(chunk).and_then(|()| fast.take_text());
            let b = plain.write_all(chunk).and_then(|()| plain.take_text());
            proptest::prop_assert_eq!(format!("{a:?}"), format!("{b:?}"), "after {:?}", chunk);
        }
        proptest::prop_assert_eq!(fast.common_written, plain.common_written);
        proptest::prop_assert_eq!(format!("{:?}", fast.finish()), format!("{:?}", plain.finish()));
    }
}

/// The emission bench's spiral (X, Z and C on every move, inverse time)
/// goes the one-pass way block for block, and so does a mill's feed per
/// minute; a dialect that numbers its blocks does not.
#[test]
fn common_blocks_are_the_common_path() {
    let spiral: Vec<M> = (0..2000)
        .map(|i| {
            let c = i as f64 * 0.0021;
            M::Linear {
                to: P::xzc(
                    24.0 - 0.002 * c / std::f64::consts::TAU,
                    0.4997 + 0.018 * (7.0 * c).sin().powi(2),
                    c,
                ),
                feed: Some(F::InverseTime(0.00058 + 1e-7 * (i % 13) as f64)),
            }
        })
        .collect();
    let mut w = ProgramWriter::new(
        &Dialect::linuxcnc(),
        Setup::Lathe,
        "t",
        &[],
        "XZC",
        1e-6,
        1e-5,
    )
    .expect("a lathe program");
    w.call_tool(&Start::default()).expect("tool 1");
    w.write_all(&spiral).expect("printable");
    let text = w.take_text().expect("checked");
    let blocks = text.lines().filter(|l| l.starts_with("G1 ")).count();
    // The first move states the feed mode (`G93 G1 …`): the general way.
    assert_eq!(w.common_written, blocks);
    assert_eq!(blocks, 1999);
    let mill: Vec<M> = (0..100)
        .map(|i| M::Linear {
            to: P::xyz(i as f64 * 0.01, 1.0, -0.5),
            feed: Some(F::PerTime(10.0)),
        })
        .collect();
    let mut w = ProgramWriter::new(
        &Dialect::linuxcnc(),
        Setup::Mill,
        "t",
        &[],
        "XYZ",
        1e-3,
        1e-3,
    )
    .expect("a mill program");
    w.call_tool(&Start::default()).expect("tool 1");
    w.write(&M::SpindleOn(RPM_1000)).expect("spindle");
    w.write_all(&mill).expect("printable");
    assert_eq!(w.common_written, 99);
    let mut numbered = Dialect::linuxcnc();
    numbered.line_numbers = Some(10);
    let mut w = ProgramWriter::new(&numbered, Setup::Mill, "t", &[], "XYZ", 1e-3, 1e-3)
        .expect("a mill program");
    w.call_tool(&Start::default()).expect("tool 1");
    w.write(&M::SpindleOn(RPM_1000)).expect("spindle");
    w.write_all(&mill).expect("printable");
    assert_eq!(w.common_written, 0);
}

#[test]
fn all_ascii_finds_any_byte_above_0x7f_anywhere() {
    // Lengths around the 64-byte blocks; one high byte at each place, of
    // each kind (0x80, a UTF-8 lead byte, 0xff), in the blocks and in the
    // remainder.
    for len in [0, 1, 7, 8, 63, 64, 65, 127, 128, 129, 200] {
        let ascii: Vec<u8> = (0..len).map(|i| b' ' + (i % 90) as u8).collect();
        assert!(all_ascii(&ascii), "{len} ASCII bytes");
        for at in 0..len {
            for high in [0x80, 0xc3, 0xff] {
                let mut b = ascii.clone();
                b[at] = high;
                assert!(!all_ascii(&b), "{high:#x} at {at} of {len}");
            }
        }
    }
}

#[test]
fn text_that_is_not_ascii_is_still_taken_whole() {
    // A comment's non-ASCII letters go through the UTF-8 decoder, not
    // the ASCII pass: the same text comes out.
    let mut w = ProgramWriter::new(
        &Dialect::linuxcnc(),
        Setup::Mill,
        "t1",
        &[],
        "XYZ",
        1e-3,
        1e-3,
    )
    .expect("writer");
    w.call_tool(&Start::default()).expect("tool");
    w.take_text().expect("header");
    w.comment("Glasschliff für Linse Ø 12, Mikrometer µm");
    w.write(&M::Rapid(P::xyz(1.0, 2.0, 5.0))).expect("rapid");
    let text = w.take_text().expect("UTF-8 text");
    assert!(text.contains("für Linse Ø 12"), "{text}");
    assert!(text.ends_with("G0 X1. Y2. Z5.\n"), "{text}");
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the processor has AVX2.
        let t = unsafe { utf8_avx2("Ø µ".as_bytes().to_vec()) };
        assert_eq!(t.expect("UTF-8"), "Ø µ");
        let t = unsafe { utf8_avx2(vec![b'G'; 70].into_iter().chain([0xff]).collect()) };
        assert!(t.is_err());
    }
    assert!(utf8(vec![b'X', 0xc3]).is_err());
}

#[test]
fn the_text_is_the_same_however_often_it_is_taken() {
    // Blocks printed into rooms zeroed a step ahead (`zero_ahead`): long
    // texts cross many steps, long comments push the text past what is
    // zeroed, and taking the text starts a new allocation; the text is
    // the same taken after every move as taken once at the end.
    let stream: Vec<M> = (0..3000)
        .map(|i| {
            let c = i as f64 * 0.01;
            M::Linear {
                to: P::xzc(20.0 - c * 1e-3, 0.5 + 0.01 * (3.0 * c).sin(), c),
                feed: Some(F::InverseTime(0.001 + 1e-6 * (i % 7) as f64)),
            }
        })
        .collect();
    let long_comment = "a comment, long ".repeat(700);
    let write = |take_every: usize| {
        let mut w = ProgramWriter::new(
            &Dialect::linuxcnc(),
            Setup::Lathe,
            "t1",
            &[],
            "XZC",
            1e-6,
            1e-5,
        )
        .expect("writer");
        w.call_tool(&Start::default()).expect("tool");
        let mut text = String::new();
        for (i, m) in stream.iter().enumerate() {
            if i % 1000 == 500 {
                w.comment(&long_comment);
            }
            w.write_all([m]).expect("printable");
            if (i + 1) % take_every == 0 {
                text += &w.take_text().expect("text");
            }
        }
        text + &w.finish().expect("text")
    };
    let once = write(usize::MAX);
    assert!(once.len() > 3 * ZERO_STEP * 4, "{}", once.len());
    for every in [1, 7, 333] {
        assert_eq!(write(every), once, "taken every {every} moves");
    }
}
