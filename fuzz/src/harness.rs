//! One input through the compiler as `lensc check` and `lensc build` take
//! it — check, render, lower, plan and emit, write — with the fuzzer's
//! invariant checked at each step: every diagnostic has a code and a
//! span inside its file. Panics are not caught here (`supervise` does).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lensc_build::driver;
use lensc_build::job::Limits;
use lensc_grammar::Diagnostic;
use lensc_lang::loader::{FileSystem, Root};
use lensc_lang::sandbox::ReadError;
use lensc_lang::source::SourceMap;

/// One in this many inputs is formatted twice (`formats`) and one in
/// this many parsed by pest alone too (`parses_alike`), counted per worker.
const FORMAT_EVERY: u64 = 4;
const PEST_EVERY: u64 = 8;

thread_local! {
    /// Inputs this worker has run.
    static CROSS_CHECKS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How far an input went.
#[derive(Clone, Copy, Debug, Default)]
pub struct Reached {
    /// It checked with no error.
    pub clean: bool,
    /// Jobs lowered to typed jobs (or rejected with coded diagnostics).
    pub lowered: usize,
    /// Jobs built (planned, emitted, simulated) and their files written.
    pub built: usize,
    pub written: usize,
    /// Jobs whose files could not be written: the machine's fault (a full
    /// disk), not the compiler's; counted, not failed.
    pub unwritten: usize,
    /// Where the input's time went, by phase (`PHASES`).
    pub times: Phases,
}

/// The phases of one `.lens` input whose time is counted: `check_text`;
/// the invariant and both renderers over its diagnostics; the fuzzer's own
/// cross-checks (fmt, pest); lowering as `lensc check` does; planning and
/// emitting; writing the files.
pub const PHASES: [&str; 6] = ["check", "render", "cross-check", "lower", "build", "write"];

/// Time spent in each of `PHASES`.
pub type Phases = [std::time::Duration; PHASES.len()];

/// Runs `f`, adding its time to phase `i` of `times`.
fn timed<T>(times: &mut Phases, i: usize, f: impl FnOnce() -> T) -> T {
    let t = std::time::Instant::now();
    let out = f();
    times[i] += t.elapsed();
    out
}

/// What is wrong with an input's handling, beyond a panic.
pub type Fault = String;

/// An in-memory file system for `use "…"`: a few named files (the
/// bad-input corpus's imports and a small part library); every other path
/// is missing. The fuzzer never reads the disk on an input's behalf.
pub struct MemFs {
    files: HashMap<String, Vec<u8>>,
}

impl MemFs {
    pub fn new(extra: &[(String, Vec<u8>)]) -> MemFs {
        let mut files: HashMap<String, Vec<u8>> = extra.iter().cloned().collect();
        files.insert(
            "part.lens".into(),
            b"surface part_surface = sphere { radius: 20 mm, sense: convex, aperture: circle(radius: 1 mm) }\nlet part_pitch = 0.5 mm\n".to_vec(),
        );
        files.insert("self.lens".into(), b"use \"self.lens\"\n".to_vec());
        MemFs { files }
    }

    /// Every named file, as the end-to-end share writes them to disk.
    pub fn files(&self) -> impl Iterator<Item = (&String, &Vec<u8>)> {
        self.files.iter()
    }
}

impl FileSystem for MemFs {
    /// Named files are read; a few names stand for what the sandbox
    /// refuses (a directory, a file too large, one outside the root).
    fn read(&self, _root: &Root, path: &Path) -> Result<Vec<u8>, ReadError> {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let name = name.unwrap_or_default();
        if let Some(text) = self.files.get(&name) {
            return Ok(text.clone());
        }
        Err(match name.as_str() {
            "dir" => ReadError::NotAFile {
                what: "a directory",
            },
            "big.lens" => ReadError::TooLarge {
                bytes: 1 << 30,
                limit: 16 << 20,
            },
            "up.lens" => ReadError::OutsideRoot {
                resolved: PathBuf::from("/elsewhere/up.lens"),
                root: PathBuf::from("/project"),
            },
            _ => ReadError::Io(std::io::Error::from(std::io::ErrorKind::NotFound)),
        })
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        path.to_path_buf()
    }
}

/// What to do with an input beyond checking it.
#[derive(Clone, Copy, Debug)]
pub enum Depth {
    /// Check and render.
    Check,
    /// Also, as `lensc check` does for a clean file, look for surfaces
    /// undefined over their aperture and lower every job.
    Lower,
    /// `Lower`, every job held to these size limits.
    LowerWithin(Limits),
    /// Also build every job of a clean file and write its files.
    Build,
    /// Build as `Build`, in this dialect instead of each machine's own
    /// (`--dialect`), to this largest program (`--max-program-size`), and
    /// a part that misses its acceptance criteria written all the same if
    /// `accept_warn` (`--accept warn`).
    BuildAs {
        dialect: Option<&'static str>,
        max_program_size: Option<u64>,
        accept_warn: bool,
    },
    /// Not a `.lens` file: a program for `lensc verify` (the number picks
    /// the machine and dialect it is read by if its header names none).
    Verify(usize),
    /// Not a `.lens` file: a prescription for `lensc import` (`.json` if
    /// true, else `.zmx`).
    Import { json: bool },
    /// Not a `.lens` file: a session of messages for `lensc lsp`.
    Lsp,
    /// Not a `.lens` file: a measurement file named `fuzz.EXT`, read as
    /// `lensc measure` reads it.
    Measure { ext: &'static str },
}

impl Depth {
    /// The input is a `.lens` file (checked, and lowered or built).
    pub fn is_lens(self) -> bool {
        matches!(
            self,
            Depth::Check
                | Depth::Lower
                | Depth::LowerWithin(_)
                | Depth::Build
                | Depth::BuildAs { .. }
        )
    }
}

/// Runs `bytes` as far as `depth` asks (and the checker lets it).
pub fn run(fs: &MemFs, bytes: &[u8], depth: Depth, out_dir: &Path) -> Result<Reached, Fault> {
    let mut times = Phases::default();
    let c = timed(&mut times, 0, || driver::check_text(fs, "fuzz.lens", bytes));
    let sources = &c.loaded.sources;
    timed(&mut times, 1, || {
        well_formed(c.diags(), sources)?;
        render(c.diags(), sources)
    })?;
    // The fuzzer's own cross-checks beyond what `lensc check` runs (pest
    // alone costs about as much as the checker): on a share of the inputs,
    // and always on a worker's first (so a replayed input has them all).
    let n = CROSS_CHECKS.with(|c| c.replace(c.get() + 1));
    timed(&mut times, 2, || {
        if n.is_multiple_of(FORMAT_EVERY) {
            formats(bytes)?;
        }
        if n.is_multiple_of(PEST_EVERY) {
            parses_alike(bytes)?;
        }
        Ok::<(), Fault>(())
    })?;
    let mut reached = Reached {
        clean: !c.has_errors(),
        ..Reached::default()
    };
    if !reached.clean {
        reached.times = times;
        return Ok(reached);
    }
    match depth {
        // Not `.lens` inputs: `targets::run` takes them before they come here.
        Depth::Check
        | Depth::Verify(_)
        | Depth::Import { .. }
        | Depth::Lsp
        | Depth::Measure { .. } => {}
        Depth::Lower | Depth::LowerWithin(_) => {
            let limits = match depth {
                Depth::LowerWithin(l) => l,
                _ => Limits::default(),
            };
            // What `lensc check` runs once a file checks: surfaces
            // undefined over their aperture, every job lowered.
            let found = timed(&mut times, 3, || {
                lensc_build::pipeline::findings_before_planning(&c, &limits)
            });
            timed(&mut times, 1, || {
                well_formed(&found, sources)?;
                render(&found, sources)
            })?;
            reached.lowered += c.checked.jobs.len();
        }
        Depth::Build | Depth::BuildAs { .. } => {
            let request = match depth {
                Depth::BuildAs {
                    dialect,
                    max_program_size,
                    accept_warn,
                } => driver::Request {
                    dialect,
                    max_program_size,
                    accept: if accept_warn {
                        lensc_build::accept::Mode::Warn
                    } else {
                        lensc_build::accept::Mode::Gate
                    },
                    ..driver::Request::default()
                },
                _ => driver::Request::default(),
            };
            let (built, diags) = timed(&mut times, 4, || {
                driver::plan_and_emit(&c, request, "fuzz.lens", Some(out_dir))
            });
            timed(&mut times, 1, || {
                well_formed(&diags, sources)?;
                render(&diags, sources)
            })?;
            reached.lowered = c.checked.jobs.len();
            reached.built = built.len();
            timed(&mut times, 5, || {
                for b in built {
                    match write(b, out_dir) {
                        Ok(()) => reached.written += 1,
                        Err(_) => reached.unwritten += 1,
                    }
                }
                clear(out_dir);
            });
        }
    }
    reached.times = times;
    Ok(reached)
}

/// `lensc fmt`'s invariant: a file that parses is formatted (to the same
/// tree: `format_source` refuses otherwise, with E0185), and formatting
/// the result again changes nothing.
fn formats(bytes: &[u8]) -> Result<(), Fault> {
    use lensc_lang::format::format_source;
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Ok(());
    };
    let once = match format_source(text) {
        Ok(once) => once,
        Err(d)
            if d.iter()
                .any(|d| d.code == lensc_lang::codes::FORMAT_WOULD_CHANGE_MEANING) =>
        {
            return Err("lensc fmt would change what this file means (E0185)".into());
        }
        Err(_) => return Ok(()),
    };
    match format_source(&once) {
        Ok(twice) if twice == once => Ok(()),
        Ok(_) => Err("lensc fmt of its own output changed it again".into()),
        Err(_) => Err("lensc fmt's output does not format".into()),
    }
}

/// The parser's fast path (`lensc_grammar`'s hand-written descent) and
/// pest alone give the same tree and the same diagnostics.
fn parses_alike(bytes: &[u8]) -> Result<(), Fault> {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Ok(());
    };
    let id = lensc_grammar::FileId(0);
    if lensc_grammar::parse(text, id) == lensc_grammar::parse_reference(text, id) {
        Ok(())
    } else {
        Err("the parser's fast path and pest disagree".into())
    }
}

/// The invariant: every diagnostic has a code and a primary span lying in
/// its file, on character boundaries.
pub fn well_formed(diags: &[Diagnostic], sources: &SourceMap) -> Result<(), Fault> {
    let files = sources.iter().count();
    for d in diags {
        let what = || format!("{} {:?}: {}", d.code, d.severity, d.message);
        if d.code.is_empty() {
            return Err(format!("uncoded diagnostic: {}", what()));
        }
        if d.message.is_empty() {
            return Err(format!("diagnostic without a message: {}", what()));
        }
        if d.labels.is_empty() {
            return Err(format!("diagnostic without a span: {}", what()));
        }
        for l in &d.labels {
            if l.file.0 as usize >= files {
                return Err(format!("span in no loaded file: {}", what()));
            }
            let text = &sources.get(l.file).text;
            let (s, e) = (l.span.start as usize, l.span.end as usize);
            if s > e || e > text.len() || !text.is_char_boundary(s) || !text.is_char_boundary(e) {
                return Err(format!(
                    "span {s}..{e} outside its file of {} bytes: {}",
                    text.len(),
                    what()
                ));
            }
        }
    }
    Ok(())
}

/// Both renderers take every diagnostic.
pub fn render(diags: &[Diagnostic], sources: &SourceMap) -> Result<(), Fault> {
    if diags.is_empty() {
        return Ok(());
    }
    let mut sink = Vec::new();
    lensc::render::human(diags, sources, false, &mut sink)
        .and_then(|()| lensc::render::json_lines(diags, sources, &mut sink))
        .map_err(|e| format!("rendering failed: {e}"))
}

/// Writes a built job's files as `lensc build` does: report, the files
/// beside the program, the program.
fn write(b: driver::Built, dir: &Path) -> std::io::Result<()> {
    driver::write_atomic(&dir.join(&b.report_name), &b.report.to_json_text())?;
    for (name, text) in b.beside {
        text.write_to(&dir.join(name))?;
    }
    b.program.write_to(&dir.join(&b.program_name))
}

/// Empties the output directory between builds.
fn clear(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_grammar::{FileId, Span};

    fn sources() -> SourceMap {
        driver::check_text(&MemFs::new(&[]), "t.lens", b"let a = 1 mm\n")
            .loaded
            .sources
    }

    #[test]
    fn a_diagnostic_without_a_code_or_outside_its_file_is_a_fault() {
        let s = sources();
        let ok = Diagnostic::error("E0001", "fine", FileId(0), Span { start: 0, end: 3 });
        assert!(well_formed(std::slice::from_ref(&ok), &s).is_ok());
        let uncoded = Diagnostic::error("", "no code", FileId(0), Span { start: 0, end: 3 });
        assert!(well_formed(&[uncoded], &s).is_err());
        let outside = Diagnostic::error(
            "E0001",
            "past the end",
            FileId(0),
            Span { start: 0, end: 99 },
        );
        assert!(well_formed(&[outside], &s).is_err());
        let mut unspanned = ok.clone();
        unspanned.labels.clear();
        assert!(well_formed(&[unspanned], &s).is_err());
    }

    #[test]
    fn a_small_job_is_checked_built_and_written() {
        let dir = tempfile::tempdir().expect("temp dir");
        let text = b"surface s = sphere { radius: 20 mm, sense: convex, aperture: circle(radius: 0.2 mm) }\n\
            use std::machines::linuxcnc_lathe\n\
            tool t = round_nose { nose_radius: 0.5 mm, clearance: 7 deg }\n\
            strategy st = profile_turning { feed: 20 um/rev, spindle_speed: 1000 rpm, chord_tolerance: 1 um }\n\
            job j { surface: s, tool: t, machine: linuxcnc_lathe, strategy: st }\n";
        let r = run(&MemFs::new(&[]), text, Depth::Build, dir.path()).expect("no fault");
        assert!(r.clean);
        assert_eq!((r.built, r.written), (1, 1));
        assert_eq!(
            std::fs::read_dir(dir.path()).expect("dir").count(),
            0,
            "the directory is emptied"
        );
    }
}
