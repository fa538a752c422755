//! What one input came to, as a lane reports it to the fuzzer's parent
//! process: one line of tab-separated fields on the worker's standard
//! output (`Record::line`, read back by `Record::parse`), so the parent
//! counts every input a worker finished even if the worker then dies.

use std::time::Duration;

use crate::harness::{PHASES, Phases, Reached};

/// Where an input came from.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum Source {
    Generated,
    Mutated,
    SmallJob,
    Program,
    Prescription,
    Session,
    Measurement,
}

const SOURCES: [Source; 7] = [
    Source::Generated,
    Source::Mutated,
    Source::SmallJob,
    Source::Program,
    Source::Prescription,
    Source::Session,
    Source::Measurement,
];

/// The strategies a small job's file may name (`strategy_of`).
pub const STRATEGIES: [&str; 7] = [
    "profile_turning",
    "profile_grinding",
    "raster",
    "spiral_turning",
    "fts_spiral",
    "roller_helix",
    "other",
];

/// What became of an input in the worker.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kind {
    /// Ran to its end, every diagnostic coded.
    Done,
    /// Ran to its end with a diagnostic that breaks the invariant.
    Uncoded,
    Panicked,
    Hung,
}

/// One input's outcome, as the parent counts it.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub index: u64,
    pub source: Source,
    /// The input was a build (a small job built and written).
    pub build: bool,
    /// The strategy a build's file uses (`STRATEGIES`).
    pub strategy: &'static str,
    pub kind: Kind,
    /// Wall time of the input in its worker (the end-to-end run aside).
    pub took: Duration,
    /// Time the fuzzer took to make the input.
    pub made: Duration,
    pub clean: bool,
    pub lowered: u64,
    pub built: u64,
    pub written: u64,
    pub unwritten: u64,
    pub times: Phases,
    /// Also run through the `lensc` binary: `Some(passed)`.
    pub end_to_end: Option<bool>,
    /// What failed (`uncoded`, `panic`, `hang`, `end-to-end`) and the message.
    pub failures: Vec<(String, String)>,
}

impl Record {
    /// A record of an input with nothing reached yet.
    pub fn new(index: u64, source: Source, build: bool, strategy: &'static str) -> Record {
        Record {
            index,
            source,
            build,
            strategy,
            kind: Kind::Done,
            took: Duration::ZERO,
            made: Duration::ZERO,
            clean: false,
            lowered: 0,
            built: 0,
            written: 0,
            unwritten: 0,
            times: Phases::default(),
            end_to_end: None,
            failures: Vec::new(),
        }
    }

    /// Takes in what the harness reached.
    pub fn reached(&mut self, r: &Reached) {
        self.clean = r.clean;
        self.lowered = r.lowered as u64;
        self.built = r.built as u64;
        self.written = r.written as u64;
        self.unwritten = r.unwritten as u64;
        self.times = r.times;
    }

    /// The record as one line (no newline in it).
    pub fn line(&self) -> String {
        let source = SOURCES.iter().position(|s| *s == self.source).unwrap_or(0);
        let kind = match self.kind {
            Kind::Done => 'd',
            Kind::Uncoded => 'u',
            Kind::Panicked => 'p',
            Kind::Hung => 'h',
        };
        let times: Vec<String> = self
            .times
            .iter()
            .map(|t| t.as_nanos().to_string())
            .collect();
        let e2e = match self.end_to_end {
            None => '-',
            Some(true) => 'y',
            Some(false) => 'n',
        };
        let mut out = format!(
            "rec\t{}\t{source}\t{}\t{}\t{kind}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{e2e}",
            self.index,
            u8::from(self.build),
            self.strategy,
            self.took.as_nanos(),
            self.made.as_nanos(),
            u8::from(self.clean),
            self.lowered,
            self.built,
            self.written,
            self.unwritten,
            times.join(","),
        );
        for (what, message) in &self.failures {
            out.push('\t');
            out.push_str(&escape(what));
            out.push('\t');
            out.push_str(&escape(message));
        }
        out
    }

    /// A line `line` wrote, or `None` if it is not one.
    pub fn parse(text: &str) -> Option<Record> {
        let f: Vec<&str> = text.split('\t').collect();
        if f.len() < 15 || f[0] != "rec" || !(f.len() - 15).is_multiple_of(2) {
            return None;
        }
        let n = |s: &str| s.parse::<u64>().ok();
        let mut times = Phases::default();
        let parts: Vec<&str> = f[13].split(',').collect();
        if parts.len() != PHASES.len() {
            return None;
        }
        for (t, p) in times.iter_mut().zip(parts) {
            *t = Duration::from_nanos(n(p)?);
        }
        Some(Record {
            index: n(f[1])?,
            source: *SOURCES.get(n(f[2])? as usize)?,
            build: f[3] == "1",
            strategy: STRATEGIES.into_iter().find(|s| *s == f[4])?,
            kind: match f[5] {
                "d" => Kind::Done,
                "u" => Kind::Uncoded,
                "p" => Kind::Panicked,
                "h" => Kind::Hung,
                _ => return None,
            },
            took: Duration::from_nanos(n(f[6])?),
            made: Duration::from_nanos(n(f[7])?),
            clean: f[8] == "1",
            lowered: n(f[9])?,
            built: n(f[10])?,
            written: n(f[11])?,
            unwritten: n(f[12])?,
            times,
            end_to_end: match f[14] {
                "-" => None,
                "y" => Some(true),
                "n" => Some(false),
                _ => return None,
            },
            failures: f[15..]
                .chunks(2)
                .map(|p| (unescape(p[0]), unescape(p[1])))
                .collect(),
        })
    }
}

/// `s` with backslashes, tabs, carriage returns and newlines escaped.
fn escape(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('\t', "\\t")
        .replace('\r', "\\r")
        .replace('\n', "\\n")
}

fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('t') => out.push('\t'),
            Some('r') => out.push('\r'),
            Some('n') => out.push('\n'),
            Some(other) => out.push(other),
            None => out.push('\\'),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_reads_back_as_written_messages_with_tabs_and_newlines_included() {
        let mut r = Record::new(123_456, Source::SmallJob, true, "raster");
        r.kind = Kind::Panicked;
        r.took = Duration::from_nanos(987_654_321);
        r.made = Duration::from_nanos(1_234);
        r.clean = true;
        r.lowered = 1;
        r.built = 1;
        r.written = 1;
        r.times[4] = Duration::from_nanos(42);
        r.end_to_end = Some(false);
        r.failures = vec![
            (
                "panic".into(),
                "index out of\tbounds\nat x.rs:1:2 \\ done".into(),
            ),
            ("end-to-end".into(), String::new()),
        ];
        let line = r.line();
        assert!(!line.contains('\n'), "{line}");
        assert_eq!(Record::parse(&line), Some(r));
        assert_eq!(Record::parse("fuzz: progress 30 s"), None);
        assert_eq!(Record::parse(&line[..line.len() / 2]), None);
    }
}
