//! What a built job is before it reaches the disk (`Built`, the program's
//! text in memory or spooled) and how every output file is put in place:
//! atomically (a job's program, report and tables as one unit:
//! `put_in_place`), with the user's usual mode, with no temporary file
//! left on failure,
//! and never in place of a symbolic link (`--out` itself may be one: the
//! user chose it; a link planted at an output's name is refused, not
//! followed or replaced).

use std::path::Path;

use lensc_grammar::Diagnostic;

/// Where a build puts the programs it formats.
#[derive(Clone, Copy, Debug)]
pub enum Destination<'a> {
    /// In memory (small jobs, tests).
    Memory,
    /// Spooled to a temporary file in this directory (the output
    /// directory) as it is written, so memory stays flat.
    Spool(&'a Path),
    /// Nowhere: the jobs are planned and simulated and no program is
    /// formatted (`lensc report`); each comes back empty.
    Nowhere,
}

/// One job's output, not yet written.
pub struct Built {
    /// File name of the program (`JOB.ngc`); the report is `JOB.report.json`.
    pub program_name: String,
    pub report_name: String,
    pub program: ProgramText,
    /// Points of the cut and its estimated time (s), for the summary line.
    pub cut_points: usize,
    pub cutting_time: f64,
    /// The build report (its fields are documented in
    /// docs/report.schema.json, generated from `crate::report`).
    pub report: crate::report::Report,
    /// Files the program reads, written beside it (a fast-tool-servo
    /// table): name and text.
    pub beside: Vec<(String, ProgramText)>,
    /// The series behind the plots of `lensc report`.
    pub plots: crate::plots::PlotSeries,
    /// Warnings the build found (the job still built).
    pub warnings: Vec<Diagnostic>,
    /// The dialect and machine its program was read back by, when it was
    /// (`lensc view` reads its moves by the same).
    pub read_back: Option<crate::reading::ReadBack>,
    /// The reader's findings in an in-memory program, where the build
    /// read its text once for the simulation and the read-back both
    /// (`context::read_program`): the read-back takes them instead of
    /// reading the text again.
    pub read_findings: Option<Vec<lensc_runtime::reader::Finding>>,
}

/// A program's text: in memory, or spooled as it was written to a
/// temporary file in the output directory (the programs of fast-tool-servo
/// jobs run to millions of lines).
pub enum ProgramText {
    Memory(String),
    Spooled {
        file: crate::temps::TempFile,
        lines: usize,
        bytes: u64,
        /// The reader reading the text as it was spooled, if it was
        /// (its findings are taken by the read-back).
        read: Option<crate::read_along::ReadAlong>,
    },
}

impl ProgramText {
    pub fn lines(&self) -> usize {
        match self {
            ProgramText::Memory(t) => t.lines().count(),
            ProgramText::Spooled { lines, .. } => *lines,
        }
    }
    pub fn bytes(&self) -> u64 {
        match self {
            ProgramText::Memory(t) => t.len() as u64,
            ProgramText::Spooled { bytes, .. } => *bytes,
        }
    }
    /// The whole text (read back from the spool file if need be).
    pub fn text(&self) -> std::io::Result<String> {
        match self {
            ProgramText::Memory(t) => Ok(t.clone()),
            ProgramText::Spooled { file, .. } => std::fs::read_to_string(file.path()),
        }
    }
    /// The text in a temporary file in `dir`, flushed to disk, ready to be
    /// put in place with the rest of its unit (`put_in_place`): a spooled
    /// program is already one (it was spooled into `dir`).
    pub fn into_temp(self, dir: &Path) -> std::io::Result<crate::temps::TempFile> {
        let file = match self {
            ProgramText::Memory(t) => text_temp(dir, &t)?,
            ProgramText::Spooled { file, .. } => file,
        };
        file.as_file().sync_all()?;
        Ok(file)
    }

    /// Puts the program at `path` atomically (a spooled program is renamed
    /// into place: it was written in the same directory).
    pub fn write_to(self, path: &Path) -> std::io::Result<()> {
        match self {
            ProgramText::Memory(t) => write_atomic(path, &t),
            ProgramText::Spooled { file, .. } => {
                not_a_link(path)?;
                file.as_file().sync_all()?;
                file.persist(path)
            }
        }
    }
}

/// Where the output `name` goes in `dir`: refused unless `name` is one plain
/// file name (a dialect's table extension comes from the job file, and
/// must not carry the file out of `--out`).
pub fn output_path(dir: &Path, name: &str) -> std::io::Result<std::path::PathBuf> {
    let mut parts = Path::new(name).components();
    match (parts.next(), parts.next()) {
        (Some(std::path::Component::Normal(n)), None) if n == name => Ok(dir.join(name)),
        _ => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("`{name}` is not a plain file name: outputs are written only inside --out"),
        )),
    }
}

/// Refuses a target that is a symbolic link: the rename would replace the
/// link, not write where it points, but a link there means someone expects
/// the output elsewhere — it is theirs to remove.
fn not_a_link(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "it is a symbolic link (lensc writes no output through or over one; remove it)",
        )),
        _ => Ok(()),
    }
}

/// `text` in a new temporary file in `dir` (created if need be).
pub fn text_temp(dir: &Path, text: &str) -> std::io::Result<crate::temps::TempFile> {
    use std::io::Write;
    std::fs::create_dir_all(dir)?;
    let mut tmp = crate::temps::TempFile::create_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    tmp.as_file().sync_all()?;
    Ok(tmp)
}

/// Puts a job's files in place as one unit (`temps::persist_all`): each
/// is already whole in a temporary file beside its target; nothing is
/// renamed unless every target can be replaced, and a signal waits for
/// the whole unit. The order is the order given (the program last, so a
/// program on disk always has its report and tables beside it).
pub fn put_in_place(
    files: Vec<(crate::temps::TempFile, std::path::PathBuf)>,
) -> std::io::Result<()> {
    crate::temps::persist_all(files)
}

/// Writes `text` to `path` atomically: a temporary file in the same
/// directory, flushed, then renamed over the target. On failure the
/// target is untouched and no temporary file is left behind.
/// Temporary files are created with the mode the user's files get (0666
/// less the umask: 0644 under the usual 022), so a program and its report
/// are put in place as any other file the user writes, and can be copied
/// to the controller's share.
pub fn write_atomic(path: &Path, text: &str) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    not_a_link(path)?;
    let mut tmp = crate::temps::TempFile::create_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_stay_inside_the_output_directory() {
        let dir = Path::new("out");
        assert_eq!(output_path(dir, "job.ngc").unwrap(), dir.join("job.ngc"));
        for bad in ["job./../../x", "/etc/x", "..", "a/b", "", "job.ngc/"] {
            assert!(output_path(dir, bad).is_err(), "{bad}");
        }
    }
}
