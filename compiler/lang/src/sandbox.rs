//! Which files a job may read, and reading them safely: only regular files
//! (never a FIFO, device, socket or directory, so nothing can block or
//! stream forever), at most `MAX_FILE_BYTES` each (read with a bounded
//! reader), and only under the project root after symlinks are resolved.
//! The errors are data (`ReadError`); the loader turns them into coded
//! diagnostics.

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
}

impl ReadError {
    /// The diagnostic code that reports this refusal.
    pub fn code(&self) -> &'static str {
        match self {
            ReadError::Io(_) => codes::CANNOT_READ,
            ReadError::NotAFile { .. } => codes::NOT_A_FILE,
            ReadError::TooLarge { .. } => codes::FILE_TOO_LARGE,
            ReadError::OutsideRoot { .. } => codes::OUTSIDE_ROOT,
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
        }
    }
}

impl std::error::Error for ReadError {}

/// Reads the regular file at `path`, at most `limit` bytes. What the path
/// names is checked before it is opened (a FIFO is never opened, a device
/// never read) and again on the opened file, which is opened non-blocking
/// and without following a final symlink, so a file swapped in between
/// cannot make the read block.
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    regular(&std::fs::metadata(path)?, limit)?;
    let file = open_no_block(path)?;
    let size = regular(&file.metadata()?, limit)?;
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

/// What a file that is not a regular file is, in words.
fn describe(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
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
    fn a_device_is_not_read() {
        let e = read_regular(Path::new("/dev/zero"), MAX_FILE_BYTES).unwrap_err();
        assert!(matches!(e, ReadError::NotAFile { what: "a device" }));
    }
}
