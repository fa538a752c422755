//! Text to syntax tree. The file is split at top-level item keywords and
//! each item parsed on its own, so one syntax error does not hide the next.

use std::sync::LazyLock;

use pest::Parser as _;
use pest::iterators::{Pair, Pairs};
use pest::pratt_parser::{Assoc, Op, PrattParser};

use crate::ast::*;
use crate::diagnostic::{Diagnostic, FileId, codes};

#[derive(pest_derive::Parser)]
#[grammar = "lens.pest"]
struct LensParser;

/// Longest run of operators in a row (`- - - x`) and most `^` in one item:
/// pest parses prefix operators and right-associative powers recursively.
pub const MAX_OPERATOR_RUN: usize = 32;
pub const MAX_POWERS_PER_ITEM: usize = 64;

/// Depth of an expression tree. Only called on trees already bounded by
/// `MAX_EXPR_DEPTH`, so its recursion is bounded too.
fn depth(e: &Expr) -> u32 {
    1 + match &e.kind {
        ExprKind::Unary { operand, .. } => depth(operand),
        ExprKind::Binary { lhs, rhs, .. } => depth(lhs).max(depth(rhs)),
        ExprKind::Call { callee, args } => args
            .iter()
            .map(|a| depth(&a.value))
            .fold(depth(callee), u32::max),
        ExprKind::WithBlock { base, block } => block_depth(block).max(depth(base)),
        ExprKind::Block(b) => block_depth(b),
        ExprKind::List(items) => items.iter().map(depth).max().unwrap_or(0),
        _ => 0,
    }
}

fn block_depth(b: &Block) -> u32 {
    b.entries
        .iter()
        .map(|e| match e {
            Entry::Param { value, .. } => depth(value),
            Entry::Formula { body, .. } => depth(body),
        })
        .max()
        .unwrap_or(0)
}

/// Deepest bracket nesting accepted. Deeper input is refused before pest
/// sees it, so no input can overflow the parser's stack.
pub const MAX_NESTING: usize = 64;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::range_op, Assoc::Left))
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
        .op(Op::infix(Rule::pow, Assoc::Right))
});

/// Parses one source file. Always returns a tree (possibly partial) and the
/// syntax diagnostics found, in source order.
pub fn parse(source: &str, file: FileId) -> (File, Vec<Diagnostic>) {
    parse_with(source, file, true)
}

/// `parse` by pest alone, without the hand-written fast path (`descent`):
/// the reference that tests and the fuzzer compare `parse` with. Its
/// result is the same, tree and diagnostics, only slower.
#[doc(hidden)]
pub fn parse_reference(source: &str, file: FileId) -> (File, Vec<Diagnostic>) {
    parse_with(source, file, false)
}

fn parse_with(source: &str, file: FileId, fast: bool) -> (File, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    if source.len() > u32::MAX as usize / 2 {
        diags.push(Diagnostic::error(
            codes::TOO_LARGE,
            "file is too large (over 2 GiB)",
            file,
            Span::new(0, 0),
        ));
        return (File::default(), diags);
    }
    let scan = scan(source);
    if let Some(at) = scan.too_deep_at {
        let (message, label) = match scan.why {
            TooDeep::Brackets => (
                format!("brackets are nested more than {MAX_NESTING} deep"),
                "this bracket is too deep",
            ),
            TooDeep::OperatorRun => (
                format!("more than {MAX_OPERATOR_RUN} operators in a row"),
                "one operator too many",
            ),
            TooDeep::Powers => (
                format!("more than {MAX_POWERS_PER_ITEM} powers `^` in one item"),
                "one power too many",
            ),
        };
        diags.push(
            Diagnostic::error(codes::TOO_DEEP, message, file, Span::new(at, at + 1))
                .with_label(label)
                .with_help("split the expression with `let` constants"),
        );
        return (File::default(), diags);
    }
    let mut items = Vec::new();
    let chunks: Vec<(usize, usize)> = scan
        .chunks
        .into_iter()
        .filter(|&(s, e)| !source[s..e].trim().is_empty())
        .collect();
    // Items are parsed a batch at a time (a pest call per item costs more
    // than the item: 200,000 one-line `let`s took a second); a batch that
    // does not parse is parsed again item by item, for every error in it.
    for batch in batches(&chunks) {
        let (start, end) = (batch[0].0, batch[batch.len() - 1].1);
        // Text with nothing to report takes the hand-written path; pest
        // parses the rest, and every error is reported from there.
        if fast && crate::descent::items(&source[start..end], start, &mut items).is_some() {
            continue;
        }
        if batch.len() > 1
            && let Ok(pairs) = LensParser::parse(Rule::file, &source[start..end])
        {
            let mut b = Builder {
                file,
                offset: start,
                diags: &mut diags,
            };
            b.items(pairs, &mut items);
            continue;
        }
        for &(start, end) in batch {
            let text = &source[start..end];
            let mut b = Builder {
                file,
                offset: start,
                diags: &mut diags,
            };
            match LensParser::parse(Rule::file, text) {
                Ok(pairs) => b.items(pairs, &mut items),
                Err(e) => {
                    // An entry half typed (`chords:` with no value yet, or
                    // `chor`) costs only that entry, not the whole item:
                    // blanked out, the rest parses and is kept.
                    if let Some((fixed, half_typed)) = without_half_typed_entries(text)
                        && let Ok(pairs) = LensParser::parse(Rule::file, &fixed)
                    {
                        for (span, name, colon) in half_typed {
                            b.diags
                                .push(half_typed_entry(file, start, span, &name, colon));
                        }
                        b.items(pairs, &mut items);
                        continue;
                    }
                    let d = b.syntax_error(source, text, e);
                    diags.push(d);
                }
            }
        }
    }
    (File { items }, diags)
}

/// An entry half typed: its span in the item, its name, and whether it
/// had its `:`.
type HalfTyped = ((usize, usize), String, bool);

/// The item's text with every line that holds only a name, or a name and
/// a `:` (an entry half typed inside a block), blanked with spaces (so
/// every other span stays where it is); each such line's span in the item,
/// its name and whether it had the `:`. `None` if there is no such line.
/// The item's first line (its keyword and name) is never blanked.
fn without_half_typed_entries(text: &str) -> Option<(String, Vec<HalfTyped>)> {
    let mut fixed = text.as_bytes().to_vec();
    let mut found = Vec::new();
    let mut offset = 0;
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let start = offset;
        offset += line.len();
        if n == 0 {
            continue;
        }
        let body = line.trim_end_matches(['\n', '\r']);
        let trimmed = body.trim();
        let (name, colon) = match trimmed.strip_suffix(':') {
            Some(n) => (n.trim_end(), true),
            None => (trimmed, false),
        };
        let is_name = name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !is_name {
            continue;
        }
        let lead = body.len() - body.trim_start().len();
        let (s, e) = (start + lead, start + lead + trimmed.len());
        fixed[s..e].fill(b' ');
        found.push(((s, e), name.to_string(), colon));
    }
    if found.is_empty() {
        return None;
    }
    String::from_utf8(fixed).ok().map(|f| (f, found))
}

/// The error for an entry half typed at `span` of the item at `offset`.
fn half_typed_entry(
    file: FileId,
    offset: usize,
    (s, e): (usize, usize),
    name: &str,
    colon: bool,
) -> Diagnostic {
    let span = Span::new(offset + s, offset + e);
    if colon {
        Diagnostic::error(codes::SYNTAX, format!("`{name}` has no value"), file, span)
            .with_label("a value goes after the `:`")
            .with_help(format!("write its value (`{name}: …`) or remove the line; the rest of the block is read without it"))
    } else {
        Diagnostic::error(
            codes::SYNTAX,
            format!("`{name}` is not an entry"),
            file,
            span,
        )
        .with_label("an entry is `name: value`")
        .with_help(format!(
            "write `{name}: value`, or remove the line; the rest of the block is read without it"
        ))
    }
}

/// Bytes of source parsed in one pest call, at most (one item may be longer).
const BATCH_BYTES: usize = 16 << 10;

/// Consecutive items grouped into batches of about `BATCH_BYTES`.
fn batches(chunks: &[(usize, usize)]) -> impl Iterator<Item = &[(usize, usize)]> {
    let mut rest = chunks;
    std::iter::from_fn(move || {
        let first = rest.first()?;
        let n = rest
            .iter()
            .position(|&(_, e)| e - first.0 > BATCH_BYTES)
            .unwrap_or(rest.len())
            .max(1);
        let (batch, tail) = rest.split_at(n);
        rest = tail;
        Some(batch)
    })
}

struct Scan {
    chunks: Vec<(usize, usize)>,
    too_deep_at: Option<usize>,
    why: TooDeep,
}

enum TooDeep {
    Brackets,
    OperatorRun,
    Powers,
}

/// Whether byte `i` of `b` is one of the three of a byte-order mark.
fn in_bom(b: &[u8], i: usize) -> bool {
    const BOM: &[u8] = "\u{FEFF}".as_bytes();
    (0..3).any(|k| i >= k && b[i - k..].starts_with(BOM))
}

/// One pass over the bytes: bracket depth (outside comments and strings) and
/// the byte offsets where top-level items start.
fn scan(src: &str) -> Scan {
    let b = src.as_bytes();
    let mut depth = 0usize;
    let mut starts = vec![0usize];
    let mut i = 0;
    let mut at_word_start = true;
    let mut op_run = 0usize;
    let mut powers = 0usize;
    while i < b.len() {
        let c = b[i];
        match c {
            b'-' | b'+' | b'*' | b'/' | b'^'
                if !(c == b'/' && matches!(b.get(i + 1), Some(b'/' | b'*'))) =>
            {
                op_run += 1;
                powers += usize::from(c == b'^');
                if op_run > MAX_OPERATOR_RUN || powers > MAX_POWERS_PER_ITEM {
                    return Scan {
                        chunks: vec![],
                        too_deep_at: Some(i),
                        why: if op_run > MAX_OPERATOR_RUN {
                            TooDeep::OperatorRun
                        } else {
                            TooDeep::Powers
                        },
                    };
                }
            }
            b' ' | b'\t' | b'\r' | b'\n' => {}
            // A byte-order mark is blank to the parser: it does not end a
            // run of operators either (a run split by one counted as two
            // runs, and `lensc fmt`, which drops the mark, refused the file
            // with E0185).
            0xEF | 0xBB | 0xBF if in_bom(b, i) => {}
            _ => op_run = 0,
        }
        match c {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
                at_word_start = true;
                continue;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                    i += 1;
                }
                i = (i + 2).min(b.len());
                at_word_start = true;
                continue;
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i = (i + 1).min(b.len());
                at_word_start = false;
                continue;
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Scan {
                        chunks: vec![],
                        too_deep_at: Some(i),
                        why: TooDeep::Brackets,
                    };
                }
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        let is_word = is_word_byte(c);
        if is_word {
            if at_word_start && i > 0 && preceded_by_line_start(b, i) && starts_item(&src[i..]) {
                // Also inside an unclosed bracket: an item keyword at the start of
                // a line followed by a name cannot continue the previous item,
                // so a missing `)` or `}` does not swallow the rest of the file.
                starts.push(i);
                powers = 0;
            }
            // The rest of the word changes nothing above: pass over it.
            i += b[i..].iter().take_while(|&&w| is_word_byte(w)).count();
            at_word_start = false;
            continue;
        }
        at_word_start = true;
        i += 1;
    }
    let mut chunks = Vec::with_capacity(starts.len());
    for (k, &s) in starts.iter().enumerate() {
        let e = starts.get(k + 1).copied().unwrap_or(src.len());
        chunks.push((s, e));
    }
    Scan {
        chunks,
        too_deep_at: None,
        why: TooDeep::Brackets,
    }
}

fn is_word_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// `surface name`, `let name`, `use "…"`, `use std…`: an item keyword followed
/// by a name or string, not a parameter such as `surface: s`.
fn starts_item(rest: &str) -> bool {
    [
        "use", "let", "job", "surface", "tool", "machine", "strategy",
    ]
    .iter()
    .any(|k| {
        rest.starts_with(k) && {
            let after = &rest[k.len()..];
            let trimmed = after.trim_start_matches([' ', '\t']);
            trimmed.len() < after.len()
                && trimmed
                    .starts_with(|ch: char| ch.is_ascii_alphabetic() || ch == '_' || ch == '"')
        }
    })
}

/// Items are split only at keywords that begin a line, so `a: 1 mm, tool: t`
/// style text stays in one piece even if a bracket is missing.
fn preceded_by_line_start(b: &[u8], i: usize) -> bool {
    let mut j = i;
    while j > 0 {
        match b[j - 1] {
            b' ' | b'\t' | b'\r' => j -= 1,
            b'\n' => return true,
            _ => return false,
        }
    }
    true
}

struct Builder<'d> {
    file: FileId,
    offset: usize,
    diags: &'d mut Vec<Diagnostic>,
}

impl Builder<'_> {
    fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        Span::new(s.start() + self.offset, s.end() + self.offset)
    }

    fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident {
            span: self.span(&p),
            name: p.as_str().to_string(),
        }
    }

    fn item(&mut self, p: Pair<Rule>) -> Item {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut inner = p.into_inner();
        let kind = match rule {
            Rule::use_item => {
                let _kw = inner.next();
                let target = inner.next().expect("use target");
                match target.as_rule() {
                    Rule::string => {
                        let span = self.span(&target);
                        ItemKind::Use(UseTarget::File {
                            path: self.string(target),
                            span,
                        })
                    }
                    _ => ItemKind::Use(UseTarget::Std(
                        target.into_inner().map(|s| self.ident(s)).collect(),
                    )),
                }
            }
            Rule::let_item => {
                let _kw = inner.next();
                let name = self.ident(inner.next().expect("let name"));
                let value = self.expr(inner.next().expect("let value"));
                ItemKind::Let { name, value }
            }
            Rule::decl_item => {
                let keyword = inner.next().expect("decl kind").as_str();
                let kind = DeclKind::from_keyword(keyword)
                    .unwrap_or_else(|| unreachable!("`{keyword}` is in lens.pest's decl_kind"));
                let name = self.ident(inner.next().expect("decl name"));
                let value = self.expr(inner.next().expect("decl value"));
                ItemKind::Decl { kind, name, value }
            }
            _ => {
                let _kw = inner.next();
                let name = self.ident(inner.next().expect("job name"));
                let body = self.block(inner.next().expect("job body"));
                ItemKind::Job { name, body }
            }
        };
        Item { kind, span }
    }

    fn expr(&mut self, p: Pair<Rule>) -> Expr {
        let pairs = p.into_inner();
        self.pratt(pairs)
    }

    fn pratt(&mut self, pairs: Pairs<Rule>) -> Expr {
        // The closures below all need `self`; pest's Pratt API takes them
        // separately, so share `self` through a RefCell. Each node carries
        // its depth so that chains like `1 + 1 + … + 1` stop at the limit.
        let me = std::cell::RefCell::new(self);
        let (e, _) = PRATT
            .map_primary(|p| {
                let e = me.borrow_mut().operand(p);
                let d = depth(&e);
                (e, d)
            })
            .map_prefix(|op, (rhs, d)| {
                let span = me.borrow().span(&op).to(rhs.span);
                let e = Expr {
                    kind: ExprKind::Unary {
                        op: UnaryOp::Neg,
                        operand: Box::new(rhs),
                    },
                    span,
                };
                me.borrow_mut().limit_depth(e, d + 1)
            })
            .map_infix(|(lhs, dl), op, (rhs, dr)| {
                let op = match op.as_rule() {
                    Rule::add => BinaryOp::Add,
                    Rule::sub => BinaryOp::Sub,
                    Rule::mul => BinaryOp::Mul,
                    Rule::div => BinaryOp::Div,
                    Rule::pow => BinaryOp::Pow,
                    _ => BinaryOp::Range,
                };
                let span = lhs.span.to(rhs.span);
                let e = Expr {
                    kind: ExprKind::Binary {
                        op,
                        lhs: Box::new(lhs),
                        rhs: Box::new(rhs),
                    },
                    span,
                };
                me.borrow_mut().limit_depth(e, dl.max(dr) + 1)
            })
            .parse(pairs);
        e
    }

    /// Replaces a node deeper than `MAX_EXPR_DEPTH` by `Invalid` (reported
    /// once, where the limit was crossed), so no later pass recurses deeper.
    fn limit_depth(&mut self, e: Expr, d: u32) -> (Expr, u32) {
        if d == MAX_EXPR_DEPTH + 1 {
            self.diags.push(
                Diagnostic::error(
                    codes::TOO_DEEP,
                    format!("this expression is nested more than {MAX_EXPR_DEPTH} operations deep"),
                    self.file,
                    e.span,
                )
                .with_label("too deep")
                .with_help("split the expression with `let` constants"),
            );
        }
        if d > MAX_EXPR_DEPTH {
            (
                Expr {
                    kind: ExprKind::Invalid,
                    span: e.span,
                },
                d,
            )
        } else {
            (e, d)
        }
    }

    fn operand(&mut self, p: Pair<Rule>) -> Expr {
        let mut inner = p.into_inner();
        let mut e = self.primary(inner.next().expect("primary"));
        let mut d = depth(&e);
        for post in inner {
            let span = e.span.to(self.span(&post));
            e = match post.as_rule() {
                Rule::call_args => {
                    let args = post.into_inner().map(|a| self.arg(a)).collect();
                    Expr {
                        kind: ExprKind::Call {
                            callee: Box::new(e),
                            args,
                        },
                        span,
                    }
                }
                _ => {
                    let block = self.block(post);
                    Expr {
                        kind: ExprKind::WithBlock {
                            base: Box::new(e),
                            block,
                        },
                        span,
                    }
                }
            };
            d += 1;
            e = self.limit_depth(e, d).0;
        }
        e
    }

    fn arg(&mut self, p: Pair<Rule>) -> Arg {
        let mut inner: Vec<Pair<Rule>> = p.into_inner().collect();
        let value = self.expr(inner.pop().expect("arg value"));
        let name = inner.pop().map(|n| self.ident(n));
        Arg { name, value }
    }

    fn primary(&mut self, p: Pair<Rule>) -> Expr {
        let span = self.span(&p);
        let kind = match p.as_rule() {
            Rule::quantity => return self.quantity(p),
            Rule::string => ExprKind::Str(self.string(p)),
            Rule::ident => ExprKind::Name(p.as_str().to_string()),
            Rule::paren => {
                let inner = self.expr(p.into_inner().next().expect("paren expr"));
                return Expr {
                    kind: inner.kind,
                    span,
                };
            }
            Rule::list => ExprKind::List(p.into_inner().map(|e| self.expr(e)).collect()),
            _ => ExprKind::Block(self.block(p)),
        };
        Expr { kind, span }
    }

    fn quantity(&mut self, p: Pair<Rule>) -> Expr {
        let span = self.span(&p);
        let mut inner = p.into_inner();
        let num = inner.next().expect("number");
        let value: f64 = num.as_str().parse().unwrap_or(f64::INFINITY);
        if !value.is_finite() {
            self.diags.push(
                Diagnostic::error(
                    codes::BAD_NUMBER,
                    "number is too large",
                    self.file,
                    self.span(&num),
                )
                .with_label("this does not fit in a 64-bit float")
                .with_help("write it in a larger unit, or check for a typo in the exponent"),
            );
        }
        let unit = inner.next().map(|u| {
            let uspan = self.span(&u);
            let mut parts = Vec::new();
            for (k, part) in u.into_inner().enumerate() {
                let pspan = self.span(&part);
                let mut pi = part.into_inner();
                let name = pi.next().expect("unit name").as_str().to_string();
                let mut power: i32 = pi
                    .next()
                    .map(|x| x.as_str().parse().unwrap_or(1))
                    .unwrap_or(1);
                if power == 0 {
                    self.diags.push(
                        Diagnostic::error(
                            codes::BAD_UNIT_POWER,
                            "a unit to the power zero",
                            self.file,
                            pspan,
                        )
                        .with_label("remove this unit or give it a non-zero power"),
                    );
                    power = 1;
                }
                if k > 0 {
                    power = -power;
                }
                parts.push(UnitPart {
                    name,
                    power,
                    span: pspan,
                });
            }
            Unit { parts, span: uspan }
        });
        let value = if value.is_finite() { value } else { 0.0 };
        Expr {
            kind: ExprKind::Quantity { value, unit },
            span,
        }
    }

    fn string(&mut self, p: Pair<Rule>) -> String {
        let body = p.into_inner().next().expect("string body");
        let start = self.span(&body).start as usize;
        let raw = body.as_str();
        let mut out = String::with_capacity(raw.len());
        let mut chars = raw.char_indices();
        while let Some((i, c)) = chars.next() {
            if c != '\\' {
                out.push(c);
                continue;
            }
            match chars.next() {
                Some((_, '"')) => out.push('"'),
                Some((_, '\\')) => out.push('\\'),
                Some((_, 'n')) => out.push('\n'),
                Some((_, 't')) => out.push('\t'),
                Some((j, other)) => {
                    let span = Span::new(start + i, start + j + other.len_utf8());
                    self.diags.push(
                        Diagnostic::error(
                            codes::BAD_ESCAPE,
                            format!("unknown escape `\\{other}` in a string"),
                            self.file,
                            span,
                        )
                        .with_label("not an escape")
                        .with_help("the escapes are \\\" \\\\ \\n \\t"),
                    );
                }
                None => {}
            }
        }
        out
    }

    fn block(&mut self, p: Pair<Rule>) -> Block {
        let span = self.span(&p);
        let mut entries = Vec::new();
        for e in p.into_inner() {
            let rule = e.as_rule();
            let mut inner: Vec<Pair<Rule>> = e.into_inner().collect();
            let last = inner.pop().expect("entry value");
            let value = self.expr(last);
            let mut names = inner.into_iter().map(|n| self.ident(n));
            let name = names.next().expect("entry name");
            entries.push(match rule {
                Rule::param_entry => Entry::Param { name, value },
                _ => Entry::Formula {
                    name,
                    params: names.collect(),
                    body: value,
                },
            });
        }
        Block { entries, span }
    }

    /// `text` is the item that failed, `source` the whole file: what was
    /// found is described from the whole file, so an item cut short by the
    /// next one reports that item's keyword, not "end of file".
    /// The items of a parsed `file`, in order.
    fn items(&mut self, mut pairs: Pairs<Rule>, items: &mut Vec<Item>) {
        let file_pair = pairs.next().expect("file rule");
        for p in file_pair.into_inner() {
            if p.as_rule() != Rule::EOI {
                items.push(self.item(p));
            }
        }
    }

    fn syntax_error(&self, source: &str, text: &str, e: pest::error::Error<Rule>) -> Diagnostic {
        use pest::error::{ErrorVariant, InputLocation};
        let at = match e.location {
            InputLocation::Pos(p) => p,
            InputLocation::Span((s, _)) => s,
        };
        let found = describe_found(source, self.offset + at);
        let (message, expected) = match &e.variant {
            ErrorVariant::ParsingError { positives, .. } => {
                let mut words: Vec<&str> =
                    positives.iter().filter_map(|r| describe_rule(*r)).collect();
                words.sort_unstable();
                words.dedup();
                let expected = match words.len() {
                    0 => String::new(),
                    1 => words[0].to_string(),
                    _ => {
                        let (last, rest) = words.split_last().expect("non-empty");
                        format!("{} or {}", rest.join(", "), last)
                    }
                };
                (format!("unexpected {found}"), expected)
            }
            ErrorVariant::CustomError { message } => (message.clone(), String::new()),
        };
        let abs = self.offset + at;
        let span = Span::new(abs, abs + found_len(source, abs));
        let mut d = Diagnostic::error(codes::SYNTAX, message, self.file, span);
        d = d.with_label(if expected.is_empty() {
            "expected `surface`, `tool`, `machine`, `strategy`, `job`, `let` or `use`".to_string()
        } else {
            format!("expected {expected}")
        });
        if let Some(h) = syntax_hint(text, at) {
            d = d.with_help(h);
        }
        d
    }
}

/// Plain words for the rules a user can be told were expected; `None`
/// hides a rule that only makes sense inside the grammar.
fn describe_rule(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::EOI => "end of file",
        Rule::use_item | Rule::kw_use => "`use`",
        Rule::let_item | Rule::kw_let => "`let`",
        Rule::decl_item | Rule::decl_kind => {
            "a declaration (`surface`, `tool`, `machine`, `strategy`)"
        }
        Rule::job_item | Rule::kw_job => "`job`",
        Rule::std_path => "a module path like `std::tools`",
        Rule::ident => "a name",
        Rule::param_name => "a parameter name",
        Rule::expr | Rule::operand | Rule::quantity | Rule::number => "a value",
        Rule::paren => "`(`",
        Rule::list => "`[`",
        Rule::block => "`{`",
        Rule::call_args => "`(`",
        Rule::param_entry | Rule::formula_entry => "a parameter (`name: value`)",
        Rule::range_op | Rule::add | Rule::sub | Rule::mul | Rule::div | Rule::pow => "an operator",
        Rule::neg => "`-`",
        Rule::string => "a string",
        Rule::unit | Rule::unit_part | Rule::unit_name => "a unit",
        Rule::unit_power => "a whole-number power",
        Rule::arg => "an argument",
        _ => return None,
    })
}

fn found_len(text: &str, at: usize) -> usize {
    let rest = &text[at..];
    let word: usize = rest
        .char_indices()
        .take_while(|(_, c)| c.is_alphanumeric() || *c == '_')
        .map(|(_, c)| c.len_utf8())
        .sum();
    if word > 0 {
        word
    } else {
        rest.chars().next().map_or(0, char::len_utf8)
    }
}

fn describe_found(text: &str, at: usize) -> String {
    let rest = &text[at..];
    match rest.chars().next() {
        None => "end of file".to_string(),
        Some(c) if c.is_alphanumeric() || c == '_' => format!("`{}`", &rest[..found_len(text, at)]),
        Some('\n') | Some('\r') => "end of line".to_string(),
        Some(c) if c.is_control() => format!("control character U+{:04X}", c as u32),
        Some(c) => format!("`{c}`"),
    }
}

fn syntax_hint(text: &str, at: usize) -> Option<String> {
    let rest = &text[at..];
    let word = &rest[..found_len(text, at)];
    let keywords = [
        "use", "let", "job", "surface", "tool", "machine", "strategy",
    ];
    if let Some(k) = crate::suggest::did_you_mean(word, keywords) {
        return Some(format!("did you mean `{k}`?"));
    }
    if rest.starts_with('"') {
        return Some("this string is not closed before the end of its line".into());
    }
    if rest.starts_with('=') && !rest.starts_with("==") {
        return Some("parameters are written `name: value`, with a colon".into());
    }
    if rest.starts_with(';') {
        return Some("lines need no `;`; separate parameters with new lines or commas".into());
    }
    if rest.is_empty() {
        let opens =
            text.matches('{').count() + text.matches('(').count() + text.matches('[').count();
        let closes =
            text.matches('}').count() + text.matches(')').count() + text.matches(']').count();
        if opens > closes {
            return Some("a bracket is not closed".into());
        }
    }
    None
}
