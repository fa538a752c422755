//! `lensc lsp` end to end: the real binary started as an editor starts
//! it, spoken to in JSON-RPC over its stdin and stdout (initialize,
//! initialized, didOpen, didChange, publishDiagnostics, hover, completion,
//! definition, formatting, shutdown, exit), every answer checked.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

use serde_json::{Value, json};

use crate::common::{lensc, root};

const JOB: &str = r#"// A µ-turning job: the µ and ° before later spans test UTF-16 columns.
use std::machines::linuxcnc_lathe
use "common.lens"

let depth = 2 * 5 um + margin

surface lens = conic {
    radius: 22.405 mm
    conic: -1
    sense: convex
    aperture: circle(radius: 1.6 mm)
}

tool knife = round_nose { nose_radius: 85 µm, clearance: 10° }

machine lathe1 = linuxcnc_lathe { resolution: 2 nm }

strategy pass = profile_turning {
    feed: 20 um/s
    spindle_speed: 1000 rpm
    chord_tolerance: depth
}

job j { surface: lens, tool: knife, machine: lathe1, strategy: pass }
"#;

const COMMON: &str = "// Shared figures.\nlet margin = 3 um\n";

/// An editor's end of the connection.
struct Client {
    child: Child,
    stdin: ChildStdin,
    incoming: Receiver<Value>,
    next_id: i64,
}

impl Client {
    fn start(cwd: &Path, cache: &Path) -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_lensc"))
            .arg("lsp")
            .current_dir(cwd)
            .env("XDG_CACHE_HOME", cache)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start lensc lsp");
        let stdin = child.stdin.take().expect("stdin");
        let mut out = BufReader::new(child.stdout.take().expect("stdout"));
        let (tx, incoming) = channel();
        std::thread::spawn(move || {
            loop {
                // Headers up to a blank line, then Content-Length bytes.
                let mut length = None;
                loop {
                    let mut line = String::new();
                    if out.read_line(&mut line).unwrap_or(0) == 0 {
                        return;
                    }
                    let line = line.trim_end();
                    if line.is_empty() {
                        break;
                    }
                    if let Some(n) = line.strip_prefix("Content-Length: ") {
                        length = n.parse::<usize>().ok();
                    }
                }
                let mut body = vec![0; length.expect("a Content-Length header")];
                out.read_exact(&mut body).expect("a message body");
                let msg: Value = serde_json::from_slice(&body).expect("JSON");
                if tx.send(msg).is_err() {
                    return;
                }
            }
        });
        Client {
            child,
            stdin,
            incoming,
            next_id: 1,
        }
    }

    fn send(&mut self, msg: Value) {
        let body = msg.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("write");
        self.stdin.flush().expect("flush");
    }

    /// Writes bytes as they are, framed or not.
    fn raw(&mut self, bytes: &[u8]) {
        // The server may have read what it needs and moved on: a write
        // into a closed pipe is the test's concern only when the server
        // died, which the answers awaited show.
        let _ = self.stdin.write_all(bytes);
        let _ = self.stdin.flush();
    }

    /// Sends a request and returns the whole answer, result or error.
    fn answer(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let msg = self.next();
            if msg["id"] == json!(id) {
                return msg;
            }
        }
    }

    /// The next message that is not a notification.
    fn next_answer(&mut self) -> Value {
        loop {
            let msg = self.next();
            if msg.get("method").is_none() {
                return msg;
            }
        }
    }

    fn initialize(&mut self, work: &Path) {
        self.request(
            "initialize",
            json!({"processId": null, "rootUri": uri_of(work), "capabilities": {}}),
        );
        self.notify("initialized", json!({}));
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    /// Sends a request and returns its result (notifications on the way
    /// are passed over).
    fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let msg = self.next();
            if msg["id"] == json!(id) {
                assert!(msg.get("error").is_none(), "{method}: {msg}");
                return msg["result"].clone();
            }
        }
    }

    /// The next diagnostics published for `uri`.
    fn diagnostics(&mut self, uri: &str) -> Vec<Value> {
        loop {
            let msg = self.next();
            if msg["method"] == "textDocument/publishDiagnostics" && msg["params"]["uri"] == uri {
                return msg["params"]["diagnostics"]
                    .as_array()
                    .expect("a list")
                    .clone();
            }
        }
    }

    fn next(&mut self) -> Value {
        self.incoming
            .recv_timeout(Duration::from_secs(60))
            .expect("an answer from lensc lsp within a minute")
    }
}

fn uri_of(p: &Path) -> String {
    format!("file://{}", p.display())
}

/// The protocol position of the `n`th (0-based) occurrence of `needle`
/// in `text`, plus `plus` characters: its line, and its column in UTF-16
/// code units, counted here independently of the server.
fn pos(text: &str, needle: &str, n: usize, plus: usize) -> Value {
    let at = text.match_indices(needle).nth(n).expect(needle).0;
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let line = text[..at].matches('\n').count();
    let col = text[line_start..at].encode_utf16().count() + plus;
    json!({"line": line, "character": col})
}

fn at(uri: &str, p: Value) -> Value {
    json!({"textDocument": {"uri": uri}, "position": p})
}

fn hover_text(c: &mut Client, uri: &str, p: Value) -> String {
    let h = c.request("textDocument/hover", at(uri, p));
    h["contents"]["value"].as_str().unwrap_or("").to_string()
}

fn labels(v: &Value) -> Vec<String> {
    v.as_array()
        .expect("a completion list")
        .iter()
        .map(|i| i["label"].as_str().expect("a label").to_string())
        .collect()
}

#[test]
fn an_editor_session() {
    let dir = tempfile::tempdir().expect("tempdir");
    let work = dir.path().canonicalize().expect("dir").join("work");
    let cache = dir.path().join("cache");
    std::fs::create_dir_all(&work).expect("mkdir");
    std::fs::write(work.join("job.lens"), JOB).expect("write");
    std::fs::write(work.join("common.lens"), COMMON).expect("write");
    let uri = uri_of(&work.join("job.lens"));

    let mut c = Client::start(&work, &cache);
    let init = c.request(
        "initialize",
        json!({"processId": null, "rootUri": uri_of(&work), "capabilities": {}}),
    );
    let caps = &init["capabilities"];
    assert_eq!(caps["hoverProvider"], json!(true), "{init}");
    assert_eq!(caps["definitionProvider"], json!(true));
    assert_eq!(caps["documentFormattingProvider"], json!(true));
    assert_eq!(init["serverInfo"]["name"], "lensc");
    c.notify("initialized", json!({}));

    // The file as saved checks clean.
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": JOB}}),
    );
    assert_eq!(c.diagnostics(&uri), Vec::<Value>::new());

    // Typing `s` over the `m` of `85 µm`: an incremental change whose
    // column counts `µ` as one UTF-16 unit. The checker's E0122 comes
    // back at `85 µs`, its columns in UTF-16 too.
    let m = pos(JOB, "µm,", 0, 1);
    let end = json!({"line": m["line"], "character": m["character"].as_u64().expect("col") + 1});
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2},
               "contentChanges": [{"range": {"start": m, "end": end}, "text": "s"}]}),
    );
    let d = c.diagnostics(&uri);
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0]["code"], "E0122");
    assert_eq!(d[0]["severity"], 1);
    assert_eq!(d[0]["source"], "lensc");
    assert!(
        d[0]["message"]
            .as_str()
            .expect("message")
            .contains("`nose_radius` must be a length, but this is a time"),
        "{}",
        d[0]["message"]
    );
    let bad = JOB.replace("85 µm", "85 µs");
    assert_eq!(d[0]["range"]["start"], pos(&bad, "85 µs", 0, 0));
    assert_eq!(d[0]["range"]["end"], pos(&bad, "85 µs", 0, 5));

    // A whole-text change back: clean again.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 3}, "contentChanges": [{"text": JOB}]}),
    );
    assert_eq!(c.diagnostics(&uri), Vec::<Value>::new());

    // Hover: a parameter (documentation, dimension, unit, range), a kind,
    // a `let`'s evaluated value with its unit, a standard-library item.
    let h = hover_text(&mut c, &uri, pos(JOB, "nose_radius", 0, 2));
    assert!(
        h.contains("**nose_radius**: a length, in mm, > 0, required"),
        "{h}"
    );
    assert!(h.contains("radius of the cutting edge's nose"), "{h}");
    let h = hover_text(&mut c, &uri, pos(JOB, "conic {", 0, 1));
    assert!(h.starts_with("**conic** — a surface, built-in kind"), "{h}");
    assert!(h.contains("- `radius`:"), "{h}");
    let h = hover_text(&mut c, &uri, pos(JOB, "depth", 1, 1));
    assert!(h.contains("let depth = 0.013 mm"), "{h}");
    assert!(h.contains("a length"), "{h}");
    let h = hover_text(&mut c, &uri, pos(JOB, "linuxcnc_lathe {", 0, 3));
    assert!(h.contains("of the standard library"), "{h}");
    assert!(h.contains("`use std::machines::linuxcnc_lathe`"), "{h}");
    let h = hover_text(&mut c, &uri, pos(JOB, "µm,", 0, 1));
    assert!(h.contains("a unit of a length: 1 µm = 0.001 mm"), "{h}");

    // Completion: a block's parameters not yet given, after typing a line.
    let typed = JOB.replace(
        "    chord_tolerance: depth\n",
        "    chord_tolerance: depth\n    \n",
    );
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 4}, "contentChanges": [{"text": typed}]}),
    );
    c.diagnostics(&uri);
    let empty = typed
        .lines()
        .position(|l| l == "    ")
        .expect("the new line");
    let l = labels(&c.request(
        "textDocument/completion",
        at(&uri, json!({"line": empty, "character": 4})),
    ));
    assert!(!l.contains(&"feed".to_string()), "`feed` is given: {l:?}");
    assert!(!l.contains(&"spindle_speed".to_string()), "{l:?}");
    let profile = lensc_lang::schema::kind("profile_turning").expect("kind");
    for p in profile.params {
        if !["feed", "spindle_speed", "chord_tolerance"].contains(&p.name) {
            assert!(l.contains(&p.name.to_string()), "{} missing: {l:?}", p.name);
        }
    }
    // Standard-library modules after `use std::`, a module's items after
    // `use std::machines::`, units after a number, kinds in a value.
    let typed = format!("use std::\n{JOB}");
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 5}, "contentChanges": [{"text": typed}]}),
    );
    c.diagnostics(&uri);
    let l = labels(&c.request(
        "textDocument/completion",
        at(&uri, json!({"line": 0, "character": 9})),
    ));
    assert_eq!(l, ["machines", "tools", "strategies", "dialects"]);
    let typed = format!("use std::machines::\n{JOB}");
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 6}, "contentChanges": [{"text": typed}]}),
    );
    c.diagnostics(&uri);
    let l = labels(&c.request(
        "textDocument/completion",
        at(&uri, json!({"line": 0, "character": 19})),
    ));
    assert!(l.contains(&"linuxcnc_lathe".to_string()), "{l:?}");
    assert!(!l.contains(&"fanuc".to_string()), "{l:?}");
    let l = labels(&c.request(
        "textDocument/completion",
        at(&uri, pos(&typed, "85 ", 0, 3)),
    ));
    for u in ["um", "µm", "mm", "nm", "deg", "rpm"] {
        assert!(l.contains(&u.to_string()), "{u}: {l:?}");
    }
    let l = labels(&c.request(
        "textDocument/completion",
        at(&uri, pos(&typed, "conic {", 0, 0)),
    ));
    // A surface's value: the surface kinds, not the `let`s or functions
    // (a slot of one category offers that category only).
    assert!(
        l.contains(&"asphere".to_string())
            && !l.contains(&"depth".to_string())
            && !l.contains(&"sin".to_string()),
        "{l:?}"
    );
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 7}, "contentChanges": [{"text": JOB}]}),
    );
    c.diagnostics(&uri);

    // Go to definition: into the standard library (written to the cache
    // directory) and across a `use` of another file.
    let def = c.request(
        "textDocument/definition",
        at(&uri, pos(JOB, "linuxcnc_lathe {", 0, 2)),
    );
    let target = def["uri"].as_str().expect("a location");
    let path = target.strip_prefix("file://").expect("a file");
    assert!(Path::new(path).starts_with(&cache), "{target}");
    let std_text = std::fs::read_to_string(path).expect("the stdlib copy");
    assert_eq!(
        std_text,
        std::fs::read_to_string(root().join("stdlib/machines.lens")).expect("stdlib")
    );
    let line = def["range"]["start"]["line"].as_u64().expect("line") as usize;
    assert!(
        std_text
            .lines()
            .nth(line)
            .expect("line")
            .contains("machine linuxcnc_lathe ="),
        "{def}"
    );
    let def = c.request(
        "textDocument/definition",
        at(&uri, pos(JOB, "margin", 0, 1)),
    );
    assert_eq!(def["uri"], uri_of(&work.join("common.lens")));
    assert_eq!(def["range"]["start"], json!({"line": 1, "character": 4}));
    let def = c.request("textDocument/definition", at(&uri, pos(JOB, "depth", 1, 0)));
    assert_eq!(def["uri"], uri);
    assert_eq!(def["range"]["start"], pos(JOB, "depth", 0, 0));

    // Formatting answers what `lensc fmt` writes.
    let messy = "tool t = round_nose{nose_radius:85 um,clearance:7 deg}\n";
    std::fs::write(work.join("messy.lens"), messy).expect("write");
    let messy_uri = uri_of(&work.join("messy.lens"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": messy_uri, "languageId": "lens", "version": 1, "text": messy}}),
    );
    c.diagnostics(&messy_uri);
    let out = lensc(&work, &["fmt", "messy.lens"]);
    assert!(out.status.success());
    let formatted = std::fs::read_to_string(work.join("messy.lens")).expect("read");
    assert_ne!(formatted, messy);
    let edits = c.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": messy_uri}, "options": {"tabSize": 4, "insertSpaces": true}}),
    );
    assert_eq!(edits.as_array().map(Vec::len), Some(1), "{edits}");
    assert_eq!(edits[0]["newText"], formatted);
    assert_eq!(
        edits[0]["range"]["start"],
        json!({"line": 0, "character": 0})
    );
    assert_eq!(edits[0]["range"]["end"], json!({"line": 1, "character": 0}));

    let r = c.request("shutdown", Value::Null);
    assert_eq!(r, Value::Null);
    c.notify("exit", Value::Null);
    let status = c.child.wait().expect("wait");
    assert!(status.success(), "{status}");
}

/// What `lensc check` finds only by lowering the jobs (here W0006, a
/// wrapped design open at the roller's seam) shows when the document is
/// opened and saved, stays while it is edited (moved with the edits), is
/// found again after a pause in typing, and goes after the pause that
/// follows the edit that mends it, unsaved (issue #32: it vanished at the
/// next keystroke).
#[test]
fn lowering_findings_are_kept_while_typing_and_renewed_after_a_pause() {
    let dir = tempfile::tempdir().expect("tempdir");
    let work = dir.path().canonicalize().expect("dir").join("work");
    let cache = dir.path().join("cache");
    std::fs::create_dir_all(&work).expect("mkdir");
    let open =
        std::fs::read_to_string(root().join("tests/bad_builds/roller_design_open_at_seam.lens"))
            .expect("the bad build");
    std::fs::write(work.join("seam.lens"), &open).expect("write");
    let uri = uri_of(&work.join("seam.lens"));
    let codes = |d: &[Value]| -> Vec<String> {
        d.iter()
            .map(|v| v["code"].as_str().expect("a code").to_string())
            .collect()
    };

    let mut c = Client::start(&work, &cache);
    let init = c.request(
        "initialize",
        json!({"processId": null, "rootUri": uri_of(&work), "capabilities": {}}),
    );
    assert_eq!(
        init["capabilities"]["textDocumentSync"]["save"],
        json!(true),
        "{init}"
    );
    c.notify("initialized", json!({}));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": open}}),
    );
    let d = c.diagnostics(&uri);
    assert_eq!(codes(&d), ["W0006"], "{d:?}");
    assert_eq!(d[0]["severity"], 2);
    let job = pos(&open, "j {", 0, 0);
    assert_eq!(d[0]["range"]["start"], job);

    // Typing (an edit of a few bytes): the last lowering's finding is
    // kept, moved with the edit, at once...
    let typed = format!("// edited\n{open}");
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [{
            "range": {"start": {"line": 0, "character": 0}, "end": {"line": 0, "character": 0}},
            "text": "// edited\n"}]}),
    );
    let d = c.diagnostics(&uri);
    assert_eq!(codes(&d), ["W0006"], "{d:?}");
    assert_eq!(d[0]["range"]["start"], pos(&typed, "j {", 0, 0));
    // ...and found again by lowering after a pause in typing, unsaved.
    let d = c.diagnostics(&uri);
    assert_eq!(codes(&d), ["W0006"], "{d:?}");
    assert_eq!(d[0]["range"]["start"], pos(&typed, "j {", 0, 0));
    // Saved: lowered again, at the job's new place.
    c.notify(
        "textDocument/didSave",
        json!({"textDocument": {"uri": uri}}),
    );
    let d = c.diagnostics(&uri);
    assert_eq!(codes(&d), ["W0006"], "{d:?}");
    assert_eq!(d[0]["range"]["start"], pos(&typed, "j {", 0, 0));

    // A whole number of periods around the roller: kept until the pause's
    // lowering finds nothing, unsaved.
    let closed = typed.replace("sin(1 rad/mm * y)", "sin(1.0471975511965976 rad/mm * y)");
    assert_ne!(closed, typed);
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 3}, "contentChanges": [{"text": closed}]}),
    );
    assert_eq!(codes(&c.diagnostics(&uri)), ["W0006"]);
    assert_eq!(codes(&c.diagnostics(&uri)), Vec::<String>::new());

    let r = c.request("shutdown", Value::Null);
    assert_eq!(r, Value::Null);
    c.notify("exit", Value::Null);
    assert!(c.child.wait().expect("wait").success());
}

/// Completion in a slot that takes a machine (issue #32: it offered 79
/// items, surfaces and functions among them) offers only machines: the
/// document's own, the machine kinds and the standard library's; picking
/// a standard-library machine not yet in scope adds its `use` line.
#[test]
fn completion_in_a_machine_slot_offers_machines_and_adds_the_use() {
    let (_dir, work, mut c) = session();
    let text = "// a job in the making\nuse std::tools::diamond_r500um\nsurface lens = sphere { radius: 20 mm, sense: convex, aperture: 5 mm }\nmachine mine = lathe { resolution: 1 nm }\nmachine m2 = \njob j { surface: lens, tool: diamond_r500um, machine: m }\n";
    std::fs::write(work.join("c.lens"), text).expect("write");
    let uri = uri_of(&work.join("c.lens"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": text}}),
    );
    c.diagnostics(&uri);
    let machines: Vec<String> = lensc_lang::stdlib::items()
        .iter()
        .filter(|i| i.module == "machines")
        .map(|i| i.name.clone())
        .collect();
    assert!(machines.len() >= 3, "{machines:?}");
    for (what, p) in [
        ("after `machine m2 =`", pos(text, "m2 = ", 0, 5)),
        ("in `machine:`", pos(text, "machine: m", 0, 10)),
    ] {
        let items = c.request("textDocument/completion", at(&uri, p));
        let got = labels(&items);
        for m in &machines {
            assert!(got.contains(m), "{what}: no {m} in {got:?}");
        }
        assert!(got.contains(&"mine".to_string()), "{what}: {got:?}");
        for not in ["sphere", "lens", "sin", "diamond_r500um", "raster"] {
            assert!(!got.contains(&not.to_string()), "{what}: {not} in {got:?}");
        }
        assert!(got.len() < 30, "{what}: {} items", got.len());
        // The standard library's machine brings its `use` line, after the
        // file's own `use`.
        let lathe = items
            .as_array()
            .expect("items")
            .iter()
            .find(|i| i["label"] == machines[0].as_str())
            .expect("a stdlib machine");
        let edit = &lathe["additionalTextEdits"][0];
        assert_eq!(
            edit["newText"],
            format!("use std::machines::{}\n", machines[0]),
            "{what}: {lathe}"
        );
        assert_eq!(
            edit["range"]["start"],
            json!({"line": 2, "character": 0}),
            "{what}"
        );
    }
}

/// The outline, references and rename across a `use`d file, and the
/// quick fixes lensc's diagnostics carry (issue #32: each answered
/// -32601, method not found).
#[test]
fn outline_references_rename_and_quick_fixes() {
    let (_dir, work, mut c) = session();
    std::fs::write(work.join("job.lens"), JOB).expect("write");
    std::fs::write(work.join("common.lens"), COMMON).expect("write");
    let uri = uri_of(&work.join("job.lens"));
    let common = uri_of(&work.join("common.lens"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": JOB}}),
    );
    c.diagnostics(&uri);

    // The outline: each item by name, the job with its entries.
    let outline = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri}}),
    );
    let names: Vec<&str> = outline
        .as_array()
        .expect("symbols")
        .iter()
        .map(|s| s["name"].as_str().expect("a name"))
        .collect();
    assert_eq!(
        names,
        ["depth", "lens", "knife", "lathe1", "pass", "j"],
        "{outline}"
    );
    let job = &outline[5];
    assert_eq!(
        job["children"].as_array().expect("entries").len(),
        4,
        "{job}"
    );
    assert_eq!(job["selectionRange"]["start"], pos(JOB, "j {", 0, 0));

    // References to `margin`, declared in common.lens: its declaration
    // there and its use here.
    let refs = c.request(
        "textDocument/references",
        json!({"textDocument": {"uri": uri}, "position": pos(JOB, "margin", 0, 1),
               "context": {"includeDeclaration": true}}),
    );
    let mut got: Vec<(String, Value)> = refs
        .as_array()
        .expect("locations")
        .iter()
        .map(|l| {
            (
                l["uri"].as_str().expect("uri").to_string(),
                l["range"]["start"].clone(),
            )
        })
        .collect();
    got.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        got,
        [
            (common.clone(), pos(COMMON, "margin", 0, 0)),
            (uri.clone(), pos(JOB, "margin", 0, 0)),
        ],
        "{refs}"
    );

    // Rename `depth` (declared and used here): both places.
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(JOB, "depth", 1, 0), "newName": "cut_depth"}),
    );
    let edits = edit["changes"][uri.as_str()]
        .as_array()
        .expect("edits")
        .clone();
    let starts: Vec<Value> = edits.iter().map(|e| e["range"]["start"].clone()).collect();
    assert_eq!(
        starts,
        [pos(JOB, "depth", 0, 0), pos(JOB, "depth", 1, 0)],
        "{edit}"
    );
    assert!(edits.iter().all(|e| e["newText"] == "cut_depth"));
    // A taken name, a word that is not a name, a standard-library item.
    for (at, new, why) in [
        (pos(JOB, "depth", 1, 0), "knife", "already a name"),
        (pos(JOB, "depth", 1, 0), "2cut", "not a name"),
        (
            pos(JOB, "linuxcnc_lathe", 0, 2),
            "my_lathe",
            "standard library",
        ),
    ] {
        let answer = c.answer(
            "textDocument/rename",
            json!({"textDocument": {"uri": uri}, "position": at, "newName": new}),
        );
        let message = answer["error"]["message"]
            .as_str()
            .unwrap_or_default()
            .to_string();
        assert!(message.contains(why), "{new}: {answer}");
    }

    // Quick fixes: a unit mistyped, a standard-library machine not used.
    let typed = JOB
        .replace("85 µm", "85 umm")
        .replace("use std::machines::linuxcnc_lathe\n", "");
    assert_ne!(typed, JOB);
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [{"text": typed}]}),
    );
    let diags = c.diagnostics(&uri);
    let actions = c.request(
        "textDocument/codeAction",
        json!({"textDocument": {"uri": uri}, "range": {"start": {"line": 0, "character": 0}, "end": {"line": 0, "character": 0}},
               "context": {"diagnostics": diags}}),
    );
    let titles: Vec<&str> = actions
        .as_array()
        .expect("actions")
        .iter()
        .map(|a| a["title"].as_str().expect("a title"))
        .collect();
    assert!(
        titles.iter().any(|t| t.contains("write `mm`")),
        "{titles:?} {diags:?}"
    );
    assert!(
        titles
            .iter()
            .any(|t| t.contains("add `use std::machines::linuxcnc_lathe`")),
        "{titles:?} {diags:?}"
    );
}

/// Hover on an acceptance criterion inside `accept { }` (issue #32: it
/// said nothing) and on a standard-library machine (its travel and
/// limits were left out).
#[test]
fn hover_on_criteria_and_a_machines_limits() {
    let (_dir, work, mut c) = session();
    let text = JOB.replace(
        "job j { surface: lens, tool: knife, machine: lathe1, strategy: pass }",
        "job j {\n    surface: lens\n    tool: knife\n    machine: lathe1\n    strategy: pass\n    accept: { form_pv: 50 nm, max_gouge: 20 nm }\n}",
    );
    assert_ne!(text, JOB);
    std::fs::write(work.join("a.lens"), &text).expect("write");
    std::fs::write(work.join("common.lens"), COMMON).expect("write");
    let uri = uri_of(&work.join("a.lens"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": text}}),
    );
    c.diagnostics(&uri);
    let h = hover_text(&mut c, &uri, pos(&text, "form_pv", 0, 2));
    assert!(
        h.contains("**form_pv**") && h.contains("peak-to-valley"),
        "{h}"
    );
    let h = hover_text(&mut c, &uri, pos(&text, "max_gouge", 0, 1));
    assert!(h.contains("deepest cut below the design"), "{h}");
    let h = hover_text(&mut c, &uri, pos(&text, "linuxcnc_lathe {", 0, 3));
    assert!(h.contains("travel:") && h.contains("max_feed:"), "{h}");
}

/// A session for the malformed-input tests: its directory kept alive.
fn session() -> (tempfile::TempDir, std::path::PathBuf, Client) {
    let dir = tempfile::tempdir().expect("tempdir");
    let work = dir.path().canonicalize().expect("dir").join("work");
    let cache = dir.path().join("cache");
    std::fs::create_dir_all(&work).expect("mkdir");
    let mut c = Client::start(&work, &cache);
    c.initialize(&work);
    (dir, work, c)
}

/// Every kind of frame that is not a JSON-RPC message, each followed by a
/// good request: the bad frame is answered with an error (a parse error,
/// -32700, or an invalid request, -32600, with the id when it has one) and
/// the request after it is answered as usual. Lengths of a tebibyte and
/// 2 GiB cost nothing (the server neither allocates nor waits for them),
/// nor does a header line with no end.
#[test]
fn every_malformed_frame_is_answered_and_the_server_stays_up() {
    let (_dir, _work, mut c) = session();
    let framed = |body: &str| format!("Content-Length: {}\r\n\r\n{body}", body.len()).into_bytes();
    let mut endless = vec![b'A'; 1 << 20];
    endless.extend_from_slice(b"\r\n\r\n");
    let cases: Vec<(&str, Vec<u8>, Value, i64)> = vec![
        (
            "a tebibyte",
            b"Content-Length: 1099511627776\r\n\r\n".to_vec(),
            Value::Null,
            -32600,
        ),
        (
            "2 GiB",
            b"Content-Length: 2147483648\r\n\r\n{".to_vec(),
            Value::Null,
            -32600,
        ),
        (
            "negative",
            b"Content-Length: -40\r\n\r\n{}".to_vec(),
            Value::Null,
            -32700,
        ),
        (
            "missing",
            b"Content-Type: application/json\r\n\r\n{}".to_vec(),
            Value::Null,
            -32700,
        ),
        ("endless header line", endless, Value::Null, -32700),
        (
            "not JSON",
            framed("{\"jsonrpc\": 2.0, oops"),
            Value::Null,
            -32700,
        ),
        ("an array", framed("[1, 2]"), Value::Null, -32600),
        (
            "no jsonrpc",
            framed(r#"{"id": 5, "method": "textDocument/hover"}"#),
            json!(5),
            -32600,
        ),
        (
            "no method",
            framed(r#"{"jsonrpc": "2.0", "id": "six"}"#),
            json!("six"),
            -32600,
        ),
        (
            "a method not a string",
            framed(r#"{"jsonrpc": "2.0", "id": 7, "method": 7}"#),
            json!(7),
            -32600,
        ),
    ];
    for (what, bytes, id, code) in cases {
        c.raw(&bytes);
        let e = c.next_answer();
        assert_eq!(e["id"], id, "{what}: {e}");
        assert_eq!(e["error"]["code"], json!(code), "{what}: {e}");
        // The server is still there and in step.
        let a = c.answer("lensc/nothing", json!({}));
        assert_eq!(a["error"]["code"], json!(-32601), "{what}: {a}");
    }
    let r = c.request("shutdown", Value::Null);
    assert_eq!(r, Value::Null);
    c.notify("exit", Value::Null);
    assert!(c.child.wait().expect("wait").success());
}

/// After `shutdown` every request is an invalid request (-32600) until
/// `exit`, which then ends the server with 0; `exit` without `shutdown`
/// ends it with 1, as the protocol says.
#[test]
fn shutdown_then_exit() {
    let (_dir, work, mut c) = session();
    let uri = uri_of(&work.join("a.lens"));
    let r = c.request("shutdown", Value::Null);
    assert_eq!(r, Value::Null);
    for method in ["textDocument/hover", "shutdown", "initialize"] {
        let a = c.answer(
            method,
            json!({"textDocument": {"uri": uri}, "position": {"line": 0, "character": 0}}),
        );
        assert_eq!(a["error"]["code"], json!(-32600), "{method}: {a}");
    }
    c.notify("exit", Value::Null);
    assert_eq!(c.child.wait().expect("wait").code(), Some(0));

    let (_dir, _work, mut c) = session();
    c.notify("exit", Value::Null);
    assert_eq!(c.child.wait().expect("wait").code(), Some(1));
}

/// A document over the 16 MiB a file may have is refused as `lensc check`
/// refuses the file (E0109) and its text is not kept; a whole new text
/// within the limit is checked again.
#[test]
fn a_document_over_the_file_limit_is_refused() {
    let (_dir, work, mut c) = session();
    let uri = uri_of(&work.join("big.lens"));
    let big = format!(
        "let a = 1 mm\n{}",
        "// padding\n".repeat(17 << 20 >> 4 << 1)
    );
    assert!(big.len() > 16 << 20 && big.len() < 2 * (16 << 20));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "lens", "version": 1, "text": big}}),
    );
    let d = c.diagnostics(&uri);
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0]["code"], "E0109", "{d:?}");
    // An edit inside it has nothing to edit; a whole small text is checked.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [
            {"range": {"start": {"line": 0, "character": 0}, "end": {"line": 0, "character": 0}}, "text": "x"},
            {"text": "let a = 1 mm +\n"},
        ]}),
    );
    let d = c.diagnostics(&uri);
    assert!(
        !d.is_empty() && d.iter().all(|d| d["code"] != "E0109"),
        "{d:?}"
    );
    let r = c.request("shutdown", Value::Null);
    assert_eq!(r, Value::Null);
    c.notify("exit", Value::Null);
    assert!(c.child.wait().expect("wait").success());
}
