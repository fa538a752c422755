//! Where things are, in the two ways the two sides count: the compiler's
//! byte offsets and the protocol's line and UTF-16 column (a `µ` is two
//! bytes and one UTF-16 unit, an astral character four bytes and two
//! units); and `file://` URIs to paths and back.

use std::path::{Path, PathBuf};

use lsp_types::{Position, Range, Uri};

/// A text's line starts, for converting offsets to positions and back.
pub struct LineIndex<'t> {
    text: &'t str,
    line_starts: Vec<usize>,
}

impl<'t> LineIndex<'t> {
    pub fn new(text: &'t str) -> Self {
        LineIndex {
            text,
            line_starts: lensc_lang::source::line_starts(text),
        }
    }

    /// The position of a byte offset (clamped to the text, and to the
    /// start of the character it falls inside).
    pub fn position(&self, offset: usize) -> Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.line_starts.partition_point(|&s| s <= offset) - 1;
        let start = self.line_starts[line];
        let character = self.text[start..offset].encode_utf16().count();
        Position::new(line as u32, character as u32)
    }

    pub fn range(&self, start: usize, end: usize) -> Range {
        Range::new(self.position(start), self.position(end))
    }

    /// The byte offset of a position: a line past the end is the end of
    /// the text, a column past the line's end is its end (before the
    /// line break), a column inside a surrogate pair the pair's start.
    pub fn offset(&self, p: Position) -> usize {
        let Some(&start) = self.line_starts.get(p.line as usize) else {
            return self.text.len();
        };
        let end = self
            .line_starts
            .get(p.line as usize + 1)
            .map_or(self.text.len(), |&next| next - 1);
        let line = &self.text[start..end];
        let line = line.strip_suffix('\r').unwrap_or(line);
        let mut units = 0;
        for (i, c) in line.char_indices() {
            units += c.len_utf16();
            if units > p.character as usize {
                return start + i;
            }
        }
        start + line.len()
    }
}

/// The path of a `file://` URI, percent-decoded; `None` for another scheme.
pub fn uri_to_path(uri: &Uri) -> Option<PathBuf> {
    let rest = uri.as_str().strip_prefix("file://")?;
    // `file:///p` and `file://localhost/p`: the path starts at the first `/`.
    let path = &rest[rest.find('/')?..];
    let mut bytes = Vec::with_capacity(path.len());
    let raw = path.as_bytes();
    let mut i = 0;
    while i < raw.len() {
        if raw[i] == b'%'
            && let Some(b) = path
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            bytes.push(b);
            i += 3;
            continue;
        }
        bytes.push(raw[i]);
        i += 1;
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        Some(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
    }
    #[cfg(not(unix))]
    {
        Some(PathBuf::from(String::from_utf8_lossy(&bytes).into_owned()))
    }
}

/// The `file://` URI of an absolute path, every byte outside the URI's
/// unreserved set and `/` percent-encoded.
pub fn path_to_uri(path: &Path) -> Uri {
    let mut s = String::from("file://");
    let text = path.to_string_lossy();
    if !text.starts_with('/') {
        s.push('/');
    }
    for b in text.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => {
                s.push(b as char)
            }
            _ => s.push_str(&format!("%{b:02X}")),
        }
    }
    s.parse().expect("a percent-encoded file URI parses")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_utf16_units_not_bytes() {
        // `µ` is 2 bytes and 1 unit; `𝑥` (U+1D465) 4 bytes and 2 units.
        let text = "a: 1 µm\n// 𝑥 here\nb";
        let ix = LineIndex::new(text);
        let m = text.find('m').expect("m");
        assert_eq!(ix.position(m), Position::new(0, 6));
        let here = text.find("here").expect("here");
        assert_eq!(ix.position(here), Position::new(1, 6));
        let b = text.rfind('b').expect("b");
        assert_eq!(ix.position(b), Position::new(2, 0));
        for off in [0, m, here, b, text.len()] {
            assert_eq!(ix.offset(ix.position(off)), off, "{off}");
        }
        // Past the line's end: its end; past the text: the text's end.
        assert_eq!(
            ix.offset(Position::new(0, 99)),
            text.find('\n').expect("nl")
        );
        assert_eq!(ix.offset(Position::new(9, 0)), text.len());
        // Inside the surrogate pair: the character's start.
        assert_eq!(ix.offset(Position::new(1, 4)), text.find('𝑥').expect("x"));
    }

    #[test]
    fn crlf_lines_end_before_the_carriage_return() {
        let text = "ab\r\ncd";
        let ix = LineIndex::new(text);
        assert_eq!(ix.offset(Position::new(0, 9)), 2);
        assert_eq!(ix.position(4), Position::new(1, 0));
    }

    #[test]
    fn uris_round_trip_through_percent_encoding() {
        let p = Path::new("/tmp/a lens/µ#1.lens");
        let uri = path_to_uri(p);
        assert_eq!(uri.as_str(), "file:///tmp/a%20lens/%C2%B5%231.lens");
        assert_eq!(uri_to_path(&uri).as_deref(), Some(p));
        let other: Uri = "untitled:1".parse().expect("uri");
        assert_eq!(uri_to_path(&other), None);
    }
}
