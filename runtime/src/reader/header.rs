//! What a program's header comments say that the reader uses: the machine
//! and dialect it was written for (`(machine NAME: DIALECT lathe)`, or
//! `; machine …` where comments are semicolons), and which way is out of
//! the material.

/// The machine and dialect a header names, and the words after them
/// (`lathe`, `3-axis mill`, `fast-tool-servo lathe`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HeaderNames {
    pub machine: String,
    pub dialect: String,
    pub kind: String,
}

/// The names in the first `machine NAME: DIALECT …` comment of `text`, if
/// its header has one.
pub fn header_names(text: &str) -> Option<HeaderNames> {
    text.lines().take(200).find_map(|line| {
        let comment = comment_text(line)?;
        let rest = comment.trim().strip_prefix("machine ")?;
        let (machine, rest) = rest.split_once(": ")?;
        let mut words = rest.split_whitespace();
        let dialect = words.next()?.to_string();
        let kind = words.collect::<Vec<_>>().join(" ");
        Some(HeaderNames {
            machine: machine.trim().to_string(),
            dialect,
            kind,
        })
    })
}

/// The source file a header names (`source PATH fnv1a64 …`), if any.
pub fn header_source(text: &str) -> Option<String> {
    text.lines().take(200).find_map(|line| {
        let rest = comment_text(line)?.trim().strip_prefix("source ")?;
        rest.rsplit_once(" fnv1a64 ").map(|(p, _)| p.to_string())
    })
}

/// The source file a header names and the hash it carries (`source PATH
/// fnv1a64 HEX`), with the line it is on (from 1), if any.
pub fn header_source_hash(text: &str) -> Option<(String, u64, usize)> {
    text.lines().take(200).enumerate().find_map(|(i, line)| {
        let rest = comment_text(line)?.trim().strip_prefix("source ")?;
        let (path, hash) = rest.rsplit_once(" fnv1a64 ")?;
        let hash = u64::from_str_radix(hash.trim(), 16).ok()?;
        Some((path.to_string(), hash, i + 1))
    })
}

/// Where the program's control point lies from the tool's centre (mm
/// along X, Y, Z), as its header states it
/// (`control point tip at Y+0 Z-0.5 mm from the tool centre …`,
/// on its comment's first line: nothing before the offset folds); none if
/// the header states none (a program written before the control point
/// was stated is the tool centre's).
pub fn header_control_offset(text: &str) -> Option<[f64; 3]> {
    text.lines()
        .take(200)
        .find_map(|line| control_offset(comment_text(line)?))
}

/// The control point's offset from the tool's centre, if this header
/// comment states it (`control point tip at X+0 Y+0 Z-0.085 mm from the
/// tool centre …`).
pub(crate) fn control_offset(comment: &str) -> Option<[f64; 3]> {
    let rest = comment.trim().strip_prefix("control point ")?;
    let (_, rest) = rest.split_once(" at ")?;
    let (rest, _) = rest.split_once(" mm from the tool centre")?;
    let mut offset = [0.0f64; 3];
    for word in rest.split_whitespace() {
        let axis = "XYZ".find(word.get(..1)?)?;
        offset[axis] = word.get(1..)?.parse().ok()?;
    }
    offset.iter().all(|v| v.is_finite()).then_some(offset)
}

/// The text of a whole-line comment in any dialect: `(…)`, `; …`, a
/// numbered `N9 ; … *`, or Klartext's `9 ; …`.
pub fn comment_text(line: &str) -> Option<&str> {
    let t = line.trim();
    if let Some(inner) = t.strip_prefix('(') {
        return inner.strip_suffix(')');
    }
    let t = t.strip_prefix('N').unwrap_or(t);
    let t = t.trim_start_matches(|c: char| c.is_ascii_digit()).trim();
    let inner = t.strip_prefix(';')?;
    Some(inner.trim_end().trim_end_matches('*'))
}

/// The axis (0 X, 2 Z) whose positive direction leads out of the material,
/// if this header comment says so: `+Z out of the material` on lathes and
/// mills, X for a roller (`the radius of the nose centre about the roller
/// axis`).
pub(crate) fn away_axis(comment: &str) -> Option<usize> {
    if comment.contains("+Z out of the material") {
        Some(2)
    } else if comment.contains("about the roller axis") {
        Some(0)
    } else {
        None
    }
}
