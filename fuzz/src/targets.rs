//! The fuzzer's targets beyond `check` and `build` (issue #33, item 7):
//! `lensc verify` on mutated programs, `lensc import` on mutated
//! prescriptions, and the language server on random message sequences,
//! each input made from the run's seed and index (`Rng::for_input`), so
//! any input can be replayed. The invariants: no panic, no hang, every
//! finding and diagnostic coded and spanned inside its text; an import
//! never writes a `.lens` over the file-size limit; the language server
//! exits 0 or 1 (never a panic's 101 or a signal) whatever it is sent.

use std::collections::HashMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use lensc_build::driver;
use lensc_lang::lower::read_back;
use lensc_lang::source::SourceMap;
use lensc_runtime::reader;

use crate::harness::{Depth, Fault, MemFs, Reached, render, well_formed};
use crate::mutate::Corpus;
use crate::rng::Rng;

/// Runs one input of any target: a program, a prescription or a session
/// here, a `.lens` file through `harness::run`.
pub fn run(fs: &MemFs, bytes: &[u8], depth: Depth, out_dir: &Path) -> Result<Reached, Fault> {
    match depth {
        Depth::Verify(pair) => verify(fs, bytes, pair),
        Depth::Import { json } => import(fs, bytes, json),
        Depth::Lsp => lsp(bytes),
        Depth::Measure { ext } => crate::measure::run(&format!("fuzz.{ext}"), bytes),
        _ => crate::harness::run(fs, bytes, depth, out_dir),
    }
}

/// The stdlib machines and the dialects they are read by, for programs
/// whose (mutated) header names none that can be found.
const MACHINES: &[(&str, &str)] = &[
    ("linuxcnc_lathe", "linuxcnc"),
    ("linuxcnc_lathe", "fanuc_0i_lathe"),
    ("ultra_precision_lathe", "ultra_precision_lathe_gcode"),
    ("nanoform_x_fts5000", "ultra_precision_lathe_gcode"),
    ("generic_3axis_mill", "heidenhain_iso"),
    ("generic_3axis_mill", "heidenhain_tnc_klartext"),
    ("generic_3axis_mill", "siemens_840d_mill"),
    ("generic_3axis_mill", "fanuc_0i_mill"),
    ("linuxcnc_lathe", "siemens_840d_lathe"),
];

/// Every program of the bad-program corpus (clean ones included).
pub fn programs(root: &Path) -> std::io::Result<Corpus> {
    Corpus::under(
        root,
        &["tests/bad_programs", "tests/bad_programs/clean"],
        |_| true,
    )
}

/// Every prescription `lensc import` reads in the import corpus.
pub fn prescriptions(root: &Path) -> std::io::Result<Corpus> {
    Corpus::under(root, &["tests/import"], |name| {
        name.ends_with(".zmx") || name.ends_with(".json")
    })
}

/// A machine's limits and a dialect, as `lensc verify` finds them.
type Reading = (
    lensc_runtime::reader::MachineLimits,
    lensc_runtime::post::Dialect,
);

/// Readings by machine and dialect name (`None`: no such pair).
type Readings = HashMap<(String, String), Option<std::rc::Rc<Reading>>>;

thread_local! {
    /// Readings looked up so far, once per worker.
    static READINGS: std::cell::RefCell<Readings> = Default::default();
}

/// The stdlib machine `machine` read by dialect `dialect`, if both exist
/// (names from a mutated header are tried as they are).
fn reading(fs: &MemFs, machine: &str, dialect: &str) -> Option<std::rc::Rc<Reading>> {
    let ident = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ident(machine) || !ident(dialect) {
        return None;
    }
    let key = (machine.to_string(), dialect.to_string());
    READINGS.with(|r| {
        if let Some(found) = r.borrow().get(&key) {
            return found.clone();
        }
        let uses = format!("use std::machines::{machine}\nuse std::dialects::{dialect}\n");
        let c = driver::check_text(fs, "<standard library>", uses.as_bytes());
        let decls = &c.checked.declarations;
        let found = read_back::machine_named(decls, machine)
            .and_then(|(limits, _)| Some((limits, read_back::dialect_named(decls, dialect)?)))
            .map(std::rc::Rc::new);
        r.borrow_mut().insert(key, found.clone());
        found
    })
}

/// `lensc verify` on a program: read by the machine and dialect its
/// header names (else the `fallback` pair), every finding inside the
/// program, shown over its own line as `verify` shows it, both renderers.
pub fn verify(fs: &MemFs, bytes: &[u8], fallback: usize) -> Result<Reached, Fault> {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64 << 10)]).into_owned();
    let named = reader::header_names(&head).and_then(|h| reading(fs, &h.machine, &h.dialect));
    let (m, d) = MACHINES[fallback % MACHINES.len()];
    let Some(r) = named.or_else(|| reading(fs, m, d)) else {
        return Err(format!("the stdlib pair {m}/{d} cannot be read by"));
    };
    let findings = reader::read_from(bytes, &r.1, &r.0).map_err(|e| format!("read: {e}"))?;
    let lines = bytes.split(|&b| b == b'\n').count();
    let mut sources = SourceMap::default();
    let mut diags = Vec::new();
    let mut starts = vec![0];
    starts.extend(
        bytes
            .iter()
            .enumerate()
            .filter(|(_, b)| **b == b'\n')
            .map(|(i, _)| i + 1),
    );
    for f in &findings {
        if f.line == 0 || f.line > lines + 1 {
            return Err(format!(
                "finding {:?} at line {} of a program of {lines} lines",
                f.rule, f.line
            ));
        }
        // The line as `verify` keeps it: a part of the program, its bytes
        // that are not UTF-8 read as `�` (as the reader reads them: a
        // span counts from the line's first byte in the program, then in
        // the line as read).
        let start = starts.get(f.line - 1).copied().unwrap_or(bytes.len());
        let end = starts.get(f.line).copied().unwrap_or(bytes.len());
        let text = String::from_utf8_lossy(&bytes[start..end])
            .trim_end_matches(['\n', '\r'])
            .to_string();
        let (s, e) = (f.span.0.wrapping_sub(start), f.span.1.wrapping_sub(start));
        if f.span.0 < start
            || s > e
            || e > text.len()
            || !text.is_char_boundary(s)
            || !text.is_char_boundary(e)
        {
            return Err(format!(
                "finding {:?} at line {} span {:?} outside its line ({start}..{end} in the program, {} bytes read)",
                f.rule,
                f.line,
                f.span,
                text.len()
            ));
        }
        let file = sources.add_part("fuzz.ngc".into(), None, text, f.line - 1, start);
        let mut g = f.clone();
        g.span = (s, e);
        diags.push(read_back::finding_diagnostic(&g, file));
    }
    // Spans past a line that lost its bytes to `�` are clamped by the
    // renderer, as `verify`'s are; the invariant is the code and message.
    for d in &diags {
        if d.code.is_empty() || d.message.is_empty() || d.labels.is_empty() {
            return Err(format!("a finding without a code, message or span: {d:?}"));
        }
    }
    render(&diags, &sources)?;
    Ok(Reached {
        clean: findings.is_empty(),
        ..Reached::default()
    })
}

/// `lensc import` on a prescription named `name`: coded diagnostics
/// within its text, and a `.lens` (if any) within the file-size limit that
/// `check` takes without a panic.
pub fn import(fs: &MemFs, bytes: &[u8], json: bool) -> Result<Reached, Fault> {
    let name = if json { "fuzz.json" } else { "fuzz.zmx" };
    let imported = lensc_lang::import::import(name, bytes);
    let mut sources = SourceMap::default();
    sources.add(name.into(), None, imported.source_text.clone());
    well_formed(&imported.diags, &sources)?;
    render(&imported.diags, &sources)?;
    let Some(lens) = imported.lens else {
        return Ok(Reached::default());
    };
    if lens.len() as u64 > lensc_lang::sandbox::MAX_FILE_BYTES {
        return Err(format!(
            "import wrote {} bytes, over the file-size limit",
            lens.len()
        ));
    }
    let c = driver::check_text(fs, "imported.lens", lens.as_bytes());
    well_formed(c.diags(), &c.loaded.sources)?;
    render(c.diags(), &c.loaded.sources)?;
    Ok(Reached {
        clean: !c.has_errors(),
        ..Reached::default()
    })
}

/// The `lensc` binary the language-server target starts (`--lensc`).
pub static LENSC: OnceLock<PathBuf> = OnceLock::new();

/// How long one language-server session may take.
const SESSION: Duration = Duration::from_secs(8);

/// A session of the language server fed `bytes` (frames, some malformed)
/// on its standard input, which is then closed: it must answer and exit 0
/// or 1 within `SESSION`, never panic (101) or die by a signal.
pub fn lsp(bytes: &[u8]) -> Result<Reached, Fault> {
    let Some(lensc) = LENSC.get() else {
        return Err("the lsp target needs --lensc PATH".into());
    };
    let mut child = Command::new(lensc)
        .arg("lsp")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", lensc.display()))?;
    let mut stdin = child.stdin.take().ok_or("no stdin")?;
    let input = bytes.to_vec();
    // Written from a thread: the server answers as it reads, and would
    // block on a full pipe if its answers were not read meanwhile.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let mut stdout = child.stdout.take().ok_or("no stdout")?;
    let mut stderr = child.stderr.take().ok_or("no stderr")?;
    let reader = std::thread::spawn(move || {
        let mut out = Vec::new();
        let _ = stdout.read_to_end(&mut out);
        out
    });
    let err_reader = std::thread::spawn(move || {
        let mut err = Vec::new();
        let _ = stderr.read_to_end(&mut err);
        err
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| format!("wait: {e}"))? {
            break s;
        }
        if start.elapsed() > SESSION {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "the language server did not exit within {SESSION:?}"
            ));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let _ = writer.join();
    let answers = reader.join().unwrap_or_default();
    let err = err_reader.join().unwrap_or_default();
    let err = String::from_utf8_lossy(&err);
    match status.code() {
        Some(0 | 1) if !err.contains("panicked") => Ok(Reached {
            clean: !answers.is_empty(),
            ..Reached::default()
        }),
        code => Err(format!(
            "the language server ended with {code:?}: {}",
            err.lines().next().unwrap_or("")
        )),
    }
}

/// A frame of `body` with its header.
fn frame(body: &[u8]) -> Vec<u8> {
    let mut f = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    f.extend_from_slice(body);
    f
}

/// A random session: an `initialize` (most of the time), then messages
/// about a document (open, change, hover, completion, definition,
/// formatting, save, close), some malformed frames, and now and then
/// `shutdown` and `exit`.
pub fn session(corpus: &Corpus, rng: &mut Rng) -> Vec<u8> {
    let uri = "file:///tmp/lensc-fuzz/doc.lens";
    let mut out = Vec::new();
    let mut id = 0;
    let mut next_id = || {
        id += 1;
        id
    };
    if rng.chance(0.9) {
        let body = format!(
            r#"{{"jsonrpc":"2.0","id":{},"method":"initialize","params":{{"capabilities":{{}}}}}}"#,
            next_id()
        );
        out.extend(frame(body.as_bytes()));
        out.extend(frame(
            br#"{"jsonrpc":"2.0","method":"initialized","params":{}}"#,
        ));
    }
    let text = String::from_utf8_lossy(&crate::mutate::mutant(corpus, rng)).into_owned();
    let quoted = serde_json_string(&text);
    let pos = |rng: &mut Rng| {
        format!(
            r#"{{"line":{},"character":{}}}"#,
            rng.below(40),
            rng.below(80)
        )
    };
    for _ in 0..1 + rng.below(12) {
        let body = match rng.below(14) {
            0 => format!(
                r#"{{"jsonrpc":"2.0","method":"textDocument/didOpen","params":{{"textDocument":{{"uri":"{uri}","languageId":"lens","version":1,"text":{quoted}}}}}}}"#
            ),
            1 => format!(
                r#"{{"jsonrpc":"2.0","method":"textDocument/didChange","params":{{"textDocument":{{"uri":"{uri}","version":2}},"contentChanges":[{{"range":{{"start":{},"end":{}}},"text":{}}}]}}}}"#,
                pos(rng),
                pos(rng),
                serde_json_string(prefix(&text, rng.below(64)))
            ),
            2 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"textDocument/hover","params":{{"textDocument":{{"uri":"{uri}"}},"position":{}}}}}"#,
                next_id(),
                pos(rng)
            ),
            3 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"textDocument/completion","params":{{"textDocument":{{"uri":"{uri}"}},"position":{}}}}}"#,
                next_id(),
                pos(rng)
            ),
            4 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"textDocument/definition","params":{{"textDocument":{{"uri":"{uri}"}},"position":{}}}}}"#,
                next_id(),
                pos(rng)
            ),
            5 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"textDocument/formatting","params":{{"textDocument":{{"uri":"{uri}"}},"options":{{"tabSize":4,"insertSpaces":true}}}}}}"#,
                next_id()
            ),
            6 => format!(
                r#"{{"jsonrpc":"2.0","method":"textDocument/didSave","params":{{"textDocument":{{"uri":"{uri}"}}}}}}"#
            ),
            7 => format!(
                r#"{{"jsonrpc":"2.0","method":"textDocument/didClose","params":{{"textDocument":{{"uri":"{uri}"}}}}}}"#
            ),
            8 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"shutdown"}}"#,
                next_id()
            ),
            9 => r#"{"jsonrpc":"2.0","method":"exit"}"#.to_string(),
            10 => format!(
                r#"{{"jsonrpc":"2.0","id":{},"method":"no/such"}}"#,
                next_id()
            ),
            // Malformed frames: written raw, not through `frame`.
            11 => {
                let junk: &[&[u8]] = &[
                    b"Content-Length: -5\r\n\r\n",
                    b"Content-Length: 1099511627776\r\n\r\n",
                    b"Content-Length: 3\r\n\r\n{}}",
                    b"Content-Type: x\r\n\r\n",
                    b"Content-Length: 12\r\n\r\nnot json !!!",
                    b"\r\n\r\n",
                    b"Content-Length: 2\r\n\r\n[]",
                    b"Content-Length: 4\r\n\r\nnull",
                ];
                let pick: &[u8] = junk[rng.below(junk.len())];
                out.extend_from_slice(pick);
                continue;
            }
            12 => {
                // A body cut off or bytes flipped in a valid frame.
                let body = format!(
                    r#"{{"jsonrpc":"2.0","id":{},"method":"shutdown"}}"#,
                    next_id()
                );
                let mut f = frame(body.as_bytes());
                let i = rng.below(f.len());
                f[i] ^= 1 << rng.below(8);
                out.extend(f);
                continue;
            }
            _ => {
                // A header line with no end, then the stream's end.
                out.extend(std::iter::repeat_n(b'A', rng.below(100_000)));
                continue;
            }
        };
        out.extend(frame(body.as_bytes()));
    }
    out
}

/// The first `n` bytes of `s` or fewer, on a character boundary.
fn prefix(s: &str, n: usize) -> &str {
    let mut n = n.min(s.len());
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    &s[..n]
}

/// `s` as a JSON string literal.
fn serde_json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
