//! The build's temporary files: every `.lensc-<pid>-<random>.tmp` this
//! process has open in an output directory (spooled programs, files on
//! their way to an atomic rename) is in one registry, so an interrupted
//! build can remove them all before it exits; and the sweep that removes,
//! at the start of a build, those left behind by a lensc that is no longer
//! running (the owner's pid is in the name).
//!
//! The registry's lock is held while a temporary file is created, renamed
//! into place or deleted, and by [`remove_all_and_hold`] until the process
//! exits: a file is never created or renamed behind the back of the clean-up.

use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// What every temporary file's name starts and ends with.
const PREFIX: &str = ".lensc-";
const SUFFIX: &str = ".tmp";

/// Paths of this process's live temporary files.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The registry, even if a thread panicked while holding it (the list of
/// paths is still right: every change to it is one push or one removal).
fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A temporary file of this build in an output directory, registered while
/// it exists: renamed into place by [`TempFile::persist`], deleted (and
/// unregistered) when dropped.
pub struct TempFile {
    /// `None` only once persisted or dropped.
    file: Option<tempfile::NamedTempFile>,
}

impl TempFile {
    /// Creates `.lensc-<pid>-<random>.tmp` in `dir`, with the mode a file
    /// the user creates gets (0666 less the umask, as the kernel applies
    /// it when the file is created), since it becomes an output file.
    pub fn create_in(dir: &Path) -> io::Result<TempFile> {
        let mut live = live();
        let prefix = format!("{PREFIX}{}-", std::process::id());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(SUFFIX);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let file = builder.tempfile_in(dir)?;
        live.push(file.path().to_path_buf());
        Ok(TempFile { file: Some(file) })
    }

    fn inner(&self) -> &tempfile::NamedTempFile {
        self.file.as_ref().expect("a temporary file in use")
    }

    pub fn path(&self) -> &Path {
        self.inner().path()
    }

    pub fn as_file(&self) -> &std::fs::File {
        self.inner().as_file()
    }

    /// Renames the file to `target` (in the same directory) and forgets it.
    pub fn persist(mut self, target: &Path) -> io::Result<()> {
        let file = self.file.take().expect("a temporary file in use");
        let mut live = live();
        let path = file.path().to_path_buf();
        match file.persist(target) {
            Ok(_) => {
                forget(&mut live, &path);
                Ok(())
            }
            Err(e) => {
                // Dropped (so deleted) with the lock still held.
                drop(e.file);
                forget(&mut live, &path);
                Err(e.error)
            }
        }
    }
}

/// What a commit's journal is called: `.lensc-<pid>-commit.tmp`.
fn journal_name(pid: u32) -> String {
    format!("{PREFIX}{pid}-commit{SUFFIX}")
}

/// Puts temporary files in place as one unit (a program, its report and
/// the files beside it, all in one directory): every target is checked
/// first, then, with the registry locked (so SIGINT or SIGTERM, whose
/// clean-up takes the lock, waits until the unit is in place), a journal
/// naming each temporary file and its target is written and flushed, the
/// files are renamed in order, and the journal removed. A process killed
/// outright between two renames leaves the journal: the next build's
/// sweep (`remove_stale`) finishes the renames it names before anything
/// else, so the directory holds the previous files or the new ones,
/// never a mix once a build has started there.
pub fn persist_all(files: Vec<(TempFile, PathBuf)>) -> io::Result<()> {
    let Some(dir) = files.first().map(|(t, _)| {
        t.path()
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf()
    }) else {
        return Ok(());
    };
    for (t, target) in &files {
        let parent = |p: &Path| {
            let d = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            std::fs::canonicalize(d).unwrap_or_else(|_| d.to_path_buf())
        };
        if parent(target) != parent(t.path()) {
            return Err(io::Error::other("a unit's files must share one directory"));
        }
        if let Ok(m) = std::fs::symlink_metadata(target) {
            if m.file_type().is_symlink() {
                return Err(io::Error::new(
                    io::ErrorKind::AlreadyExists,
                    format!(
                        "{} is a symbolic link (lensc writes no output through or over one; remove it)",
                        target.display()
                    ),
                ));
            }
            if m.is_dir() {
                return Err(io::Error::new(
                    io::ErrorKind::AlreadyExists,
                    format!("{} is a directory", target.display()),
                ));
            }
        }
    }
    let mut live = live();
    let name = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let journal = dir.join(journal_name(std::process::id()));
    let mut text = String::new();
    for (t, target) in &files {
        text.push_str(&format!("{}\t{}\n", name(t.path()), name(target)));
    }
    {
        let mut j = std::fs::File::create(&journal)?;
        j.write_all(text.as_bytes())?;
        j.sync_all()?;
    }
    sync_dir(&dir);
    let mut result = Ok(());
    for (step, (mut t, target)) in files.into_iter().enumerate() {
        stop_for_a_test(step);
        let file = t.file.take().expect("a temporary file in use");
        let path = file.path().to_path_buf();
        if result.is_err() {
            drop(file);
        } else if let Err(e) = file.persist(&target) {
            drop(e.file);
            result = Err(e.error);
        }
        forget(&mut live, &path);
    }
    stop_for_a_test(usize::MAX);
    sync_dir(&dir);
    let _ = std::fs::remove_file(&journal);
    result
}

/// The tests' way to stop a commit part-way: with
/// `LENSC_TEST_STOP_COMMIT=STEP:SIGNAL` (`SIGNAL` being `TERM`, `INT` or
/// `KILL`), the process sends itself that signal just before its commit's
/// rename number `STEP` (from 0), or with `STEP` `end` after the last
/// rename, before the journal is removed. Unset, as in every real build,
/// it does nothing. (A signal from outside cannot be aimed between two
/// renames a few microseconds apart; `tests/it/interrupt.rs` aims this
/// one at every step.)
fn stop_for_a_test(step: usize) {
    let Some(spec) = std::env::var_os("LENSC_TEST_STOP_COMMIT") else {
        return;
    };
    let spec = spec.to_string_lossy();
    let Some((at, signal)) = spec.split_once(':') else {
        return;
    };
    let at = if at == "end" {
        usize::MAX
    } else {
        match at.parse() {
            Ok(n) => n,
            Err(_) => return,
        }
    };
    if at != step {
        return;
    }
    #[cfg(unix)]
    {
        let signal = match signal {
            "TERM" => libc::SIGTERM,
            "INT" => libc::SIGINT,
            "KILL" => libc::SIGKILL,
            _ => return,
        };
        // SAFETY: kill(2) on this process's own pid; no memory is touched.
        unsafe {
            libc::kill(libc::getpid(), signal);
        }
    }
    #[cfg(not(unix))]
    let _ = signal;
}

/// Flushes a directory's entries (the renames in it), where that can be
/// asked.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Finishes the commit a journal left by a process that is no longer
/// running names: each temporary file still there renamed to its target
/// (both plain names in `dir`), then the journal removed.
fn roll_forward(dir: &Path, journal: &Path) {
    let Ok(text) = std::fs::read_to_string(journal) else {
        return;
    };
    let plain = |n: &str| !n.is_empty() && !n.contains('/') && n != "." && n != "..";
    let pairs: Vec<(&str, &str)> = text.lines().filter_map(|l| l.split_once('\t')).collect();
    // A journal cut short (the process killed while writing it) commits
    // nothing: its temporary files are swept.
    if !text.ends_with('\n')
        || pairs
            .iter()
            .any(|(t, g)| !plain(t) || !plain(g) || owner(t).is_none())
    {
        let _ = std::fs::remove_file(journal);
        return;
    }
    for (tmp, target) in pairs {
        let from = dir.join(tmp);
        if std::fs::symlink_metadata(&from).is_ok_and(|m| m.is_file()) {
            let _ = std::fs::rename(&from, dir.join(target));
        }
    }
    sync_dir(dir);
    let _ = std::fs::remove_file(journal);
}

impl Write for TempFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        (&mut self.inner().as_file()).write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        (&mut self.inner().as_file()).flush()
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if let Some(file) = self.file.take() {
            let mut live = live();
            let path = file.path().to_path_buf();
            drop(file);
            forget(&mut live, &path);
        }
    }
}

fn forget(live: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = live.iter().position(|p| p == path) {
        live.swap_remove(i);
    }
}

/// Removes every live temporary file of this process and keeps the
/// registry locked until the returned guard is dropped: called on SIGINT
/// or SIGTERM just before the process exits, so no new one is made.
pub fn remove_all_and_hold() -> MutexGuard<'static, Vec<PathBuf>> {
    let mut live = live();
    for path in live.drain(..) {
        let _ = std::fs::remove_file(&path);
    }
    live
}

/// Removes the temporary files in `dir` whose owner (the pid in their name)
/// is no longer running; returns how many. Files of a live process, and
/// `.lensc-*.tmp` files without a pid (which name no owner), are kept.
/// A missing or unreadable `dir` has nothing to sweep.
pub fn remove_stale(dir: &Path) -> usize {
    // First the commits of lenscs that died mid-way, finished.
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let name = entry.file_name();
            let Some(name) = name.to_str() else { continue };
            if let Some(pid) = owner(name)
                && name == journal_name(pid)
                && !is_running(pid)
            {
                roll_forward(dir, &entry.path());
            }
        }
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(owner) else {
            continue;
        };
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && !is_running(pid) && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The owner's pid in a temporary file's name `.lensc-<pid>-<random>.tmp`.
fn owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(PREFIX)?.strip_suffix(SUFFIX)?;
    let (pid, random) = rest.split_once('-')?;
    if random.is_empty() || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// Whether a process `pid` exists (signal 0 is sent to nobody: only the
/// permission check runs). A process of another user answers EPERM: it is
/// running. Where this cannot be asked, every owner is taken as running.
fn is_running(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        if pid <= 0 {
            return true;
        }
        // SAFETY: kill with signal 0 sends nothing; it only reports
        // whether the process exists and may be signalled.
        let answer = unsafe { libc::kill(pid, 0) };
        answer == 0 || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owner_is_read_from_the_name() {
        assert_eq!(owner(".lensc-1234-aB3xZq.tmp"), Some(1234));
        assert_eq!(owner(".lensc-aB3xZq.tmp"), None);
        assert_eq!(owner(".lensc-12a-x.tmp"), None);
        assert_eq!(owner(".lensc-12-.tmp"), None);
        assert_eq!(owner("lensc-12-x.tmp"), None);
        assert_eq!(owner(".lensc-12-x.ngc"), None);
    }

    /// A unit put in place whole; and a commit a killed process left
    /// half done (its journal and one temporary file still there) finished
    /// by the next sweep, not swept away.
    #[test]
    fn a_unit_is_put_in_place_and_a_half_done_one_finished() {
        let dir = tempfile::tempdir().expect("tmp");
        let d = dir.path();
        let mut a = TempFile::create_in(d).expect("a");
        a.write_all(b"new report").expect("write");
        let mut b = TempFile::create_in(d).expect("b");
        b.write_all(b"new program").expect("write");
        std::fs::write(d.join("j.report.json"), "old report").expect("old");
        persist_all(vec![(a, d.join("j.report.json")), (b, d.join("j.ngc"))]).expect("persist");
        assert_eq!(
            std::fs::read_to_string(d.join("j.report.json")).expect("r"),
            "new report"
        );
        assert_eq!(
            std::fs::read_to_string(d.join("j.ngc")).expect("p"),
            "new program"
        );

        // Killed after the report's rename, before the program's.
        let dead = u32::try_from(i32::MAX).expect("pid");
        assert!(!is_running(dead));
        let tmp = format!(".lensc-{dead}-x1.tmp");
        std::fs::write(d.join(&tmp), "newer program").expect("tmp");
        std::fs::write(d.join("j.report.json"), "newer report").expect("renamed already");
        std::fs::write(
            d.join(journal_name(dead)),
            format!(".lensc-{dead}-x0.tmp\tj.report.json\n{tmp}\tj.ngc\n"),
        )
        .expect("journal");
        remove_stale(d);
        assert_eq!(
            std::fs::read_to_string(d.join("j.ngc")).expect("p"),
            "newer program"
        );
        let left: Vec<_> = std::fs::read_dir(d)
            .expect("dir")
            .map(|e| e.expect("e").file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(PREFIX))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }

    #[test]
    fn this_process_is_running() {
        assert!(is_running(std::process::id()));
    }

    #[test]
    fn a_file_is_registered_while_it_exists() {
        let dir = tempfile::tempdir().expect("tmp");
        let mut t = TempFile::create_in(dir.path()).expect("create");
        let path = t.path().to_path_buf();
        t.write_all(b"G0 X0\n").expect("write");
        assert!(live().contains(&path));
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        assert_eq!(owner(&name), Some(std::process::id()));
        t.persist(&dir.path().join("a.ngc")).expect("persist");
        assert!(!live().contains(&path));
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.ngc")).unwrap(),
            "G0 X0\n"
        );
        let t = TempFile::create_in(dir.path()).expect("create");
        let path = t.path().to_path_buf();
        drop(t);
        assert!(!path.exists() && !live().contains(&path));
    }
}
