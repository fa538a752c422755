//! A split program read as the control runs it: the main program's calls
//! of its parts followed, each part's text in place of its call, so the
//! reader reads the set as one program. Part `k`'s call and its file's
//! opening and closing lines are the dialect's (`PartCalls`, data); this
//! file shares no code with the writer's splitter (`post/split.rs`).

use crate::dialect::{Dialect, PartCalls};

/// Why a split set could not be read as one program.
#[derive(Clone, Debug, PartialEq)]
pub enum PartsError {
    /// Part `name` could not be read.
    Unreadable { name: String, why: String },
    /// Part `name` does not open or close with the dialect's lines.
    Frame { name: String, expected: String },
}

impl PartsError {
    pub fn message(&self) -> String {
        match self {
            PartsError::Unreadable { name, why } => {
                format!("the part `{name}` the main program calls could not be read: {why}")
            }
            PartsError::Frame { name, expected } => format!(
                "the part `{name}` does not open and close as the dialect's parts do (expected `{expected}`)"
            ),
        }
    }
}

/// Part `k` of the program `job` (the main program's file name without
/// its extension) in the dialect's words: its call, its file name, its
/// opening and closing lines.
struct Part {
    call: String,
    file: String,
    start: Vec<String>,
    end: Vec<String>,
}

fn fill(t: &str, job: &str, k: usize, p: &PartCalls, number: u32) -> String {
    let n = (number as usize + k).to_string();
    let name = p
        .name
        .replace("{job}", job)
        .replace("{JOB}", &job.to_uppercase())
        .replace("{k}", &k.to_string())
        .replace("{number}", &n);
    t.replace("{part}", &name)
        .replace("{PART}", &name.to_uppercase())
        .replace("{number}", &n)
        .replace("{k}", &k.to_string())
        .replace("{job}", job)
        .replace("{JOB}", &job.to_uppercase())
}

fn part(job: &str, k: usize, p: &PartCalls, number: u32) -> Part {
    let f = |t: &str| fill(t, job, k, p, number);
    Part {
        call: f(&p.call),
        file: format!("{}.{}", f("{part}"), p.extension),
        start: p.start.iter().map(|l| f(l)).collect(),
        end: p.end.iter().map(|l| f(l)).collect(),
    }
}

/// Whether `main` (the program `job` in `dialect`) calls its first part.
pub fn calls_parts(main: &str, dialect: &Dialect, job: &str) -> bool {
    let Some(p) = &dialect.parts else {
        return false;
    };
    let first = part(job, 1, p, dialect.program_number).call;
    main.lines().any(|l| l.trim() == first)
}

/// The file names of the parts `main` calls, in order.
pub fn part_files(main: &str, dialect: &Dialect, job: &str) -> Vec<String> {
    let Some(p) = &dialect.parts else {
        return Vec::new();
    };
    let mut k = 1;
    let mut out = Vec::new();
    for l in main.lines() {
        let next = part(job, k, p, dialect.program_number);
        if l.trim() == next.call {
            out.push(next.file);
            k += 1;
        }
    }
    out
}

/// `main` with each call of a part (`M198 P…`, `EXTCALL`, `O<…> call`)
/// replaced by that part's lines between its opening and closing lines;
/// `load` reads a part by its file name. A main program that calls no
/// parts comes back as it is.
pub fn assemble(
    main: &str,
    dialect: &Dialect,
    job: &str,
    load: &mut dyn FnMut(&str) -> Result<String, String>,
) -> Result<String, PartsError> {
    let Some(p) = &dialect.parts else {
        return Ok(main.to_string());
    };
    let mut out = String::with_capacity(main.len());
    let mut k = 1;
    for line in main.split_inclusive('\n') {
        let next = part(job, k, p, dialect.program_number);
        if line.trim() != next.call {
            out.push_str(line);
            continue;
        }
        let text = load(&next.file).map_err(|why| PartsError::Unreadable {
            name: next.file.clone(),
            why,
        })?;
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        let (s, e) = (next.start.len(), next.end.len());
        let framed = lines.len() >= s + e
            && lines[..s]
                .iter()
                .zip(&next.start)
                .all(|(a, b)| a.trim() == b)
            && lines[lines.len() - e..]
                .iter()
                .zip(&next.end)
                .all(|(a, b)| a.trim() == b);
        if !framed {
            return Err(PartsError::Frame {
                name: next.file,
                expected: next
                    .start
                    .iter()
                    .chain(&next.end)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(" … "),
            });
        }
        for l in &lines[s..lines.len() - e] {
            out.push_str(l);
        }
        k += 1;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fanuc() -> Dialect {
        Dialect {
            program_number: 4711,
            parts: Some(PartCalls {
                call: "M198 P{number}".into(),
                name: "O{number}".into(),
                extension: "nc".into(),
                start: vec!["%".into(), "O{number} ({PART})".into()],
                end: vec!["M99".into(), "%".into()],
                continuous: false,
            }),
            ..Dialect::linuxcnc()
        }
    }

    /// Written by hand as the Fast Data Server manual describes a main
    /// program calling its files: the parts' bodies in place of the calls.
    #[test]
    fn calls_are_followed_in_order() {
        let main = "%\nO4711 (J)\nG0 X1\nM198 P4712\nM198 P4713\nM30\n%\n";
        let mut files = std::collections::HashMap::new();
        files.insert("O4712.nc", "%\nO4712 (O4712)\nG1 X2\nM99\n%\n");
        files.insert("O4713.nc", "%\nO4713 (O4713)\nG1 X3\nM99\n%\n");
        let mut load = |n: &str| {
            files
                .get(n)
                .map(|t| t.to_string())
                .ok_or("absent".to_string())
        };
        let d = fanuc();
        assert!(calls_parts(main, &d, "j"));
        assert_eq!(part_files(main, &d, "j"), ["O4712.nc", "O4713.nc"]);
        assert_eq!(
            assemble(main, &d, "j", &mut load).expect("assembles"),
            "%\nO4711 (J)\nG0 X1\nG1 X2\nG1 X3\nM30\n%\n"
        );
    }

    #[test]
    fn a_missing_or_misframed_part_is_refused() {
        let main = "%\nO4711 (J)\nM198 P4712\nM30\n%\n";
        let d = fanuc();
        let mut none = |_: &str| Err("no such file".to_string());
        assert!(matches!(
            assemble(main, &d, "j", &mut none),
            Err(PartsError::Unreadable { .. })
        ));
        let mut bare = |_: &str| Ok("G1 X2\n".to_string());
        assert!(matches!(
            assemble(main, &d, "j", &mut bare),
            Err(PartsError::Frame { .. })
        ));
    }
}
