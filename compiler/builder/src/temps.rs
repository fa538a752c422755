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
