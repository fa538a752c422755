//! Which of the reader's rules are lensc's own safety policy rather than
//! the controller's: a program breaking one runs on the controller (LinuxCNC's
//! `rs274` runs it), and lensc refuses it on purpose. Each has a name a
//! user can look up and the reason it is held; every other rule is the
//! controller's own, and the controller refuses the program too.

use super::Rule;

/// Whose rule a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// The controller refuses the program (or the block) itself.
    Controller,
    /// The controller would run it; lensc refuses it on purpose.
    Policy,
}

impl Class {
    pub fn as_str(self) -> &'static str {
        match self {
            Class::Controller => "controller",
            Class::Policy => "policy",
        }
    }
}

/// A rule of lensc's policy: its name and why lensc holds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Policy {
    pub name: &'static str,
    pub reason: &'static str,
}

impl Rule {
    /// Whose rule this is.
    pub fn class(self) -> Class {
        if self.policy().is_some() {
            Class::Policy
        } else {
            Class::Controller
        }
    }

    /// The policy this rule is, if it is lensc's own.
    pub fn policy(self) -> Option<Policy> {
        let (name, reason) = match self {
            Rule::SpindleStopped => (
                "spindle-stopped-feed",
                "a feed move with the spindle stopped (and not held in position) cuts nothing or breaks the tool; the controller runs it",
            ),
            Rule::NoTool => (
                "no-tool-call",
                "a cut before a tool is called and changed runs with whatever tool and offset the spindle holds",
            ),
            Rule::OutsideTravel => (
                "over-travel",
                "a move outside the travel the machine file states: the controller knows only its own soft limits",
            ),
            Rule::FeedTooHigh => (
                "feed-over-limit",
                "a feed above the machine file's highest: the controller clamps it or runs it, either way not the feed planned",
            ),
            Rule::SpindleTooFast => (
                "spindle-over-limit",
                "a spindle speed (or C turned) above the machine file's highest",
            ),
            Rule::RapidIntoPart => (
                "rapid-into-material",
                "a rapid across or down into the material cut so far, including a plunge before the first cut: the controller runs it into the part",
            ),
            Rule::ModalStateUnstated => (
                "modal-state-unstated",
                "a move before units, distance mode or plane are stated: the controller uses whatever an earlier program left",
            ),
            Rule::NoFeedMode => (
                "feed-mode-unstated",
                "a feed move before G93/G94/G95 is stated: F would be read in the mode an earlier program left",
            ),
            Rule::SpindleSpeedMode => (
                "speed-mode-unstated",
                "a spindle start before G96/G97 is stated: a G96 left by an earlier program would read S as a surface speed",
            ),
            Rule::NoSpindleSpeed => (
                "spindle-speed-unstated",
                "a spindle start with no speed: the controller starts it at S0 or the last speed",
            ),
            Rule::NoSpeedCap => (
                "surface-speed-uncapped",
                "constant surface speed with no speed limit: at the centre the spindle runs to its maximum",
            ),
            Rule::FullCircle => (
                "full-circle",
                "an arc that ends where it starts: lensc never writes one, and a full circle where an arc of no length was meant cuts a ring",
            ),
            Rule::PositionUnknown => (
                "arc-from-unstated-point",
                "an arc from a point the program never stated: its centre and radius depend on where the tool stands",
            ),
            Rule::MainProgramLoop => (
                "main-program-loop",
                "M99 in a main program starts it again from its first block, for ever: the part is cut again and again until the operator stops the machine",
            ),
            Rule::BlockAfterEnd => (
                "blocks-after-end",
                "blocks after M2 or M30 are never run (the controller does not even read them): a stray end code loses the rest of the cut silently",
            ),
            Rule::NurbsNotCut => (
                "nurbs-not-cut",
                "a LinuxCNC NURBS block (G5.2) left without its G5.3 is never cut: the controller drops the curve at the next motion code and runs on, so a part of the cut is missing silently",
            ),
            Rule::NurbsWeight => (
                "nurbs-weight",
                "a control point of the first G5.2 block with no weight P (which LinuxCNC reads as −1) or one not above zero: the controller runs it, and the curve turns away from its points or divides by zero",
            ),
            _ => return None,
        };
        Some(Policy { name, reason })
    }
}
