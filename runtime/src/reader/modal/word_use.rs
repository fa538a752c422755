//! The words a LinuxCNC block's codes use: a parameter word (I J K R P Q
//! L D H) that no code of its block takes is refused, as the RS274NGC
//! interpreter refuses it (`interp_check.cc`, `check_other_codes`; its
//! messages, such as "I word with no G2, G3, G5, G5.1, G10, G33.1, G76,
//! or G87 to use it", are those of `rs274 -g` from linuxcnc-uspace 2.9,
//! checked block by block in `docs/controllers/linuxcnc.md`), and so are
//! two codes that both take the axis words (G28 with a motion code).
//!
//! The motion a block's words go to is the block's own motion code, or,
//! when the block has axis words (or, in an arc mode, centre words) and
//! no code of its own, the motion mode in force: the interpreter's
//! `motion_to_be`. Codes the reader does not know (G10, canned cycles,
//! G33, G76, M66 …) are refused as unknown before this rule, so the uses
//! they would give a word are not listed here.
//!
//! Fanuc, Sinumerik and Heidenhain ISO blocks are held to the same rule
//! for the parameter words whose use lensc reads (`parameter_words`):
//! their tables are in `docs/controllers/<family>.md`, each row with its
//! source or marked an assumption.

use super::super::lexer::{Block, Found};
use super::super::{Controller, Rule};
use super::{GGroup, Motion, State};

/// What a block holds that may use a parameter word.
struct Users {
    /// The motion the block's words go to (`motion_to_be`).
    motion: Option<Motion>,
    /// The block's G codes, in tenths (`G64` is 640).
    g: Vec<i64>,
    /// The block's M codes.
    m: Vec<i64>,
}

impl Users {
    fn g(&self, code: i64) -> bool {
        self.g.contains(&code)
    }

    fn arc(&self) -> bool {
        matches!(self.motion, Some(Motion::Cw | Motion::Ccw))
    }

    /// A block of a NURBS block (G5.2, or its control points in the mode).
    fn nurbs(&self) -> bool {
        self.motion == Some(Motion::NurbsBlock)
    }

    /// Whether a code of the block uses `letter`, by LinuxCNC's rules; the
    /// codes that would, for the message.
    fn uses(&self, letter: char) -> (bool, &'static str) {
        let spline = |codes: &[i64]| codes.iter().any(|c| self.g(*c));
        match letter {
            'I' | 'J' => (
                self.arc() || spline(&[50, 51]),
                "G2, G3, G5 or G5.1 (or G10, G33.1, G76, G87, which lensc does not read)",
            ),
            'K' => (
                self.arc(),
                "G2 or G3 (or G33, G33.1, G76, G87, which lensc does not read)",
            ),
            'R' => (
                self.arc() || self.m.contains(&19),
                "G2, G3 or M19 (or G10 and the canned cycles, which lensc does not read)",
            ),
            'P' => (
                self.arc() || self.nurbs() || spline(&[40, 50, 640]) || self.m.contains(&19),
                "G2, G3 (turns), G4 (dwell), G5, G5.2, G64 or M19",
            ),
            'Q' => (spline(&[50, 640]) || self.m.contains(&19), "G5, G64 or M19"),
            'L' => (
                self.nurbs() || spline(&[410, 420]),
                "G5.2 or cutter compensation (G41, G42)",
            ),
            'D' => (spline(&[410, 420, 960]), "G41, G42 or G96"),
            'H' => (self.g(430), "G43"),
            _ => (true, ""),
        }
    }
}

impl State {
    /// Every parameter word no code of the block uses, and two codes of
    /// the block that both take its axis words (LinuxCNC only).
    pub(super) fn word_use(
        &self,
        b: &Block,
        groups: &[(GGroup, usize)],
        line: &str,
        out: &mut Vec<Found>,
    ) {
        let g: Vec<i64> = b
            .words
            .iter()
            .filter(|w| w.letter == 'G')
            .filter_map(|w| self.g_code(w.value))
            .collect();
        let m: Vec<i64> = b
            .words
            .iter()
            .filter(|w| w.letter == 'M')
            .map(|w| w.value.round() as i64)
            .collect();
        // G80 beside another motion code: the other code wins.
        let own = groups
            .iter()
            .filter_map(|(g, i)| match g {
                GGroup::Motion(m) => Some((*m, *i)),
                _ => None,
            })
            .min_by_key(|(m, _)| *m == Motion::Cancel);
        let axis_users = groups
            .iter()
            .find(|(g, _)| *g == GGroup::MachineMove)
            .filter(|(_, i)| self.g_code(b.words[*i].value) == Some(280));
        if let (Some((_, i)), Some(&(_, j))) = (own, axis_users) {
            out.push((
                Rule::SameModalGroup,
                b.words[i].span,
                format!(
                    "`{}` and `{}` both take the block's axis words: the controller refuses the block",
                    b.words[j].text(line),
                    b.words[i].text(line)
                ),
                Some("put the motion and the G28 in blocks of their own".into()),
            ));
        }
        let has = |letters: &[char]| b.words.iter().any(|w| letters.contains(&w.letter));
        let modal_arc = matches!(self.motion, Some(Motion::Cw | Motion::Ccw));
        let motion = match own {
            Some((m, _)) => Some(m),
            None if axis_users.is_none()
                && (has(&['X', 'Y', 'Z', 'A', 'B', 'C'])
                    || (modal_arc && has(&['I', 'J', 'K', 'R']))) =>
            {
                self.motion
            }
            None => None,
        };
        if let Some((arc @ (Motion::Cw | Motion::Ccw), i)) = own
            && !has(&['I', 'J', 'K', 'R'])
        {
            out.push((
                Rule::ArcWords,
                b.words[i].span,
                format!(
                    "`{}` with no centre (I, J, K) or radius (R): the controller refuses the block",
                    b.words[i].text(line)
                ),
                Some(format!(
                    "give the arc its end and centre, or leave the {} out",
                    if arc == Motion::Cw { "G2" } else { "G3" }
                )),
            ));
        }
        // G5 and G5.1 with no axis word: "All axes missing with motion
        // code" (`rs274` 2.9; G0, G1 and G5.2 alone are run).
        if let Some((Motion::Spline(_), i)) = own
            && !has(&['X', 'Y', 'Z', 'A', 'B', 'C'])
        {
            out.push((
                Rule::ArcWords,
                b.words[i].span,
                format!(
                    "`{}` with no axis word: the controller refuses a spline with no end",
                    b.words[i].text(line)
                ),
                Some("give the spline its end point X Y, or leave the code out".into()),
            ));
        }
        if let Some(i) = b
            .words
            .iter()
            .position(|w| w.letter == 'G' && self.g_code(w.value) == Some(530))
            && !matches!(motion, Some(Motion::Rapid | Motion::Linear))
        {
            out.push((
                Rule::UnusedWord,
                b.words[i].span,
                "`G53` with no straight move (G0 or G1 with axis words) to go to machine coordinates: the controller refuses it".into(),
                Some("write G53 in a block with G0 or G1 and the axis words".into()),
            ));
        }
        // A feed motion code with no feed in force, in a block with no
        // axis words: "Cannot do g1 with zero feed rate" (a block with
        // axis words is `motion`'s to check).
        let feed_code = groups.iter().any(|(g, _)| matches!(g, GGroup::Feed(_)));
        let feed = has(&['F']) || (self.feed.is_some() && !feed_code);
        if let Some((Motion::Linear | Motion::Cw | Motion::Ccw, i)) = own
            && !feed
            && !has(&['X', 'Y', 'Z', 'A', 'B', 'C'])
        {
            out.push((
                Rule::NoFeedRate,
                b.words[i].span,
                format!(
                    "`{}` with no feed (F) in force: the controller refuses it (a G93, G94 or G95 forgets F)",
                    b.words[i].text(line)
                ),
                Some("give F in this block".into()),
            ));
        }
        let users = Users { motion, g, m };
        for w in &b.words {
            let (used, by) = users.uses(w.letter);
            if !used {
                out.push((
                    Rule::UnusedWord,
                    w.span,
                    format!(
                        "`{}`: no code of this block uses {} word (the controller refuses it)",
                        w.text(line),
                        a_word(w.letter)
                    ),
                    Some(format!(
                        "{} word goes with {by}; take it out or add the code meant",
                        a_word(w.letter)
                    )),
                ));
            }
        }
    }
}

impl State {
    /// Fanuc, Sinumerik and Heidenhain ISO: a parameter word that no code
    /// of its block uses (the uses lensc reads; a word of a code it does
    /// not read is refused with its code, as unknown). I, J and K are an
    /// arc's centre (G2, G3: the block's own code, or the mode in force
    /// for a block with axis words); on a Heidenhain ISO block with no
    /// motion and no axis words they set the circle centre. Fanuc: R is an
    /// arc's radius, P the dwell of G4, Q the mode of G05.1, H the length
    /// offset of G43, D the radius offset of G41 and G42; L goes with M98
    /// and G10, which lensc does not read. Sinumerik: P is a subprogram's
    /// passes, with L (an arc's turns are `TURN=`).
    pub(super) fn parameter_words(
        &self,
        b: &Block,
        groups: &[(GGroup, usize)],
        line: &str,
        out: &mut Vec<Found>,
    ) {
        let c = self.lex.controller;
        if !matches!(
            c,
            Controller::Fanuc | Controller::Siemens | Controller::HeidenhainIso
        ) {
            return;
        }
        let has = |letters: &[char]| b.words.iter().any(|w| letters.contains(&w.letter));
        let g = |code: i64| {
            b.words
                .iter()
                .any(|w| w.letter == 'G' && self.g_code(w.value) == Some(code))
        };
        let own = groups.iter().find_map(|(g, _)| match g {
            GGroup::Motion(m) => Some(*m),
            _ => None,
        });
        // A NURBS block (G06.2 and the blocks of its curve) carries its
        // own P (rank), K (knots) and R (weights): the NURBS reader holds
        // them to the control's rules (E0340).
        if own == Some(Motion::Nurbs) || self.motion == Some(Motion::Nurbs) {
            return;
        }
        let axes = has(&['X', 'Y', 'Z', 'A', 'B', 'C', 'U', 'W']);
        let motion = own.or(if axes { self.motion } else { None });
        let arc = matches!(motion, Some(Motion::Cw | Motion::Ccw));
        // A Heidenhain ISO block of I J K alone sets the circle centre.
        let centre_alone = c == Controller::HeidenhainIso && motion.is_none() && !axes;
        for w in &b.words {
            let (used, by) = match (c, w.letter) {
                (_, 'I' | 'J' | 'K') => (arc || centre_alone, "G2 or G3 (an arc's centre)"),
                (Controller::Fanuc, 'R') => (arc, "G2 or G3 (an arc's radius)"),
                (Controller::Fanuc, 'P') => (g(40), "G4 (the dwell)"),
                (Controller::Fanuc, 'Q') => (g(51), "G05.1 (AI contour control)"),
                (Controller::Fanuc, 'H') => (g(430) || g(440), "G43 or G44 (the length offset)"),
                (Controller::Fanuc, 'D') => (g(410) || g(420), "G41 or G42 (the radius offset)"),
                (Controller::Fanuc, 'L') => (false, "M98 or G10, which lensc does not read"),
                (Controller::Siemens, 'P') => (
                    has(&['L']),
                    "L (a subprogram's passes; an arc's turns are TURN=)",
                ),
                _ => (true, ""),
            };
            if !used {
                out.push((
                    Rule::UnusedWord,
                    w.span,
                    format!(
                        "`{}`: no code of this block uses {} word (the controller refuses it)",
                        w.text(line),
                        a_word(w.letter)
                    ),
                    Some(format!(
                        "{} word goes with {by}; take it out or add the code meant",
                        a_word(w.letter)
                    )),
                ));
            }
        }
    }
}

/// "an R", "a P": the letter with its article, as it is spoken.
fn a_word(letter: char) -> String {
    let article = if "AEFHILMNORSX".contains(letter) {
        "an"
    } else {
        "a"
    };
    format!("{article} {letter}")
}
