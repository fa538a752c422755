//! Mutations of real files: the examples, the standard library and the
//! bad-input corpora, with bytes flipped, tokens swapped, lines deleted or
//! duplicated, numbers replaced by extremes and files spliced together.

use std::path::{Path, PathBuf};

use crate::rng::Rng;

/// The files mutations start from: name and bytes.
pub struct Corpus {
    pub files: Vec<(String, Vec<u8>)>,
}

impl Corpus {
    /// Every file directly in `dirs` under `root` whose name `keep` takes,
    /// in name order.
    pub fn under(
        root: &Path,
        dirs: &[&str],
        keep: impl Fn(&str) -> bool,
    ) -> std::io::Result<Corpus> {
        let mut files = Vec::new();
        for dir in dirs {
            let mut paths: Vec<PathBuf> = std::fs::read_dir(root.join(dir))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file())
                .collect();
            paths.sort();
            for p in paths {
                let name = p
                    .file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned();
                if keep(&name) {
                    files.push((name, std::fs::read(&p)?));
                }
            }
        }
        Ok(Corpus { files })
    }

    /// Every `.lens` file of examples/, stdlib/, tests/bad/ and
    /// tests/bad_builds/ under the repository at `root`.
    pub fn load(root: &Path) -> std::io::Result<Corpus> {
        Corpus::under(
            root,
            &["examples", "stdlib", "tests/bad", "tests/bad_builds"],
            |_| true,
        )
    }
}

/// Numbers a mutation puts in place of one in the file.
const REPLACEMENTS: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "1e308",
    "-1e308",
    "1e999",
    "5e-324",
    "1e-300",
    "1e-9",
    "1e-15",
    "-1",
    "100000",
    "100001",
    "4294967297",
    "18446744073709551616",
    "0.5",
    "2",
    "(0/0)",
    "sqrt(-1)",
    "1e-6 nm",
    "1e-12 mm",
    "0 nm",
    "1e9 rpm",
    "-3",
];

/// Tokens a mutation inserts.
const TOKENS: &[&str] = &[
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    ",",
    ":",
    "=",
    "..",
    "+",
    "-",
    "*",
    "/",
    "^",
    "\"",
    "//",
    "/*",
    "let",
    "use",
    "job",
    "surface",
    "mm",
    "um",
    "deg",
    "rpm",
    "x",
    "y",
    "\n",
    "é",
    "\u{0}",
    "\u{feff}",
    "µm",
    "std::",
    "circle(radius: 1 mm)",
];

/// One mutated file (a few mutations of one corpus file, now and then
/// spliced with another).
pub fn mutant(corpus: &Corpus, rng: &mut Rng) -> Vec<u8> {
    let (_, base) = rng.pick(&corpus.files);
    let mut bytes = base.clone();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        match rng.below(10) {
            0 => flip_byte(&mut bytes, rng),
            1 => swap_tokens(&mut bytes, rng),
            2 => delete_line(&mut bytes, rng),
            3 => duplicate_line(&mut bytes, rng),
            4 | 5 => replace_number(&mut bytes, rng),
            6 => insert_token(&mut bytes, rng),
            7 => {
                let (_, other) = rng.pick(&corpus.files);
                splice(&mut bytes, other, rng);
            }
            8 => {
                let at = rng.below(bytes.len() + 1);
                bytes.truncate(at);
            }
            _ => delete_range(&mut bytes, rng),
        }
    }
    bytes
}

fn flip_byte(b: &mut [u8], rng: &mut Rng) {
    if !b.is_empty() {
        let i = rng.below(b.len());
        b[i] ^= 1 << rng.below(8);
    }
}

/// Byte ranges of the file's tokens: runs of word characters, or single
/// punctuation bytes.
fn tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || c >= 0x80;
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        if word(b[i]) {
            while i < b.len() && word(b[i]) {
                i += 1;
            }
        } else {
            i += 1;
        }
        out.push((start, i));
    }
    out
}

fn swap_tokens(b: &mut Vec<u8>, rng: &mut Rng) {
    let toks = tokens(b);
    if toks.len() < 2 {
        return;
    }
    let (mut x, mut y) = (*rng.pick(&toks), *rng.pick(&toks));
    if x.0 > y.0 {
        std::mem::swap(&mut x, &mut y);
    }
    if x.1 > y.0 {
        return;
    }
    let mut out = Vec::with_capacity(b.len());
    out.extend_from_slice(&b[..x.0]);
    out.extend_from_slice(&b[y.0..y.1]);
    out.extend_from_slice(&b[x.1..y.0]);
    out.extend_from_slice(&b[x.0..x.1]);
    out.extend_from_slice(&b[y.1..]);
    *b = out;
}

fn lines(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < b.len() {
        out.push((start, b.len()));
    }
    out
}

fn delete_line(b: &mut Vec<u8>, rng: &mut Rng) {
    let ls = lines(b);
    if !ls.is_empty() {
        let (s, e) = *rng.pick(&ls);
        b.drain(s..e);
    }
}

fn duplicate_line(b: &mut Vec<u8>, rng: &mut Rng) {
    let ls = lines(b);
    if !ls.is_empty() {
        let (s, e) = *rng.pick(&ls);
        let line = b[s..e].to_vec();
        let (at, _) = *rng.pick(&ls);
        b.splice(at..at, line);
    }
}

fn replace_number(b: &mut Vec<u8>, rng: &mut Rng) {
    let nums: Vec<_> = tokens(b)
        .into_iter()
        .filter(|&(s, _)| b[s].is_ascii_digit())
        .collect();
    if nums.is_empty() {
        return;
    }
    let (s, e) = *rng.pick(&nums);
    let new = rng.pick(REPLACEMENTS).as_bytes();
    b.splice(s..e, new.iter().copied());
}

fn insert_token(b: &mut Vec<u8>, rng: &mut Rng) {
    let at = rng.below(b.len() + 1);
    let t = rng.pick(TOKENS).as_bytes();
    b.splice(at..at, t.iter().copied());
}

fn splice(b: &mut Vec<u8>, other: &[u8], rng: &mut Rng) {
    let at = rng.below(b.len() + 1);
    let from = rng.below(other.len() + 1);
    let to = from + rng.below(other.len() - from + 1);
    b.splice(at..at, other[from..to].iter().copied());
}

fn delete_range(b: &mut Vec<u8>, rng: &mut Rng) {
    if b.is_empty() {
        return;
    }
    let s = rng.below(b.len());
    let e = (s + 1 + rng.below(64)).min(b.len());
    b.drain(s..e);
}
