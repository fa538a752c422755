//! The writer's Klartext back end: a move as Heidenhain's conversational
//! blocks (`L X+1.5 Y-2 R0 F300`, `L Z+5 R0 FMAX`, `CC X+0 Y+0` then
//! `C X+1 Y+0 DR-`), every number through the same fixed-point formatter
//! as G-code, with the sign always written and no trailing point (as the
//! TNC itself writes them).

use super::{FeedMode, ProgramWriter, Spindle, Word};
use crate::moves::{Blank, Feed, Plane, Position};
use crate::post::ProgramError;
use crate::post::format::fixed_units;

impl ProgramWriter {
    /// A move as one `L` block (a line or, with `FMAX`, a rapid), or an
    /// arc as its circle centre `CC` (when it changes) and a `C` block.
    /// Axes are modal as in G-code: a coordinate whose printed value has
    /// not changed is left out, and a move that changes none is left out
    /// whole. `R0` (no radius compensation: the path is the tool
    /// centre's) is written in every `L` block, as the TNC writes it.
    /// `FMAX` holds for its own block only; the feed after a rapid is
    /// written again.
    pub(super) fn klartext_motion(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<Feed>,
        arc: Option<(Plane, Position)>,
    ) -> Result<(), ProgramError> {
        if !to.c.is_nan() {
            return Err(ProgramError::Unsupported(format!(
                "C-axis moves ({} writes milling programs of X, Y and Z)",
                self.dialect.name
            )));
        }
        if !matches!(word, Word::Rapid) && self.spindle == Spindle::Stopped {
            return Err(ProgramError::Unsupported(
                "a feed move with the spindle stopped".into(),
            ));
        }
        let feed = match feed {
            None => None,
            Some(Feed::PerTime(v)) => Some(v * 60.0),
            Some(_) => {
                return Err(ProgramError::Unsupported(format!(
                    "feeds per revolution or in inverse time ({} feeds in mm/min)",
                    self.dialect.name
                )));
            }
        };
        let start = self.text.len();
        let block_at_start = self.block;
        let centre_at_start = self.circle_centre;
        let r = self.klartext_blocks(word, to, feed, arc);
        match r {
            Ok(true) => Ok(()),
            Ok(false) | Err(_) => {
                // Nothing to move, or refused: no CC either.
                self.text.truncate(start);
                self.block = block_at_start;
                self.circle_centre = centre_at_start;
                r.map(|_| ())
            }
        }
    }

    /// The blocks of one move; false if it changes no printed axis.
    fn klartext_blocks(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<f64>,
        arc: Option<(Plane, Position)>,
    ) -> Result<bool, ProgramError> {
        if let Some((plane, centre)) = arc {
            if !self.dialect.arc_planes.contains(&plane) {
                return Err(ProgramError::Unsupported(format!(
                    "arcs in the {} plane",
                    plane.name()
                )));
            }
            self.check_arc_radii(plane, to, centre)?;
            self.circle_centre_block(plane, centre)?;
        }
        let start = self.text.len();
        self.begin_block();
        self.text
            .push(if matches!(word, Word::ArcCw | Word::ArcCcw) {
                b'C'
            } else {
                b'L'
            });
        let axes = to.axes();
        let mut printed = [0i64; 3];
        let mut changed = 0u8;
        for i in 0..3 {
            let v = axes[i];
            if v.is_nan() {
                continue;
            }
            let d = self.axis_decimals[i];
            let (Some(letter), Some(n)) = (self.letters[i], fixed_units(v, d)) else {
                return Err(self.not_printable(i, v));
            };
            if self.last[i] == n {
                continue;
            }
            self.text.extend_from_slice(&[b' ', letter as u8]);
            self.signed_number(letter, v, n, d)?;
            printed[i] = n;
            changed |= 1 << i;
        }
        if changed == 0 {
            self.text.truncate(start);
            return Ok(false);
        }
        match word {
            Word::ArcCw => self.text.extend_from_slice(b" DR-"),
            Word::ArcCcw => self.text.extend_from_slice(b" DR+"),
            _ => self.text.extend_from_slice(b" R0"),
        }
        match (word, feed) {
            (Word::Rapid, _) => {
                self.text.extend_from_slice(b" FMAX");
                // FMAX holds for its block only: state the feed again.
                self.last_feed = None;
            }
            (_, Some(f)) => self.klartext_feed(f)?,
            (_, None) => {}
        }
        self.end_block(start)?;
        self.moved(&printed, changed, axes);
        Ok(true)
    }

    /// `CC X… Y…` (or `CC X… Z…`, `CC Y… Z…`), the circle centre of the
    /// arcs that follow, in the two axes of their plane (the TNC takes the
    /// arc's plane from the axes of its centre), when it differs from the
    /// one in force (CC is modal on the TNC).
    fn circle_centre_block(&mut self, plane: Plane, centre: Position) -> Result<(), ProgramError> {
        let d = self.decimals;
        let axes = centre.axes();
        let (a, b) = plane.axes();
        // Written in X, Y, Z order: `CC X… Z…` for the ZX plane.
        let (first, second) = (a.min(b), a.max(b));
        let (Some(u), Some(v)) = (fixed_units(axes[first], d), fixed_units(axes[second], d)) else {
            return Err(self.not_printable(first, axes[first]));
        };
        if self.circle_centre == Some((plane, u, v)) {
            return Ok(());
        }
        let letter = |i: usize| ['X', 'Y', 'Z'][i];
        let start = self.text.len();
        self.begin_block();
        self.text.extend_from_slice(b"CC ");
        self.text.push(letter(first) as u8);
        self.signed_number(letter(first), axes[first], u, d)?;
        self.text.push(b' ');
        self.text.push(letter(second) as u8);
        self.signed_number(letter(second), axes[second], v, d)?;
        self.end_block(start)?;
        self.circle_centre = Some((plane, u, v));
        Ok(())
    }

    /// The workpiece blank for the TNC's graphic test run:
    /// `BLK FORM 0.1 Z X… Y… Z…` (the tool axis Z and the least corner),
    /// `BLK FORM 0.2 X… Y… Z…` (the greatest).
    pub(super) fn blank_form(&mut self, blank: &Blank) -> Result<(), ProgramError> {
        let d = self.decimals;
        for (head, corner) in [("BLK FORM 0.1 Z", blank.min), ("BLK FORM 0.2", blank.max)] {
            let start = self.text.len();
            self.begin_block();
            self.text.extend_from_slice(head.as_bytes());
            for (i, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                let Some(n) = fixed_units(corner[i], d) else {
                    return Err(self.not_printable(i, corner[i]));
                };
                self.text.extend_from_slice(&[b' ', letter as u8]);
                self.signed_number(letter, corner[i], n, d)?;
            }
            self.end_block(start)?;
        }
        Ok(())
    }

    /// The feed word (mm/min), written when its printed value changes or
    /// after a rapid.
    fn klartext_feed(&mut self, value: f64) -> Result<(), ProgramError> {
        let d = self.feed_decimals;
        let Some(n) = fixed_units(value, d).filter(|&n| n > 0) else {
            return Err(ProgramError::NotPrintable { word: 'F', value });
        };
        if self.last_feed != Some(n) {
            self.text.extend_from_slice(b" F");
            self.number('F', value, n, d)?;
            if self.text.last() == Some(&b'.') {
                self.text.pop();
            }
        }
        self.last_feed = Some(n);
        self.mode = Some(FeedMode::PerMinute);
        Ok(())
    }

    /// A coordinate as the TNC writes it: its sign always (`X+0`,
    /// `Y-1.25`), no trailing point.
    fn signed_number(&mut self, letter: char, v: f64, n: i64, d: u32) -> Result<(), ProgramError> {
        if n >= 0 {
            self.text.push(b'+');
        }
        self.number(letter, v, n, d)?;
        if self.text.last() == Some(&b'.') {
            self.text.pop();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ProgramWriter, Setup};
    use crate::dialect::{Dialect, Language, WordFormat};
    use crate::moves::{Feed as F, Move as M, Plane, Position as P, Start};
    use crate::post::ProgramError;
    use crate::reader::{self, MachineLimits, Path};
    use std::f64::consts::PI;

    /// `heidenhain_tnc_klartext` as `stdlib/dialects.lens` declares it.
    fn klartext() -> Dialect {
        let lines = |l: &[&str]| l.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        Dialect {
            name: "heidenhain_tnc_klartext".into(),
            language: Language::Klartext,
            extension: "H".into(),
            comment: crate::dialect::CommentStyle::Semicolon,
            start: lines(&["BEGIN PGM {JOB} MM"]),
            lathe_setup: Vec::new(),
            mill_setup: Vec::new(),
            lathe_tool_call: Vec::new(),
            mill_tool_call: lines(&["TOOL CALL {tool} Z"]),
            path_tolerance: lines(&["CYCL DEF 32.0 TOLERANCE", "CYCL DEF 32.1 T{tolerance}"]),
            surface_speed: Vec::new(),
            constant_rpm: None,
            spindle_orient: lines(&["M19"]),
            coolant_mist: None,
            end: lines(&["M30"]),
            trailer: lines(&["END PGM {JOB} MM"]),
            rapid: "L".into(),
            linear: "L".into(),
            arc_cw: "C".into(),
            arc_ccw: "C".into(),
            arc_planes: vec![Plane::Xy],
            arc_centre_absolute: true,
            per_minute: Some("F".into()),
            per_revolution: None,
            inverse_time: None,
            word_formats: ["S5", "M3", "F5.3"]
                .iter()
                .map(|f| WordFormat::parse(f).expect("format"))
                .collect(),
            line_numbers: Some(1),
            max_line_length: Some(254),
            ..Dialect::linuxcnc()
        }
    }

    fn mill() -> MachineLimits {
        MachineLimits {
            lathe: false,
            travel: [
                Some((-50.0, 50.0)),
                Some((-50.0, 50.0)),
                Some((-50.0, 50.0)),
                None,
            ],
            max_feed: Some(5000.0),
            max_spindle_rpm: Some(24000.0),
            servo: None,
        }
    }

    fn written(stream: &[M]) -> Result<String, ProgramError> {
        let header = ["units mm; X Y Z of the tool centre, +Z out of the material".to_string()];
        let mut w =
            ProgramWriter::new(&klartext(), Setup::Mill, "dome", &header, "XYZ", 1e-3, 1e-3)?;
        w.call_tool(&Start::default())?;
        w.write(&M::SpindleOn(12000.0 * 2.0 * PI / 60.0))?;
        w.write_all(stream)?;
        w.finish()
    }

    fn arc(to: P, centre: P, ccw: bool) -> M {
        M::Arc {
            to,
            centre,
            plane: Plane::Xy,
            ccw,
            feed: Some(F::PerTime(5.0)),
        }
    }

    #[test]
    fn a_milling_program_in_klartext_reads_back_as_written() {
        let o = P::xyz(0.0, 0.0, f64::NAN);
        let text = written(&[
            M::Rapid(P::xyz(1.0, 0.0, 5.0)),
            M::Linear {
                to: P::xyz(1.0, 0.0, -0.25),
                feed: Some(F::PerTime(2.0)),
            },
            arc(P::xyz(0.0, 1.0, -0.25), o, true),
            arc(P::xyz(-1.0, 0.0, -0.25), o, true),
            arc(P::xyz(-2.0, 0.0, -0.25), P::xyz(-1.5, 0.0, f64::NAN), false),
            M::Rapid(P::xyz(-2.0, 0.0, 5.0)),
            M::Linear {
                to: P::xyz(-2.0, 0.0, 4.0),
                feed: Some(F::PerTime(5.0)),
            },
        ])
        .expect("writes");
        assert_eq!(
            text,
            "0 BEGIN PGM DOME MM\n\
             1 ; units mm; X Y Z of the tool centre, +Z out of the material\n\
             2 CYCL DEF 32.0 TOLERANCE\n\
             3 CYCL DEF 32.1 T0.001\n\
             4 TOOL CALL 1 Z S12000\n\
             5 M3\n\
             6 L X+1 Y+0 Z+5 R0 FMAX\n\
             7 L Z-0.25 R0 F120\n\
             8 CC X+0 Y+0\n\
             9 C X+0 Y+1 DR+ F300\n\
             10 C X-1 Y+0 DR+\n\
             11 CC X-1.5 Y+0\n\
             12 C X-2 DR-\n\
             13 L Z+5 R0 FMAX\n\
             14 L Z+4 R0 F300\n\
             15 M5\n\
             16 M30\n\
             17 END PGM DOME MM\n"
        );
        let (findings, moves) = reader::read_moves(&text, &klartext(), &mill());
        assert!(findings.is_empty(), "{findings:?}");
        let arcs: Vec<_> = moves
            .iter()
            .filter_map(|m| match m.path {
                Path::Arc { centre, cw, .. } => Some((centre, cw)),
                _ => None,
            })
            .collect();
        assert_eq!(
            arcs,
            [
                ((0.0, 0.0), false),
                ((0.0, 0.0), false),
                ((-1.5, 0.0), true)
            ]
        );
        assert_eq!(moves.len(), 7);
    }

    /// One `TOOL CALL` with the speed, the blank as `BLK FORM`, arcs in
    /// the ZX and YZ planes as `CC` of the plane's axes and `C`, a knife's
    /// spindle held by cycle 13; the reader reads each back as written.
    #[test]
    fn klartext_states_the_blank_calls_the_tool_once_and_cuts_arcs_in_every_plane() {
        let d = Dialect {
            arc_planes: Plane::ALL.to_vec(),
            spindle_orient: vec![
                "CYCL DEF 13.0 ORIENTATION".into(),
                "CYCL DEF 13.1 ANGLE 0".into(),
            ],
            ..klartext()
        };
        let start = Start {
            tool: 3,
            blank: Some(crate::moves::Blank {
                min: [-2.0, -2.0, -1.5],
                max: [2.0, 2.0, 0.0],
            }),
            ..Start::default()
        };
        let cut = |plane, to, centre, ccw| M::Arc {
            to,
            centre,
            plane,
            ccw,
            feed: Some(F::PerTime(5.0)),
        };
        let mut w =
            ProgramWriter::new(&d, Setup::Mill, "arcs", &[], "XYZ", 1e-3, 1e-3).expect("writer");
        w.call_tool(&start).expect("tool");
        w.write_all(&[
            M::SpindleOn(12000.0 * 2.0 * PI / 60.0),
            // Above everything the program feeds through, then down at
            // feed (a rapid below it would be a plunge, lensc's policy).
            M::Rapid(P::xyz(-1.0, 0.0, 2.0)),
            M::Linear {
                to: P::xyz(-1.0, 0.0, 0.0),
                feed: Some(F::PerTime(5.0)),
            },
            // A quarter turn in ZX about (X0, Z0): from X-1 Z0 to X0 Z-1,
            // clockwise seen in Z then X.
            cut(
                Plane::Zx,
                P::xyz(0.0, 0.0, -1.0),
                P::xyz(0.0, f64::NAN, 0.0),
                false,
            ),
            // And in YZ about (Y0, Z0): from Y0 Z-1 to Y1 Z0.
            cut(
                Plane::Yz,
                P::xyz(0.0, 1.0, 0.0),
                P::xyz(f64::NAN, 0.0, 0.0),
                true,
            ),
            M::SpindleOff,
            M::SpindleHeld,
            M::Linear {
                to: P::xyz(0.0, 1.0, 1.0),
                feed: Some(F::PerTime(5.0)),
            },
        ])
        .expect("moves");
        let text = w.finish().expect("program");
        for block in [
            "1 BLK FORM 0.1 Z X-2 Y-2 Z-1.5\n",
            "2 BLK FORM 0.2 X+2 Y+2 Z+0\n",
            "5 TOOL CALL 3 Z S12000\n6 M3\n",
            "CC X+0 Z+0\n",
            "C X+0 Z-1 DR-\n",
            "CC Y+0 Z+0\n",
            "C Y+1 Z+0 DR+\n",
            "CYCL DEF 13.0 ORIENTATION\n",
        ] {
            assert!(text.contains(block), "no `{block}` in\n{text}");
        }
        assert_eq!(text.matches("TOOL CALL").count(), 1, "{text}");
        let (findings, moves) = reader::read_moves(&text, &d, &mill());
        assert!(findings.is_empty(), "{findings:?}\n{text}");
        let arcs: Vec<_> = moves
            .iter()
            .filter_map(|m| match m.path {
                Path::Arc {
                    plane, centre, cw, ..
                } => Some((plane, centre, cw, m.to)),
                _ => None,
            })
            .collect();
        assert_eq!(
            arcs,
            [
                (
                    Plane::Zx,
                    (0.0, 0.0),
                    true,
                    [Some(0.0), Some(0.0), Some(-1.0), None]
                ),
                (
                    Plane::Yz,
                    (0.0, 0.0),
                    false,
                    [Some(0.0), Some(1.0), Some(0.0), None]
                ),
            ]
        );
    }

    #[test]
    fn what_klartext_cannot_say_is_refused() {
        let zx = M::Arc {
            to: P::xyz(1.0, 0.0, 0.0),
            centre: P::xyz(0.5, 0.0, 0.0),
            plane: Plane::Zx,
            ccw: false,
            feed: Some(F::PerTime(1.0)),
        };
        let e = written(&[M::Rapid(P::xyz(0.0, 0.0, 0.0)), zx]).expect_err("refused");
        assert!(e.message().contains("zx"), "{}", e.message());
        let per_rev = M::Linear {
            to: P::xyz(1.0, 0.0, 0.0),
            feed: Some(F::PerRevolution(0.001)),
        };
        let e = written(&[per_rev]).expect_err("refused");
        assert!(e.message().contains("mm/min"), "{}", e.message());
        let lathe = ProgramWriter::new(&klartext(), Setup::Lathe, "t", &[], "XZ", 1e-3, 1e-3);
        assert!(lathe.is_err_and(|e| e.message().contains("milling")));
    }

    #[test]
    fn the_reader_refuses_what_a_tnc_refuses() {
        let good = written(&[
            M::Rapid(P::xyz(1.0, 0.0, 5.0)),
            M::Linear {
                to: P::xyz(1.0, 0.0, -0.25),
                feed: Some(F::PerTime(2.0)),
            },
            arc(P::xyz(0.0, 1.0, -0.25), P::xyz(0.0, 0.0, f64::NAN), true),
        ])
        .expect("writes");
        let rules = |text: &str| -> Vec<reader::Rule> {
            reader::read(text, &klartext(), &mill())
                .into_iter()
                .map(|f| f.rule)
                .collect()
        };
        assert!(rules(&good).is_empty());
        let cases = [
            ("7 L Z-0.25", "8 L Z-0.25", reader::Rule::BlockSequence),
            ("8 CC X+0 Y+0\n", "", reader::Rule::NoCircleCentre),
            (
                "END PGM DOME MM",
                "END PGM OTHER MM",
                reader::Rule::ProgramFrame,
            ),
            (
                "0 BEGIN PGM DOME MM\n",
                "0 ; no begin\n",
                reader::Rule::ProgramFrame,
            ),
            ("R0 F120", "RL F120", reader::Rule::UnknownWord),
            ("DR+", "", reader::Rule::ArcWords),
            ("5 M3", "5 M5", reader::Rule::SpindleStopped),
        ];
        for (from, to, rule) in cases {
            let bad = good.replacen(from, to, 1);
            assert_ne!(bad, good, "{from}");
            assert!(
                rules(&bad).contains(&rule),
                "{from} → {to}: {:?}",
                rules(&bad)
            );
        }
    }
}
