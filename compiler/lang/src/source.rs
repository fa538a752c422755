//! Loaded source texts, with the names diagnostics show for them and the
//! mapping from byte offsets to lines and columns. A text may be a part
//! of a larger file (a line of a program `lensc verify` reads, which it
//! never holds whole): its lines and offsets then count from where the
//! part starts in that file.

use std::path::PathBuf;

use lensc_grammar::FileId;

pub struct SourceFile {
    /// What diagnostics call the file: the path as given, or `std/tools.lens`.
    pub name: String,
    /// Where it was read from; `None` for embedded standard-library files.
    pub path: Option<PathBuf>,
    pub text: String,
    line_starts: Vec<usize>,
    /// The lines of the file before `text` (0 for a whole file).
    pub first_line: usize,
    /// The bytes of the file before `text` (0 for a whole file).
    pub first_byte: usize,
}

/// The byte offset where each line of `text` starts: 0, then one past
/// every line feed.
pub fn line_starts(text: &str) -> Vec<usize> {
    let mut starts = vec![0];
    starts.extend(
        text.bytes()
            .enumerate()
            .filter(|(_, b)| *b == b'\n')
            .map(|(i, _)| i + 1),
    );
    starts
}

#[derive(Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn add(&mut self, name: String, path: Option<PathBuf>, text: String) -> FileId {
        self.add_part(name, path, text, 0, 0)
    }
    /// Adds `text`, the part of a file that starts on its 0-based line
    /// `first_line`, at its byte `first_byte`: lines are shown as the
    /// file's (`line_col`), spans stay offsets into `text`.
    pub fn add_part(
        &mut self,
        name: String,
        path: Option<PathBuf>,
        text: String,
        first_line: usize,
        first_byte: usize,
    ) -> FileId {
        let line_starts = line_starts(&text);
        self.files.push(SourceFile {
            name,
            path,
            text,
            line_starts,
            first_line,
            first_byte,
        });
        FileId(self.files.len() as u32 - 1)
    }
    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }
    pub fn iter(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (FileId(i as u32), f))
    }
    /// The 0-based line a byte offset is on.
    pub fn line_of(&self, id: FileId, offset: usize) -> usize {
        let f = self.get(id);
        f.line_starts
            .partition_point(|&s| s <= offset.min(f.text.len()))
            - 1
    }
    /// The byte range of 0-based line `line`, with its line feed.
    pub fn line_range(&self, id: FileId, line: usize) -> std::ops::Range<usize> {
        let f = self.get(id);
        let start = f.line_starts[line.min(f.line_starts.len() - 1)];
        let end = f.line_starts.get(line + 1).copied().unwrap_or(f.text.len());
        start..end
    }
    /// 1-based line (the file's, for a part) and column (in characters)
    /// of a byte offset into the text.
    pub fn line_col(&self, id: FileId, offset: usize) -> (usize, usize) {
        let f = self.get(id);
        let offset = offset.min(f.text.len());
        let line = f.line_starts.partition_point(|&s| s <= offset) - 1;
        let start = f.line_starts[line];
        let col = f
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count());
        (f.first_line + line + 1, col + 1)
    }
}
