//! The JSON-RPC transport of `lensc lsp`, written for input no editor
//! would send: every frame is read with bounded memory, and every frame
//! that is not a JSON-RPC message becomes an error to answer, never the
//! end of the session.
//!
//! A frame is header lines (`Name: value`, each ended by CRLF or LF, at
//! most `MAX_HEADER_LINE` bytes and `MAX_HEADER_LINES` of them) up to an
//! empty line, then exactly `Content-Length` bytes of JSON. The body may
//! be at most `MAX_MESSAGE_BYTES`: twice the 16 MiB a file may have
//! (`sandbox::MAX_FILE_BYTES`, the CLI's limit; JSON writes a newline,
//! quote or backslash as two bytes) plus 1 MiB for the rest of the
//! message. A body with no usable length (none, negative, not a number,
//! over the limit) or a header line too long cannot be framed: it is
//! answered with a parse error (-32700; an oversized one with an invalid
//! request, -32600) and the reader skips to the next `Content-Length:` it
//! sees, in bounded memory, so the messages after it are still read. A
//! body that is not JSON is a parse error (-32700); JSON that is not a
//! JSON-RPC 2.0 request, notification or response is an invalid request
//! (-32600), answered with its `id` when it has a usable one.

use std::io::{BufRead, Read, Write};

use serde_json::{Value, json};

use lensc_lang::sandbox::MAX_FILE_BYTES;

/// The longest header line read, in bytes.
pub const MAX_HEADER_LINE: usize = 8 << 10;
/// The most header lines in one frame.
pub const MAX_HEADER_LINES: usize = 32;
/// The largest message body read, in bytes.
pub const MAX_MESSAGE_BYTES: usize = 2 * MAX_FILE_BYTES as usize + (1 << 20);

pub const PARSE_ERROR: i32 = -32700;
pub const INVALID_REQUEST: i32 = -32600;
pub const METHOD_NOT_FOUND: i32 = -32601;
pub const INVALID_PARAMS: i32 = -32602;
pub const INTERNAL_ERROR: i32 = -32603;
pub const SERVER_NOT_INITIALIZED: i32 = -32002;

/// One JSON-RPC message from the editor.
#[derive(Debug)]
pub enum Message {
    Request {
        id: Value,
        method: String,
        params: Value,
    },
    Notification {
        method: String,
        params: Value,
    },
    /// An answer to a request of ours (the server sends none; ignored).
    Response,
}

/// What one read gives.
#[derive(Debug)]
pub enum Frame {
    Message(Message),
    /// A frame that is not a message: answered with this error.
    Malformed {
        id: Value,
        code: i32,
        message: String,
    },
    /// The editor closed its end.
    Eof,
}

/// The editor's end, read a frame at a time.
pub struct Reader<R> {
    inner: R,
    /// After a frame that could not be framed: skip to the next
    /// `Content-Length:` before reading headers.
    lost: bool,
}

const MARK: &[u8] = b"content-length:";

impl<R: BufRead> Reader<R> {
    pub fn new(inner: R) -> Self {
        Reader { inner, lost: false }
    }

    pub fn read(&mut self) -> std::io::Result<Frame> {
        let mut first = None;
        if std::mem::take(&mut self.lost) {
            if !self.skip_to_mark()? {
                return Ok(Frame::Eof);
            }
            first = Some(b"Content-Length:".to_vec());
        }
        let mut length: Option<Result<usize, String>> = None;
        let mut lines = 0;
        loop {
            let prefix = first.take().unwrap_or_default();
            let line = match self.line(prefix)? {
                Line::Eof => return Ok(Frame::Eof),
                Line::TooLong => {
                    return Ok(
                        self.unframed(format!("a header line longer than {MAX_HEADER_LINE} bytes"))
                    );
                }
                Line::Text(l) => l,
            };
            if line.is_empty() {
                if lines == 0 {
                    continue; // blank lines between frames
                }
                break;
            }
            lines += 1;
            if lines > MAX_HEADER_LINES {
                return Ok(self.unframed(format!("more than {MAX_HEADER_LINES} header lines")));
            }
            let Some(colon) = line.iter().position(|&b| b == b':') else {
                return Ok(self.unframed(format!("a header line with no `:` ({})", shown(&line))));
            };
            let (name, value) = (&line[..colon], &line[colon + 1..]);
            if name.eq_ignore_ascii_case(b"content-length") {
                length = Some(parse_length(value));
            }
        }
        let length = match length {
            None => return Ok(self.unframed("a frame with no Content-Length header".into())),
            Some(Err(why)) => return Ok(self.unframed(why)),
            Some(Ok(n)) => n,
        };
        let mut body = Vec::with_capacity(length.min(1 << 16));
        let got = (&mut self.inner)
            .take(length as u64)
            .read_to_end(&mut body)?;
        if got < length {
            return Ok(Frame::Eof);
        }
        Ok(classify(&body))
    }

    /// The frame lost: answered with a parse error, the stream skipped to
    /// the next frame.
    fn unframed(&mut self, why: String) -> Frame {
        self.lost = true;
        // A length over the limit is a frame understood and refused.
        let code = if why.contains("over the limit") {
            INVALID_REQUEST
        } else {
            PARSE_ERROR
        };
        Frame::Malformed {
            id: Value::Null,
            code,
            message: format!("lensc lsp cannot read this frame: {why}"),
        }
    }

    /// One header line (without its CRLF or LF), at most `MAX_HEADER_LINE`
    /// bytes; `prefix` is what was already read of it.
    fn line(&mut self, mut line: Vec<u8>) -> std::io::Result<Line> {
        loop {
            let buf = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if buf.is_empty() {
                return Ok(Line::Eof);
            }
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            let room = MAX_HEADER_LINE + 2 - line.len();
            if take > room {
                self.inner.consume(room);
                return Ok(Line::TooLong);
            }
            line.extend_from_slice(&buf[..take]);
            self.inner.consume(take);
            if done {
                line.pop();
                if line.last() == Some(&b'\r') {
                    line.pop();
                }
                if line.len() > MAX_HEADER_LINE {
                    return Ok(Line::TooLong);
                }
                return Ok(Line::Text(line));
            }
        }
    }

    /// Skips past the next `Content-Length:` (any case); false at the end
    /// of the input.
    fn skip_to_mark(&mut self) -> std::io::Result<bool> {
        let mut matched = 0;
        loop {
            let buf = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if buf.is_empty() {
                return Ok(false);
            }
            let mut used = 0;
            for &b in buf {
                used += 1;
                let b = b.to_ascii_lowercase();
                if b == MARK[matched] {
                    matched += 1;
                } else {
                    matched = usize::from(b == MARK[0]);
                }
                if matched == MARK.len() {
                    self.inner.consume(used);
                    return Ok(true);
                }
            }
            self.inner.consume(used);
        }
    }
}

enum Line {
    Text(Vec<u8>),
    TooLong,
    Eof,
}

/// A header line as shown in a message: its first 40 bytes, escaped.
fn shown(line: &[u8]) -> String {
    let head = &line[..line.len().min(40)];
    let mut s: String = head.escape_ascii().to_string();
    if line.len() > 40 {
        s.push('…');
    }
    s
}

fn parse_length(value: &[u8]) -> Result<usize, String> {
    let v = value.trim_ascii();
    if v.is_empty() || !v.iter().all(u8::is_ascii_digit) {
        return Err(format!(
            "a Content-Length that is not a non-negative whole number ({})",
            shown(v)
        ));
    }
    // At most 20 digits fit a u64; longer is over the limit anyway.
    let n = std::str::from_utf8(v)
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(u64::MAX);
    if n > MAX_MESSAGE_BYTES as u64 {
        return Err(format!(
            "a Content-Length of {} bytes, over the limit of {MAX_MESSAGE_BYTES} bytes",
            if n == u64::MAX {
                shown(v)
            } else {
                n.to_string()
            }
        ));
    }
    Ok(n as usize)
}

/// A body as a message, or what is wrong with it.
fn classify(body: &[u8]) -> Frame {
    let v: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            return Frame::Malformed {
                id: Value::Null,
                code: PARSE_ERROR,
                message: format!("the message is not JSON: {e}"),
            };
        }
    };
    let invalid = |id: Value, why: &str| Frame::Malformed {
        id,
        code: INVALID_REQUEST,
        message: format!("not a JSON-RPC 2.0 message: {why}"),
    };
    let Value::Object(mut o) = v else {
        return invalid(Value::Null, "not an object");
    };
    // An id the answer can carry: a number or a string.
    let id = match o.remove("id") {
        None => None,
        Some(id @ (Value::Number(_) | Value::String(_))) => Some(id),
        Some(_) => return invalid(Value::Null, "an `id` that is not a number or a string"),
    };
    if o.get("jsonrpc") != Some(&json!("2.0")) {
        return invalid(id.unwrap_or_default(), "no `\"jsonrpc\": \"2.0\"`");
    }
    let params = o.remove("params").unwrap_or(Value::Null);
    if !matches!(params, Value::Null | Value::Object(_) | Value::Array(_)) {
        return invalid(id.unwrap_or_default(), "`params` is not an object or array");
    }
    match (o.remove("method"), id) {
        (Some(Value::String(method)), Some(id)) => {
            Frame::Message(Message::Request { id, method, params })
        }
        (Some(Value::String(method)), None) => {
            Frame::Message(Message::Notification { method, params })
        }
        (Some(_), id) => invalid(id.unwrap_or_default(), "a `method` that is not a string"),
        (None, Some(_)) if o.contains_key("result") || o.contains_key("error") => {
            Frame::Message(Message::Response)
        }
        (None, id) => invalid(id.unwrap_or_default(), "no `method`"),
    }
}

/// The server's end: each message written whole and flushed.
pub struct Writer<W> {
    inner: W,
}

impl<W: Write> Writer<W> {
    pub fn new(inner: W) -> Self {
        Writer { inner }
    }

    fn write(&mut self, v: &Value) -> std::io::Result<()> {
        let body = v.to_string();
        write!(self.inner, "Content-Length: {}\r\n\r\n{body}", body.len())?;
        self.inner.flush()
    }

    pub fn result(&mut self, id: Value, result: Value) -> std::io::Result<()> {
        self.write(&json!({"jsonrpc": "2.0", "id": id, "result": result}))
    }

    pub fn error(&mut self, id: Value, code: i32, message: &str) -> std::io::Result<()> {
        self.write(&json!({
            "jsonrpc": "2.0",
            "id": id,
            "error": {"code": code, "message": message},
        }))
    }

    pub fn notify(&mut self, method: &str, params: Value) -> std::io::Result<()> {
        self.write(&json!({"jsonrpc": "2.0", "method": method, "params": params}))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(input: &[u8]) -> Vec<String> {
        let mut r = Reader::new(std::io::BufReader::with_capacity(7, input));
        let mut out = Vec::new();
        loop {
            match r.read().expect("read") {
                Frame::Eof => return out,
                Frame::Message(Message::Request { id, method, .. }) => {
                    out.push(format!("request {id} {method}"))
                }
                Frame::Message(Message::Notification { method, .. }) => {
                    out.push(format!("note {method}"))
                }
                Frame::Message(Message::Response) => out.push("response".into()),
                Frame::Malformed { id, code, .. } => out.push(format!("error {id} {code}")),
            }
        }
    }

    fn frame(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{body}", body.len())
    }

    const OK: &str = r#"{"jsonrpc":"2.0","id":7,"method":"m"}"#;

    #[test]
    fn malformed_frames_are_answered_and_the_next_is_read() {
        let cases: &[(String, &str)] = &[
            ("Content-Length: -5\r\n\r\n{}".into(), "error null -32700"),
            (
                "Content-Length: 1099511627776\r\n\r\n".into(),
                "error null -32600",
            ),
            (
                "Content-Length: 99999999999999999999999999\r\n\r\n".into(),
                "error null -32600",
            ),
            ("Content-Type: x\r\n\r\n{}".into(), "error null -32700"),
            ("Content-Length 5\r\n\r\n{}".into(), "error null -32700"),
            (frame("abc"), "error null -32700"),
            (frame("[]"), "error null -32600"),
            (frame(r#"{"id":3,"method":"m"}"#), "error 3 -32600"),
            (frame(r#"{"jsonrpc":"2.0","id":4}"#), "error 4 -32600"),
            (
                frame(r#"{"jsonrpc":"2.0","id":[1],"method":"m"}"#),
                "error null -32600",
            ),
        ];
        for (bad, want) in cases {
            let input = format!("{bad}{}", frame(OK));
            assert_eq!(frames(input.as_bytes()), [*want, "request 7 m"], "{bad:?}");
        }
    }

    #[test]
    fn an_endless_header_line_costs_bounded_memory() {
        let mut input = vec![b'A'; 10 * MAX_HEADER_LINE];
        input.extend_from_slice(frame(OK).as_bytes());
        assert_eq!(frames(&input), ["error null -32700", "request 7 m"]);
        let mut input = b"Content-Length: 1".to_vec();
        input.extend(std::iter::repeat_n(b'0', 3 * MAX_HEADER_LINE));
        input.extend_from_slice(frame(OK).as_bytes());
        assert_eq!(frames(&input), ["error null -32700", "request 7 m"]);
    }

    #[test]
    fn good_frames_and_lf_only_headers() {
        let input = format!(
            "{}Content-Length: {}\n\n{}{}",
            frame(r#"{"jsonrpc":"2.0","method":"n","params":{}}"#),
            OK.len(),
            OK,
            frame(r#"{"jsonrpc":"2.0","id":"x","result":null}"#),
        );
        assert_eq!(
            frames(input.as_bytes()),
            ["note n", "request 7 m", "response"]
        );
        // A body cut short is the end of the input.
        assert_eq!(
            frames(b"Content-Length: 10\r\n\r\n{}"),
            Vec::<String>::new()
        );
    }
}
