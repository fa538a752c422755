//! `lensc lsp`: a language server over stdin and stdout (JSON-RPC, the
//! Language Server Protocol; types `lsp-types`, the transport its own in
//! `transport`: bounded, and answering every malformed frame).
//! It keeps the documents the editor has open, checks each as it changes
//! and publishes the checker's diagnostics with their codes, and what
//! lowering its jobs finds, as `lensc check` reports it: when a document
//! is opened or saved, and after a pause in typing (`PAUSE`; the last
//! lowering's findings are kept meanwhile, moved with the edits, and a
//! message from the editor cancels a lowering not yet started). It answers
//! hover, completion, go to definition, formatting (`lensc fmt`'s
//! layout), the outline, references and rename (`symbols`) and the quick
//! fixes the diagnostics carry (`actions`). Positions are the protocol's UTF-16 columns (`text`); what the
//! cursor is on is read from the text (`context`) and the checker's own
//! tables (`lookup`); the standard library's files are written to a cache
//! directory for an editor to open (`analysis::stdlib_dir`).
//!
//! This file holds the message loop and the dispatch; one file per answer.

mod actions;
mod analysis;
mod completion;
mod context;
mod definition;
mod hover;
mod lookup;
mod symbols;
mod text;
mod transport;

use std::collections::{BTreeSet, HashMap};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Duration;

use lsp_types::notification::{self as note, Notification as _};
use lsp_types::request::{self as req, Request as _};
use lsp_types::{self as lsp, Uri};
use serde::de::DeserializeOwned;
use serde_json::Value;

use analysis::{Analysis, Docs, Document};
use text::LineIndex;
use transport::{Frame, Message};

/// Runs the server until the editor says `exit` (or closes its end);
/// returns the exit code: 0 after `shutdown`, else 1, as the protocol
/// says.
pub fn run() -> u8 {
    let stdout = std::io::stdout();
    let mut writer = transport::Writer::new(stdout.lock());
    // Frames are read on their own thread, so the loop can tell a pause in
    // typing (no frame for `PAUSE`) and whether a frame is waiting.
    let incoming = Incoming::start(std::io::BufReader::new(std::io::stdin()));
    match serve(&incoming, &mut writer) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("lensc lsp: {e}");
            1
        }
    }
}

fn capabilities() -> lsp::ServerCapabilities {
    lsp::ServerCapabilities {
        position_encoding: Some(lsp::PositionEncodingKind::UTF16),
        text_document_sync: Some(lsp::TextDocumentSyncCapability::Options(
            lsp::TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(lsp::TextDocumentSyncKind::INCREMENTAL),
                save: Some(lsp::TextDocumentSyncSaveOptions::Supported(true)),
                ..Default::default()
            },
        )),
        hover_provider: Some(lsp::HoverProviderCapability::Simple(true)),
        completion_provider: Some(lsp::CompletionOptions {
            trigger_characters: Some(vec![":".into()]),
            ..Default::default()
        }),
        definition_provider: Some(lsp::OneOf::Left(true)),
        document_formatting_provider: Some(lsp::OneOf::Left(true)),
        document_symbol_provider: Some(lsp::OneOf::Left(true)),
        references_provider: Some(lsp::OneOf::Left(true)),
        rename_provider: Some(lsp::OneOf::Left(true)),
        code_action_provider: Some(lsp::CodeActionProviderCapability::Simple(true)),
        ..Default::default()
    }
}

/// How long the editor must send nothing before the jobs of documents
/// changed since they were last lowered are lowered again.
const PAUSE: Duration = Duration::from_millis(300);

/// The frames the editor sends, read on a thread of their own, with a
/// count of those sent and not yet taken (a frame waiting cancels the
/// lowering that has not started).
struct Incoming {
    frames: Receiver<std::io::Result<Frame>>,
    waiting: Arc<AtomicUsize>,
}

impl Incoming {
    fn start<R: std::io::BufRead + Send + 'static>(input: R) -> Incoming {
        let (tx, frames) = std::sync::mpsc::channel();
        let waiting = Arc::new(AtomicUsize::new(0));
        let count = waiting.clone();
        let _ = std::thread::Builder::new()
            .name("lsp-reader".into())
            .spawn(move || {
                let mut reader = transport::Reader::new(input);
                loop {
                    let frame = reader.read();
                    let last = matches!(frame, Ok(Frame::Eof) | Err(_));
                    count.fetch_add(1, Ordering::SeqCst);
                    if tx.send(frame).is_err() || last {
                        break;
                    }
                }
            });
        Incoming { frames, waiting }
    }

    /// The next frame, or `None` if `pause` passed with none (no pause:
    /// wait for one).
    fn next(&self, pause: Option<Duration>) -> Option<std::io::Result<Frame>> {
        let frame = match pause {
            None => self.frames.recv().unwrap_or(Ok(Frame::Eof)),
            Some(p) => match self.frames.recv_timeout(p) {
                Ok(f) => f,
                Err(RecvTimeoutError::Timeout) => return None,
                Err(RecvTimeoutError::Disconnected) => Ok(Frame::Eof),
            },
        };
        self.waiting.fetch_sub(1, Ordering::SeqCst);
        Some(frame)
    }

    /// Whether a frame has come that the loop has not taken.
    fn pending(&self) -> bool {
        self.waiting.load(Ordering::SeqCst) > 0
    }
}

/// Where the session is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// Before `initialize`: requests answered "not initialized".
    Waiting,
    Running,
    /// After `shutdown`: requests answered "invalid request" until `exit`.
    ShutDown,
}

/// The message loop; the exit code once the editor says `exit` or closes
/// its end.
fn serve<W: std::io::Write>(
    incoming: &Incoming,
    writer: &mut transport::Writer<W>,
) -> std::io::Result<u8> {
    let mut state = State::Waiting;
    let mut server = Server {
        docs: HashMap::new(),
        analyses: HashMap::new(),
        stale: BTreeSet::new(),
        root: None,
    };
    loop {
        let pause = (state == State::Running && !server.stale.is_empty()).then_some(PAUSE);
        let Some(frame) = incoming.next(pause) else {
            // A pause in typing: lower what changed, unless the editor
            // has sent something meanwhile.
            let lowered = guarded(|| server.lower_stale(|| incoming.pending()));
            // A lowering that panicked is not tried again until the next
            // change (its answer is lost, never the session).
            let Some(lowered) = lowered else {
                server.stale.clear();
                continue;
            };
            for (uri, diags) in lowered {
                writer.notify(note::PublishDiagnostics::METHOD, publish(uri, diags))?;
            }
            continue;
        };
        let (id, method, params) = match frame? {
            Frame::Eof => return Ok(if state == State::ShutDown { 0 } else { 1 }),
            Frame::Malformed { id, code, message } => {
                writer.error(id, code, &message)?;
                continue;
            }
            Frame::Message(Message::Response) => continue,
            Frame::Message(Message::Notification { method, params }) => (None, method, params),
            Frame::Message(Message::Request { id, method, params }) => (Some(id), method, params),
        };
        let Some(id) = id else {
            if method == note::Exit::METHOD {
                return Ok(if state == State::ShutDown { 0 } else { 1 });
            }
            if state == State::Running {
                for (uri, diags) in
                    guarded(|| server.notification(&method, params)).unwrap_or_default()
                {
                    writer.notify(note::PublishDiagnostics::METHOD, publish(uri, diags))?;
                }
            }
            continue;
        };
        match (state, method.as_str()) {
            (State::Waiting, req::Initialize::METHOD) => {
                match serde_json::from_value::<lsp::InitializeParams>(params) {
                    Ok(p) => {
                        server.root = workspace_root(&p);
                        state = State::Running;
                        writer.result(id, initialize_result())?;
                    }
                    Err(e) => writer.error(
                        id,
                        transport::INVALID_PARAMS,
                        &format!("bad initialize parameters: {e}"),
                    )?,
                }
            }
            (State::Waiting, _) => writer.error(
                id,
                transport::SERVER_NOT_INITIALIZED,
                "lensc lsp has not been initialized",
            )?,
            (State::ShutDown, _) => writer.error(
                id,
                transport::INVALID_REQUEST,
                "lensc lsp has been shut down: only `exit` is left",
            )?,
            (State::Running, req::Shutdown::METHOD) => {
                state = State::ShutDown;
                writer.result(id, Value::Null)?;
            }
            (State::Running, req::Initialize::METHOD) => writer.error(
                id,
                transport::INVALID_REQUEST,
                "lensc lsp is already initialized",
            )?,
            (State::Running, _) => match guarded(|| server.request(&method, params)) {
                Some(Ok(v)) => writer.result(id, v)?,
                Some(Err((code, message))) => writer.error(id, code, &message)?,
                None => writer.error(
                    id,
                    transport::INTERNAL_ERROR,
                    "lensc lsp failed on this request (a bug: please report it)",
                )?,
            },
        }
    }
}

fn initialize_result() -> Value {
    serde_json::to_value(lsp::InitializeResult {
        capabilities: capabilities(),
        server_info: Some(lsp::ServerInfo {
            name: "lensc".into(),
            version: Some(env!("CARGO_PKG_VERSION").into()),
        }),
    })
    .unwrap_or_default()
}

/// A bug that panics on one message costs that answer (an internal
/// error; the panic's message goes to stderr, the editor's log), never
/// the session.
fn guarded<T>(f: impl FnOnce() -> T) -> Option<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok()
}

/// The first workspace folder (or the root URI) the editor opened.
#[allow(deprecated)]
fn workspace_root(p: &lsp::InitializeParams) -> Option<PathBuf> {
    let folder = p
        .workspace_folders
        .as_ref()
        .and_then(|f| f.first())
        .map(|f| f.uri.clone())
        .or_else(|| p.root_uri.clone())?;
    analysis::document_path(&folder)
}

struct Server {
    docs: Docs,
    /// Each open document checked after its last change, by URI.
    analyses: HashMap<String, Analysis>,
    /// Documents whose jobs have changed since they were last lowered:
    /// lowered again after a pause in typing (`PAUSE`), their last
    /// lowering's findings shown meanwhile, moved with the edits.
    stale: BTreeSet<String>,
    root: Option<PathBuf>,
}

impl Server {
    /// What a notification changes: the diagnostics to publish, by
    /// document.
    fn notification(&mut self, method: &str, params: Value) -> Vec<(Uri, Vec<lsp::Diagnostic>)> {
        // Opening or saving lowers the jobs too (`Analysis::lower_jobs`).
        let lower = matches!(
            method,
            note::DidOpenTextDocument::METHOD | note::DidSaveTextDocument::METHOD
        );
        // The edits of a changed document (`None`: its whole text).
        let mut edited: Option<(String, Vec<Option<Edit>>)> = None;
        let changed = match method {
            note::DidOpenTextDocument::METHOD => parse::<lsp::DidOpenTextDocumentParams>(params)
                .map(|p| {
                    let uri = p.text_document.uri;
                    self.docs.insert(
                        uri.as_str().to_string(),
                        Document::new(uri, p.text_document.text),
                    );
                }),
            note::DidChangeTextDocument::METHOD => {
                parse::<lsp::DidChangeTextDocumentParams>(params).and_then(|p| {
                    let key = p.text_document.uri.as_str().to_string();
                    let doc = self.docs.get_mut(&key)?;
                    let mut edits = Vec::new();
                    for c in p.content_changes {
                        edits.push(apply_change(doc, c));
                    }
                    edited = Some((key, edits));
                    Some(())
                })
            }
            note::DidSaveTextDocument::METHOD => parse::<lsp::DidSaveTextDocumentParams>(params)
                .and_then(|p| self.docs.get(p.text_document.uri.as_str()).map(|_| ())),
            note::DidCloseTextDocument::METHOD => {
                if let Some(p) = parse::<lsp::DidCloseTextDocumentParams>(params) {
                    self.docs.remove(p.text_document.uri.as_str());
                    self.analyses.remove(p.text_document.uri.as_str());
                    self.stale.remove(p.text_document.uri.as_str());
                    return vec![(p.text_document.uri, Vec::new())];
                }
                None
            }
            _ => None,
        };
        if changed.is_none() {
            return Vec::new();
        }
        // A change can change what every other open document sees through
        // its `use`s: all are checked again (a handful, each in
        // milliseconds; lowered, when opening or saving, in at most a
        // few tenths of a second).
        let keys: Vec<String> = self.docs.keys().cloned().collect();
        let mut out = Vec::new();
        for k in keys {
            if let Some(mut a) = analysis::analyse(&self.docs, self.root.as_deref(), &k) {
                if lower {
                    a.lower_jobs();
                    self.stale.remove(&k);
                } else if let Some(previous) = self.analyses.remove(&k) {
                    // Kept until the next lowering says otherwise, moved
                    // with the edits (another document's change can change
                    // what this one's jobs see: lowered again too).
                    let edits = match &edited {
                        Some((key, edits)) if *key == k => edits.as_slice(),
                        _ => &[],
                    };
                    a.before_planning =
                        moved(previous.before_planning, edits, self.docs[&k].text.len());
                    self.stale.insert(k.clone());
                }
                let doc = &self.docs[&k];
                let diags = analysis::diagnostics(&a, &doc.uri, &doc.text);
                out.push((doc.uri.clone(), diags));
                self.analyses.insert(k, a);
            }
        }
        out
    }

    /// Lowers the jobs of the documents changed since their last
    /// lowering, one after another, stopping before the next when
    /// `interrupted` says the editor has sent something (the rest stay
    /// stale, for the next pause); the diagnostics to publish.
    fn lower_stale(&mut self, interrupted: impl Fn() -> bool) -> Vec<(Uri, Vec<lsp::Diagnostic>)> {
        let mut out = Vec::new();
        while let Some(k) = self.stale.first().cloned() {
            if interrupted() {
                break;
            }
            self.stale.remove(&k);
            let (Some(doc), Some(a)) = (self.docs.get(&k), self.analyses.get_mut(&k)) else {
                continue;
            };
            a.before_planning.clear();
            a.lower_jobs();
            out.push((
                doc.uri.clone(),
                analysis::diagnostics(a, &doc.uri, &doc.text),
            ));
        }
        out
    }

    /// A request's result, or its error's code and message.
    fn request(&mut self, method: &str, params: Value) -> Result<Value, (i32, String)> {
        let result = match method {
            req::HoverRequest::METHOD => self.with_position(params, |a, _, text, at| {
                hover::hover(a, text, at).map(|(md, s, e)| lsp::Hover {
                    contents: lsp::HoverContents::Markup(lsp::MarkupContent {
                        kind: lsp::MarkupKind::Markdown,
                        value: md,
                    }),
                    range: Some(LineIndex::new(text).range(s, e)),
                })
            }),
            req::Completion::METHOD => self.with_position(params, |a, _, text, at| {
                Some(lsp::CompletionResponse::Array(completion::complete(
                    a, text, at,
                )))
            }),
            req::GotoDefinition::METHOD => self.with_position(params, |a, uri, text, at| {
                definition::definition(a?, uri, text, at).map(lsp::GotoDefinitionResponse::Scalar)
            }),
            req::DocumentSymbolRequest::METHOD => {
                match parse::<lsp::DocumentSymbolParams>(params) {
                    Some(p) => {
                        let key = p.text_document.uri.as_str();
                        let symbols = match (self.analyses.get(key), self.docs.get(key)) {
                            (Some(a), Some(doc)) => symbols::outline(a, &doc.text),
                            _ => Vec::new(),
                        };
                        serde_json::to_value(lsp::DocumentSymbolResponse::Nested(symbols))
                            .map_err(|e| e.to_string())
                    }
                    None => Err("bad document symbol parameters".to_string()),
                }
            }
            req::References::METHOD => match parse::<lsp::ReferenceParams>(params) {
                Some(p) => {
                    let with = p.context.include_declaration;
                    self.with_position(
                        serde_json::to_value(p.text_document_position).unwrap_or_default(),
                        |a, uri, text, at| Some(symbols::references(a?, uri, text, at, with)),
                    )
                }
                None => Err("bad reference parameters".to_string()),
            },
            req::Rename::METHOD => match parse::<lsp::RenameParams>(params) {
                Some(p) => {
                    let mut refused = None;
                    let new_name = p.new_name;
                    let edit = self.with_position(
                        serde_json::to_value(p.text_document_position).unwrap_or_default(),
                        |a, uri, text, at| match symbols::rename(a?, uri, text, at, &new_name) {
                            Ok(e) => Some(e),
                            Err(why) => {
                                refused = Some(why);
                                None
                            }
                        },
                    );
                    match refused {
                        Some(why) => return Err((transport::INVALID_PARAMS, why)),
                        None => edit,
                    }
                }
                None => Err("bad rename parameters".to_string()),
            },
            req::CodeActionRequest::METHOD => match parse::<lsp::CodeActionParams>(params) {
                Some(p) => {
                    let uri = &p.text_document.uri;
                    let actions = match self.docs.get(uri.as_str()) {
                        Some(doc) => actions::quick_fixes(uri, &doc.text, &p.context.diagnostics),
                        None => Vec::new(),
                    };
                    serde_json::to_value(actions).map_err(|e| e.to_string())
                }
                None => Err("bad code action parameters".to_string()),
            },
            req::Formatting::METHOD => match parse::<lsp::DocumentFormattingParams>(params) {
                Some(p) => Ok(self.format(&p.text_document.uri)),
                None => Err("bad formatting parameters".to_string()),
            },
            _ => {
                return Err((
                    transport::METHOD_NOT_FOUND,
                    format!("lensc lsp does not answer `{method}`"),
                ));
            }
        };
        result.map_err(|e| (transport::INVALID_PARAMS, e))
    }

    /// Answers a request about a position in an open document.
    fn with_position<T: serde::Serialize>(
        &self,
        params: Value,
        answer: impl FnOnce(Option<&Analysis>, &Uri, &str, usize) -> Option<T>,
    ) -> Result<serde_json::Value, String> {
        let p: lsp::TextDocumentPositionParams =
            serde_json::from_value(params).map_err(|e| format!("bad parameters: {e}"))?;
        let uri = &p.text_document.uri;
        let Some(doc) = self.docs.get(uri.as_str()) else {
            return Ok(serde_json::Value::Null);
        };
        let at = LineIndex::new(&doc.text).offset(p.position);
        let v = answer(self.analyses.get(uri.as_str()), uri, &doc.text, at);
        serde_json::to_value(v).map_err(|e| e.to_string())
    }

    /// The document in `lensc fmt`'s layout, as one edit; no edit when it
    /// is already, or while it has syntax errors (shown as diagnostics).
    fn format(&self, uri: &Uri) -> serde_json::Value {
        let Some(doc) = self.docs.get(uri.as_str()) else {
            return serde_json::Value::Null;
        };
        let edits = match lensc_lang::format::format_source(&doc.text) {
            Ok(f) if f != doc.text => vec![lsp::TextEdit {
                range: LineIndex::new(&doc.text).range(0, doc.text.len()),
                new_text: f,
            }],
            _ => Vec::new(),
        };
        serde_json::to_value(edits).unwrap_or_default()
    }
}

fn parse<T: DeserializeOwned>(v: serde_json::Value) -> Option<T> {
    serde_json::from_value(v).ok()
}

/// One edit of a document's text in bytes: `start..end` replaced by
/// `inserted` bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Edit {
    start: usize,
    end: usize,
    inserted: usize,
}

/// Applies one change; the edit it made in bytes (`None`: the whole text
/// replaced). A document over the size limit has no text to change: only
/// a whole new text (within the limit) brings it back.
fn apply_change(doc: &mut Document, c: lsp::TextDocumentContentChangeEvent) -> Option<Edit> {
    match c.range {
        None => {
            doc.set_text(c.text);
            None
        }
        Some(_) if doc.too_large.is_some() => None,
        Some(r) => {
            let mut text = std::mem::take(&mut doc.text);
            let ix = LineIndex::new(&text);
            let (s, e) = (ix.offset(r.start), ix.offset(r.end));
            let (s, e) = (s.min(e), s.max(e));
            text.replace_range(s..e, &c.text);
            doc.set_text(text);
            Some(Edit {
                start: s,
                end: e,
                inserted: c.text.len(),
            })
        }
    }
}

/// Findings of the document's last lowering, their places in it moved
/// with the edits made since (a place inside replaced text goes to the
/// edit's start; after a whole new text, places are only kept within it).
fn moved(
    mut findings: Vec<lensc_grammar::Diagnostic>,
    edits: &[Option<Edit>],
    len: usize,
) -> Vec<lensc_grammar::Diagnostic> {
    let shift = |at: u32, e: &Edit| -> u32 {
        let at = at as usize;
        let to = if at <= e.start {
            at
        } else if at < e.end {
            e.start
        } else {
            at - e.end + e.start + e.inserted
        };
        to as u32
    };
    for d in &mut findings {
        for l in d
            .labels
            .iter_mut()
            .filter(|l| l.file == lensc_grammar::FileId(0))
        {
            for e in edits.iter().flatten() {
                l.span.start = shift(l.span.start, e);
                l.span.end = shift(l.span.end, e).max(l.span.start);
            }
            l.span.start = l.span.start.min(len as u32);
            l.span.end = l.span.end.min(len as u32);
        }
    }
    findings
}

fn publish(uri: Uri, diagnostics: Vec<lsp::Diagnostic>) -> Value {
    serde_json::to_value(lsp::PublishDiagnosticsParams {
        uri,
        diagnostics,
        version: None,
    })
    .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    /// A finding's place moves with the edits before it, stays before
    /// them, and goes to an edit's start when its text is replaced.
    #[test]
    fn findings_move_with_the_edits() {
        let at = |s: usize, e: usize| {
            lensc_grammar::Diagnostic::warning(
                "W0006",
                "m".to_string(),
                lensc_grammar::FileId(0),
                lensc_grammar::ast::Span::new(s, e),
            )
        };
        let found = vec![at(10, 14), at(2, 4), at(20, 30)];
        // 3 bytes inserted at 5; then bytes 22..26 (after the insertion)
        // replaced by 1.
        let edits = [
            Some(Edit {
                start: 5,
                end: 5,
                inserted: 3,
            }),
            Some(Edit {
                start: 22,
                end: 26,
                inserted: 1,
            }),
        ];
        let moved = moved(found, &edits, 100);
        let spans: Vec<(u32, u32)> = moved
            .iter()
            .map(|d| (d.labels[0].span.start, d.labels[0].span.end))
            .collect();
        assert_eq!(spans, [(13, 17), (2, 4), (22, 30)]);
        // After a whole new text, places are only held within it.
        let kept = super::moved(vec![at(40, 60)], &[None], 50);
        assert_eq!(
            (kept[0].labels[0].span.start, kept[0].labels[0].span.end),
            (40, 50)
        );
    }

    /// Every example, standard-library file and file of the bad-input
    /// corpora, asked for hover, completion and definition at every 11th
    /// byte and formatted: no answer panics, and every position maps back
    /// to its offset's character.
    #[test]
    fn no_question_about_any_corpus_file_panics() {
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let mut files = Vec::new();
        for dir in ["examples", "stdlib", "tests/bad", "tests/bad_builds"] {
            for e in std::fs::read_dir(repo.join(dir)).expect(dir) {
                let p = e.expect("entry").path();
                if p.extension().is_some_and(|x| x == "lens") {
                    files.push(p);
                }
            }
        }
        assert!(files.len() > 100, "{}", files.len());
        let mut asked = 0;
        for path in files {
            let Ok(text) = std::fs::read_to_string(&path) else {
                continue; // a corpus file that is not UTF-8
            };
            let uri = text::path_to_uri(&path.canonicalize().expect("path"));
            let mut docs = Docs::new();
            docs.insert(
                uri.as_str().to_string(),
                Document::new(uri.clone(), text.clone()),
            );
            let a = analysis::analyse(&docs, None, uri.as_str()).expect("analysed");
            let _ = analysis::diagnostics(&a, &uri, &text);
            let ix = LineIndex::new(&text);
            for at in (0..=text.len()).step_by(11) {
                let p = ix.position(at);
                let back = ix.offset(p);
                let char_start = (0..=at).rev().find(|&i| text.is_char_boundary(i));
                assert_eq!(Some(back), char_start, "{path:?} {at}");
                let _ = hover::hover(Some(&a), &text, at);
                let _ = completion::complete(Some(&a), &text, at);
                let _ = definition::definition(&a, &uri, &text, at);
                asked += 1;
            }
            let _ = lensc_lang::format::format_source(&text);
        }
        assert!(asked > 1000, "{asked}");
    }
}
