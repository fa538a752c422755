//! Siemens B splines (BSPLINE) read from program text: the curve moved
//! along as the manual defines it, and the blocks the control refuses
//! found with their spans.

use super::*;

/// A Sinumerik mill that interpolates B splines.
fn siemens() -> Dialect {
    let mut d = Dialect::linuxcnc();
    d.comment = crate::dialect::CommentStyle::Semicolon;
    d.spline = Some(crate::dialect::SplineForm::Bspline);
    assert_eq!(Controller::of(&d), Controller::Siemens);
    d
}

fn mill() -> MachineLimits {
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

/// A quadratic B spline from X0 Z0 over the control point X1 Z1 to X2 Z0:
/// one Bézier piece, whose middle is X1 Z0.5 (¼ P0 + ½ P1 + ¼ P2, worked
/// by hand); every point on it lies on the parabola z = x (2 − x) / 2.
const PROGRAM: &str = "; +Z out of the material\nG17 G71 G90 G40 G94 G54\nT1 D1\nM6\nG97 S1000 M3\nG0 X0 Y0 Z1\nG94 G1 Z0 F100\nBSPLINE SD=2 PL=0.5 X1 Y0 Z1\nPL=0.5 X2 Y0 Z0\nG1 X3\nG0 Z1\nM5\nM30\n";

#[test]
fn a_b_spline_is_read_as_the_manual_defines_it() {
    let (found, moves) = read_moves(PROGRAM, &siemens(), &mill());
    assert_eq!(found, vec![]);
    let on_curve: Vec<&Executed> = moves
        .iter()
        .filter(|m| m.from[0].is_some_and(|x| x >= 0.0) && m.to[0].is_some_and(|x| x <= 2.0))
        .filter(|m| {
            m.path == Path::Line && m.to[2].is_some_and(|z| z > 0.0 || m.to[0] == Some(2.0))
        })
        .collect();
    assert!(on_curve.len() > 20, "{}", on_curve.len());
    for m in &on_curve {
        let (x, z) = (m.to[0].unwrap(), m.to[2].unwrap());
        assert!((z - x * (2.0 - x) / 2.0).abs() < 1e-12, "{x} {z}");
    }
    assert!(
        on_curve
            .iter()
            .any(|m| m.to[0] == Some(1.0) && m.to[2] == Some(0.5)),
        "its middle"
    );
    // The next G1 starts where the curve ends.
    let after = moves.iter().find(|m| m.to[0] == Some(3.0)).expect("G1 X3");
    assert_eq!((after.from[0], after.from[2]), (Some(2.0), Some(0.0)));
    // The fast reading reads it the same.
    let (f2, m2) = read_moves_by(PROGRAM, &siemens(), &mill(), false);
    assert_eq!((found, moves.len()), (f2, m2.len()));
}

#[test]
fn b_spline_blocks_the_control_refuses_are_found_with_their_spans() {
    let d = siemens();
    let cases: &[(&str, &str, &str)] = &[
        ("SD=2", "SD=4", "SD=2 or SD=3"),
        ("SD=2 PL=0.5", "SD=2", "without its knot spacing"),
        ("PL=0.5 X2", "PL=0.25 X2", "one spacing"),
        ("PL=0.5 X2", "PL=0 X2", "above 0"),
        ("PL=0.5 X2", "PL=0.5 PW=4 X2", "0 to 3"),
        ("PL=0.5 X2 Y0 Z0\n", "", "at least 3"),
        ("G90 G40", "G91 G40", "G90 only"),
    ];
    for (from, to, what) in cases {
        let text = PROGRAM.replacen(from, to, 1);
        assert_ne!(text, PROGRAM, "{from}");
        let found = read(&text, &d, &mill());
        let f = found
            .iter()
            .find(|f| f.rule == Rule::SplineRefused)
            .unwrap_or_else(|| panic!("{to}: {found:?}"));
        assert!(f.message.contains(what), "{to}: {}", f.message);
        assert!(f.span.1 > f.span.0, "{to}: {f:?}");
        let words = &text[f.span.0..f.span.1];
        if to.contains('=') && !what.contains("G90") {
            let word = to
                .split_whitespace()
                .find(|w| w.contains('=') && !from.contains(*w));
            if let Some(w) = word {
                assert_eq!(words, w, "{to}: {f:?}");
            }
        }
    }
}
