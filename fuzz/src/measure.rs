//! The fuzzer's target for the measurement readers (issue #33, item 7):
//! mutations of the peer files in `tests/measure/peer/` (X3P archives,
//! SDF, MetroPro `.dat` and its ASCII export, points and profiles) and of
//! maps lensc writes itself, read as `lensc measure` reads them. An X3P
//! is mutated inside its archive as often as outside it (its `main.xml`
//! or point data changed, then zipped again, checksums left stale or made
//! right), so the inputs reach past the zip's own checks. The invariants:
//! no panic, no hang; a file read is well formed (as many heights as the
//! grid has points, spacings finite and positive, every valid height and
//! every point finite); the texture figures of a map are finite or absent.

use std::io::{Read, Write};
use std::path::Path;

use lensc_measure::read::TextUnits;
use lensc_measure::{HeightMap, Measured};

use crate::harness::{Fault, Reached};
use crate::mutate::{Corpus, mutant};
use crate::rng::Rng;

/// The measurement files mutations start from: every peer file a reader
/// takes, two maps lensc writes (one with invalid points), and points and
/// profiles in each text spelling (`.xyz`, `.csv` with a header, `.txt`,
/// `.prf` with semicolons).
pub fn corpus(root: &Path) -> std::io::Result<Corpus> {
    let mut files = Corpus::under(root, &["tests/measure/peer"], |_| true)?.files;
    files.retain(|(name, bytes)| lensc_measure::read::detect(name, bytes).is_some());
    let mut map = HeightMap::from_heights(
        24,
        16,
        (0.01, 0.01),
        (0..24 * 16)
            .map(|k| 1e-4 * ((k % 24) as f64).powi(2))
            .collect(),
    );
    files.push((
        "lensc.x3p".into(),
        lensc_measure::write::x3p(&map, "lensc fuzz"),
    ));
    map.valid[5] = false;
    map.valid[100] = false;
    files.push((
        "lensc-masked.x3p".into(),
        lensc_measure::write::x3p(&map, "lensc fuzz"),
    ));
    files.push(("points.xyz".into(), points_text(&map).into_bytes()));
    files.push((
        "profile.txt".into(),
        b"0 0\n0.1 0.002\n0.2 0.008\n0.3 0.018\n".to_vec(),
    ));
    // The text readers' other spellings: a CSV with a header, a comment, an
    // invalid height and an intensity column; a `.prf` profile with
    // semicolons and tabs.
    files.push((
        "points.csv".into(),
        format!(
            "x,y,z,intensity\n# lensc fuzz\n{}0.5,0.5,NaN,7\n",
            m_csv(&map)
        )
        .into_bytes(),
    ));
    files.push((
        "profile.prf".into(),
        b"x;z\n0;0\n0.1;\t0.002\n% a comment\n0.2;0.008\n0.3;BAD\n".to_vec(),
    ));
    Ok(Corpus { files })
}

/// A map's valid points as x,y,z,intensity lines.
fn m_csv(m: &HeightMap) -> String {
    m.points()
        .iter()
        .map(|[x, y, z]| format!("{x},{y},{z},1\n"))
        .collect()
}

/// A map's valid points as x y z text.
fn points_text(m: &HeightMap) -> String {
    m.points()
        .iter()
        .map(|[x, y, z]| format!("{x} {y} {z}\n"))
        .collect()
}

/// Input `rng` makes of the corpus: the file's name (its extension picks
/// the text readers) and bytes.
pub fn input(corpus: &Corpus, rng: &mut Rng) -> (String, Vec<u8>) {
    let (name, bytes) = rng.pick(&corpus.files);
    if bytes.starts_with(b"PK\x03\x04")
        && rng.chance(0.5)
        && let Some(inside) = mutate_inside(name, bytes, rng)
    {
        return (name.clone(), inside);
    }
    let one = Corpus {
        files: vec![(name.clone(), bytes.clone())],
    };
    (name.clone(), mutant(&one, rng))
}

/// An archive's files: name and bytes.
type Entries = std::rc::Rc<Vec<(String, Vec<u8>)>>;

thread_local! {
    /// Each archive of the corpus unpacked once, by name (`None`: it
    /// cannot be opened): unpacking the 3 MB X3P again for every input
    /// was most of this target's time.
    static UNPACKED: std::cell::RefCell<std::collections::HashMap<String, Option<Entries>>> =
        Default::default();
}

/// The files of archive `name` (`bytes`), unpacked the first time.
fn unpacked(name: &str, bytes: &[u8]) -> Option<Entries> {
    UNPACKED.with(|u| {
        if let Some(e) = u.borrow().get(name) {
            return e.clone();
        }
        let e = unpack(bytes).map(std::rc::Rc::new);
        u.borrow_mut().insert(name.to_string(), e.clone());
        e
    })
}

/// The files of an archive, or `None` if it cannot be opened or holds
/// none.
fn unpack(bytes: &[u8]) -> Option<Vec<(String, Vec<u8>)>> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).ok()?;
    let mut entries = Vec::new();
    for i in 0..zip.len() {
        let mut f = zip.by_index(i).ok()?;
        if f.is_dir() {
            continue;
        }
        let mut data = Vec::new();
        f.read_to_end(&mut data).ok()?;
        entries.push((f.name().to_string(), data));
    }
    (!entries.is_empty()).then_some(entries)
}

/// Archive `name` (`bytes`) with one of its entries mutated and the
/// archive written again (entries stored), or `None` if it cannot be
/// opened.
fn mutate_inside(name: &str, bytes: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let entries = unpacked(name, bytes)?;
    let k = rng.below(entries.len());
    let one = Corpus {
        files: vec![entries[k].clone()],
    };
    let changed = mutant(&one, rng);
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (i, (name, data)) in entries.iter().enumerate() {
        out.start_file(name.as_str(), stored).ok()?;
        out.write_all(if i == k { &changed } else { data }).ok()?;
    }
    out.finish().ok().map(|c| c.into_inner())
}

/// Reads `bytes` as `lensc measure` does and holds what it read to the
/// invariants above.
pub fn run(name: &str, bytes: &[u8]) -> Result<Reached, Fault> {
    let read = match lensc_measure::read::read(name, bytes, TextUnits::MM) {
        Ok(m) => m,
        Err(e) => {
            if e.to_string().trim().is_empty() {
                return Err("a read error with no message".into());
            }
            return Ok(Reached::default());
        }
    };
    match &read.data {
        Measured::Map(m) => {
            let points = m.nx.checked_mul(m.ny);
            if points != Some(m.z.len()) || m.z.len() != m.valid.len() {
                return Err(format!(
                    "a {} x {} map with {} heights and {} validity flags",
                    m.nx,
                    m.ny,
                    m.z.len(),
                    m.valid.len()
                ));
            }
            if !(m.dx.is_finite() && m.dx > 0.0 && m.dy.is_finite() && m.dy > 0.0) {
                return Err(format!("pixel spacing {} x {} mm", m.dx, m.dy));
            }
            if !(m.x0.is_finite() && m.y0.is_finite()) {
                return Err(format!("origin ({}, {})", m.x0, m.y0));
            }
            if let Some(k) = (0..m.z.len()).find(|&k| m.valid[k] && !m.z[k].is_finite()) {
                return Err(format!("valid point {k} has height {}", m.z[k]));
            }
            if m.nx * m.ny <= 1 << 16
                && let Some(t) = lensc_measure::texture::parameters(m)
            {
                let all = [t.sa, t.sq, t.sz, t.sdq];
                if all.iter().any(|v| !v.is_finite()) {
                    return Err(format!("texture figures {all:?}"));
                }
            }
        }
        Measured::Cloud(c) => {
            if let Some(p) = c.points.iter().find(|p| p.iter().any(|v| !v.is_finite())) {
                return Err(format!("a point {p:?}"));
            }
        }
        Measured::Profile(p) => {
            if p.x.len() != p.z.len() {
                return Err(format!("a profile of {} x and {} z", p.x.len(), p.z.len()));
            }
            if p.x.iter().chain(&p.z).any(|v| !v.is_finite()) {
                return Err("a profile value that is not finite".into());
            }
        }
    }
    Ok(Reached {
        clean: true,
        ..Reached::default()
    })
}
