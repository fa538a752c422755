//! Which files a job may read, and reading them safely: only regular files
//! (never a FIFO, device, socket or directory, so nothing can block or
//! stream forever), at most `MAX_FILE_BYTES` each (read with a bounded
//! reader), only one name each (no hard link), and only beneath the
//! project root: every file under the root is opened relative to the
//! root's directory handle (`Root`), component by component, so no
//! directory swapped for a symlink between the check and the open can
//! lead outside it. The errors are data (`ReadError`); the loader turns
//! them into coded diagnostics.

use std::io::Read;
use std::path::{Component, Path, PathBuf};

use crate::codes;

/// The largest file lensc reads on a job's behalf: 16 MiB. A job that needs
/// more text is split into files joined by `use`.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Why a file was not read.
#[derive(Debug)]
pub enum ReadError {
    /// The operating system's refusal (no such file, permission denied…).
    Io(std::io::Error),
    /// The path names something other than a regular file.
    NotAFile { what: &'static str },
    /// The file is larger than `limit` bytes (`bytes` is at least `limit + 1`).
    TooLarge { bytes: u64, limit: u64 },
    /// The file resolves (after symlinks) to `resolved`, outside `root`.
    OutsideRoot { resolved: PathBuf, root: PathBuf },
    /// A regular file under the root with `links` names (hard links): one
    /// of them may lie outside the root.
    HardLinked { links: u64 },
}

impl ReadError {
    /// The diagnostic code that reports this refusal.
    pub fn code(&self) -> &'static str {
        match self {
            ReadError::Io(_) => codes::CANNOT_READ,
            ReadError::NotAFile { .. } => codes::NOT_A_FILE,
            ReadError::TooLarge { .. } => codes::FILE_TOO_LARGE,
            ReadError::OutsideRoot { .. } => codes::OUTSIDE_ROOT,
            ReadError::HardLinked { .. } => codes::HARD_LINKED,
        }
    }
}

impl From<std::io::Error> for ReadError {
    fn from(e: std::io::Error) -> Self {
        ReadError::Io(e)
    }
}

/// Why, in words, without the path (the caller names it).
impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Io(e) => f.write_str(&plain_io_error(e)),
            ReadError::NotAFile { what } => write!(f, "it is {what}, not a regular file"),
            ReadError::TooLarge { limit, .. } => {
                write!(f, "it is larger than the limit of {} MiB", limit >> 20)
            }
            ReadError::OutsideRoot { root, .. } => {
                write!(f, "it lies outside the project root `{}`", root.display())
            }
            ReadError::HardLinked { links } => write!(
                f,
                "it has {links} names (hard links), and one may lie outside the project root"
            ),
        }
    }
}

impl std::error::Error for ReadError {}

/// Reads the regular file at `path`, at most `limit` bytes: a file the
/// user named (on the command line), not one beneath a project root
/// (`Root::read` reads those). What the path
/// names is checked before it is opened (a FIFO is never opened, a device
/// never read) and again on the opened file, which is opened non-blocking
/// and without following a final symlink, so a file swapped in between
/// cannot make the read block.
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    regular(&std::fs::metadata(path)?, limit)?;
    let file = open_no_block(path)?;
    let size = regular(&file.metadata()?, limit)?;
    read_bounded(file, size, limit)
}

/// The project root, opened once: the files beneath it are opened through
/// its directory handle, never by their full name, so what the root's path
/// names later (a directory in it renamed, swapped for a symlink) cannot
/// change what is read. Where the kernel has it (Linux 5.6 on), `cap-std`
/// opens with `openat2(RESOLVE_BENEATH)`; elsewhere it walks the path one
/// component at a time from the handle, never above it.
pub struct Root {
    /// The root, resolved (what `inside` is checked against).
    path: PathBuf,
    /// Its directory handle, or why it could not be opened.
    dir: std::io::Result<cap_std::fs::Dir>,
}

impl std::fmt::Debug for Root {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Root({})", self.path.display())
    }
}

impl Root {
    /// Opens the directory `path` (resolved, as `resolve` gives it). A
    /// root that cannot be opened is kept with its error: every read
    /// beneath it fails with that error.
    pub fn open(path: PathBuf) -> Root {
        let dir = cap_std::fs::Dir::open_ambient_dir(&path, cap_std::ambient_authority());
        Root { path, dir }
    }

    /// The root, resolved.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Reads the regular file `file` (resolved: absolute, no `..`) beneath
    /// the root, at most `limit` bytes, opened through the root's handle;
    /// a file with more than one name (hard link) is refused. A path that
    /// leads outside the root, now or by a swap while it is opened, is
    /// `OutsideRoot` and nothing of it is read.
    pub fn read(&self, file: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
        let outside = || ReadError::OutsideRoot {
            resolved: file.to_path_buf(),
            root: self.path.clone(),
        };
        let rel = file.strip_prefix(&self.path).map_err(|_| outside())?;
        if !rel.components().all(|c| matches!(c, Component::Normal(_))) {
            return Err(outside());
        }
        if rel.as_os_str().is_empty() {
            return Err(ReadError::NotAFile {
                what: "a directory",
            });
        }
        let dir = match &self.dir {
            Ok(d) => d,
            Err(e) => return Err(ReadError::Io(std::io::Error::new(e.kind(), e.to_string()))),
        };
        let refusal = |e: std::io::Error| {
            if escaped(&e) {
                outside()
            } else {
                ReadError::Io(e)
            }
        };
        // What the path names is checked before it is opened (a device is
        // never opened), and again on the opened file.
        let before = dir.metadata(rel).map_err(refusal)?;
        if !before.is_file() {
            return Err(ReadError::NotAFile {
                what: describe_beneath(&before.file_type()),
            });
        }
        let file = dir
            .open_with(rel, &beneath_options())
            .map_err(refusal)?
            .into_std();
        let meta = file.metadata()?;
        let size = regular(&meta, limit)?;
        let links = link_count(&meta);
        if links > 1 {
            return Err(ReadError::HardLinked { links });
        }
        read_bounded(file, size, limit)
    }
}

/// How a file beneath the root is opened: for reading, and on Unix
/// without blocking (a FIFO swapped in after the check cannot hang the
/// open; `regular_type` then refuses it).
fn beneath_options() -> cap_std::fs::OpenOptions {
    let mut o = cap_std::fs::OpenOptions::new();
    o.read(true);
    #[cfg(unix)]
    {
        use cap_std::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NONBLOCK);
    }
    o
}

/// Whether an open failed because the path led outside the root: `cap-std`
/// says so in words; `openat2` says EXDEV.
fn escaped(e: &std::io::Error) -> bool {
    #[cfg(unix)]
    if e.raw_os_error() == Some(libc::EXDEV) {
        return true;
    }
    e.kind() == std::io::ErrorKind::PermissionDenied && e.to_string().contains("outside")
}

/// The number of names the opened file has.
#[cfg(unix)]
fn link_count(meta: &std::fs::Metadata) -> u64 {
    use std::os::unix::fs::MetadataExt;
    meta.nlink()
}

#[cfg(not(unix))]
fn link_count(_meta: &std::fs::Metadata) -> u64 {
    1
}

/// Reads an opened file of `size` bytes (as stated), at most `limit`.
fn read_bounded(file: impl Read, size: u64, limit: u64) -> Result<Vec<u8>, ReadError> {
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge {
            bytes: bytes.len() as u64,
            limit,
        });
    }
    Ok(bytes)
}

/// The file's size if it is a regular file within the limit.
fn regular(meta: &std::fs::Metadata, limit: u64) -> Result<u64, ReadError> {
    let t = meta.file_type();
    if !t.is_file() {
        return Err(ReadError::NotAFile { what: describe(&t) });
    }
    if meta.len() > limit {
        return Err(ReadError::TooLarge {
            bytes: meta.len(),
            limit,
        });
    }
    Ok(meta.len())
}

/// What a file beneath the root that is not a regular file is, in words
/// (as `describe` says it).
fn describe_beneath(t: &cap_std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    let special = {
        use cap_std::fs::FileTypeExt;
        [
            t.is_fifo(),
            t.is_char_device() || t.is_block_device(),
            t.is_socket(),
        ]
    };
    #[cfg(not(unix))]
    let special = [false; 3];
    kind_in_words(special, t.is_dir())
}

/// What a file that is not a regular file is, in words.
fn describe(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    let special = {
        use std::os::unix::fs::FileTypeExt;
        [
            t.is_fifo(),
            t.is_char_device() || t.is_block_device(),
            t.is_socket(),
        ]
    };
    #[cfg(not(unix))]
    let special = [false; 3];
    kind_in_words(special, t.is_dir())
}

/// A kind of file in words, from whether it is a FIFO, a device or a
/// socket (`special`), or a directory.
fn kind_in_words([fifo, device, socket]: [bool; 3], dir: bool) -> &'static str {
    if fifo {
        "a FIFO"
    } else if device {
        "a device"
    } else if socket {
        "a socket"
    } else if dir {
        "a directory"
    } else {
        "not a regular file"
    }
}

#[cfg(unix)]
fn open_no_block(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOFOLLOW)
        .open(path)
}

#[cfg(not(unix))]
fn open_no_block(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// `path` made absolute with every symlink resolved. A path that does not
/// exist is resolved as far as it does and the rest taken lexically, so a
/// missing file outside the root is still seen to be outside it.
pub fn resolve(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let parts: Vec<Component> = abs.components().collect();
    // The longest prefix that exists, resolved; the rest taken lexically.
    for n in (1..parts.len()).rev() {
        let prefix: PathBuf = parts[..n].iter().collect();
        if let Ok(mut out) = std::fs::canonicalize(&prefix) {
            for c in &parts[n..] {
                match c {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::Normal(s) => out.push(s),
                    _ => {}
                }
            }
            return out;
        }
    }
    abs
}

/// Whether the resolved path lies inside the resolved root (or is it).
pub fn inside(resolved: &Path, root: &Path) -> bool {
    resolved.starts_with(root)
}

/// The OS error without its "(os error 2)" tail.
pub fn plain_io_error(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        std::io::ErrorKind::IsADirectory => "it is a directory".into(),
        _ => {
            let s = e.to_string();
            s.split(" (os error").next().unwrap_or(&s).to_lowercase()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_file_beyond_the_root_is_resolved_lexically() {
        let dir = std::env::temp_dir();
        let root = std::fs::canonicalize(&dir).expect("temp dir");
        let r = resolve(&dir.join("no_such_dir/../../x.lens"));
        assert!(!inside(&r, &root), "{}", r.display());
        let r = resolve(&dir.join("no_such_dir/x.lens"));
        assert!(inside(&r, &root), "{}", r.display());
    }

    #[test]
    fn a_directory_is_not_read() {
        let e = read_regular(&std::env::temp_dir(), MAX_FILE_BYTES).unwrap_err();
        assert!(matches!(
            e,
            ReadError::NotAFile {
                what: "a directory"
            }
        ));
    }

    #[cfg(unix)]
    #[test]
    fn a_file_with_a_second_name_is_not_read_beneath_the_root() {
        let base = std::env::temp_dir().join(format!("lensc-link-{}", std::process::id()));
        let proj = base.join("proj");
        std::fs::create_dir_all(&proj).expect("proj");
        std::fs::write(base.join("outside.lens"), "let secret = 1\n").expect("outside");
        std::fs::hard_link(base.join("outside.lens"), proj.join("linked.lens")).expect("link");
        std::fs::write(proj.join("one.lens"), "let mine = 1\n").expect("one");
        let root = Root::open(resolve(&proj));
        let linked = root.read(&resolve(&proj.join("linked.lens")), MAX_FILE_BYTES);
        let one = root.read(&resolve(&proj.join("one.lens")), MAX_FILE_BYTES);
        let _ = std::fs::remove_dir_all(&base);
        assert!(
            matches!(linked, Err(ReadError::HardLinked { links: 2 })),
            "{linked:?}"
        );
        assert_eq!(one.expect("one name: read"), b"let mine = 1\n");
    }

    #[test]
    fn a_path_beneath_the_root_is_opened_from_its_handle_only() {
        let root = Root::open(resolve(&std::env::temp_dir()));
        let e = root
            .read(Path::new("/etc/passwd"), MAX_FILE_BYTES)
            .unwrap_err();
        assert!(matches!(e, ReadError::OutsideRoot { .. }), "{e:?}");
        let dotdot = root.path().join("x/../../etc/passwd");
        let e = root.read(&dotdot, MAX_FILE_BYTES).unwrap_err();
        assert!(matches!(e, ReadError::OutsideRoot { .. }), "{e:?}");
    }

    #[cfg(unix)]
    #[test]
    fn a_device_is_not_read() {
        let e = read_regular(Path::new("/dev/zero"), MAX_FILE_BYTES).unwrap_err();
        assert!(matches!(e, ReadError::NotAFile { what: "a device" }));
    }
}
