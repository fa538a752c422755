//! The fast path of parsing: a hand-written recursive-descent twin of
//! `lens.pest` for text that parses with no diagnostic at all, about ten
//! times cheaper than pest's generic machinery (docs/perf/check.md).
//!
//! `lens.pest` stays the definition of the language and pest the path for
//! everything else: this parser gives up (`None`) wherever pest would fail
//! or the tree builder would report something (a syntax error, a number too
//! large, a unit to the power zero, an unknown escape, an expression deeper
//! than `MAX_EXPR_DEPTH`), and the caller then parses the same text with
//! pest, so diagnostics come from one place. Where it succeeds, its tree is
//! the one pest's path builds, span for span: `parser::tests` and the fuzzer
//! compare the two on every input they make.
//!
//! Each function mirrors one rule of the grammar, PEG semantics included:
//! ordered choice, greedy repetition that gives back what a failed
//! repetition consumed, and pest's implicit `WHITESPACE`/`COMMENT` skipping
//! between the parts of a non-atomic rule (`skip`). Where pest would
//! backtrack out of a failure that can only end in a syntax error (an
//! operator with no operand, a `(` that opens no call), this parser gives
//! up at once.

use crate::ast::*;

/// Parses `text` (a batch of whole items starting at byte `offset` of its
/// file) as the grammar's `file` rule, appending its items to `out`.
/// `None` when pest must do it instead; `out` is then as it was.
pub(crate) fn items(text: &str, offset: usize, out: &mut Vec<Item>) -> Option<()> {
    let before = out.len();
    let mut p = Descent {
        s: text.as_bytes(),
        text,
        pos: 0,
        offset: offset as u32,
        infixes: 0,
        last_postfix: false,
    };
    let ok = p.file(out);
    if ok.is_none() {
        out.truncate(before);
    }
    ok
}

/// Why a rule did not produce a node: in every case pest takes over.
type R<T> = Option<T>;

/// An expression and the depth of its tree (as `parser::depth` counts).
type Node = (Expr, u32);

struct Descent<'a> {
    s: &'a [u8],
    text: &'a str,
    pos: usize,
    offset: u32,
    /// Infix operators consumed by the expression being parsed, at its
    /// own level (`expr_with_tail` saves and resets it around nested ones).
    infixes: usize,
    /// Whether the operand parsed last had a call or block after it.
    last_postfix: bool,
}

const KEYWORDS: [&str; 8] = [
    "use", "let", "job", "surface", "tool", "machine", "strategy", "dialect",
];

fn is_ident_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// A node no deeper than the limit, else give up (pest reports it).
fn bounded(e: Expr, d: u32) -> R<Node> {
    (d <= MAX_EXPR_DEPTH).then_some((e, d))
}

impl<'a> Descent<'a> {
    fn peek(&self) -> u8 {
        self.s.get(self.pos).copied().unwrap_or(0)
    }

    fn at(&self, lit: &[u8]) -> bool {
        self.s[self.pos..].starts_with(lit)
    }

    fn span(&self, start: usize, end: usize) -> Span {
        Span {
            start: start as u32 + self.offset,
            end: end as u32 + self.offset,
        }
    }

    /// Consumes `b` if it is next.
    fn eat(&mut self, b: u8) -> bool {
        let hit = self.peek() == b;
        self.pos += usize::from(hit);
        hit
    }

    /// Requires `b` next (after nothing skipped): gives up otherwise.
    fn expect(&mut self, b: u8) -> R<()> {
        self.eat(b).then_some(())
    }

    /// pest's implicit `(WHITESPACE | COMMENT)*` between the parts of a
    /// non-atomic rule. An unclosed `/*` is not a comment: it stays.
    fn skip(&mut self) {
        loop {
            match self.peek() {
                b' ' | b'\t' | b'\r' | b'\n' => self.pos += 1,
                0xEF if self.at("\u{FEFF}".as_bytes()) => self.pos += 3,
                b'/' if self.at(b"//") => {
                    self.pos = match memchr_newline(&self.s[self.pos..]) {
                        Some(n) => self.pos + n,
                        None => self.s.len(),
                    };
                }
                b'/' if self.at(b"/*") => {
                    let body = &self.s[self.pos + 2..];
                    match body.windows(2).position(|w| w == b"*/") {
                        Some(n) => self.pos += 2 + n + 2,
                        None => return,
                    }
                }
                _ => return,
            }
        }
    }

    /// The end of the run of `ident_char`s starting at `from`.
    fn word_end(&self, from: usize) -> usize {
        let run = self.s[from..].iter().take_while(|&&b| is_ident_char(b));
        from + run.count()
    }

    /// The word here if it starts like a name (`ASCII_ALPHA | "_"`).
    fn word(&self) -> Option<(usize, usize)> {
        let b = self.peek();
        (b.is_ascii_alphabetic() || b == b'_').then(|| (self.pos, self.word_end(self.pos)))
    }

    /// `param_name`: any word.
    fn param_name(&mut self) -> R<Ident> {
        let (start, end) = self.word()?;
        self.pos = end;
        Some(Ident {
            name: self.text[start..end].to_string(),
            span: self.span(start, end),
        })
    }

    /// `ident`: a word that is not a keyword.
    fn ident(&mut self) -> R<Ident> {
        let (start, end) = self.word()?;
        if KEYWORDS.contains(&&self.text[start..end]) {
            return None;
        }
        self.param_name()
    }

    /// `file = { SOI ~ item* ~ EOI }`
    fn file(&mut self, out: &mut Vec<Item>) -> R<()> {
        loop {
            self.skip();
            if self.pos == self.s.len() {
                return Some(());
            }
            out.push(self.item()?);
        }
    }

    /// `item = _{ use_item | let_item | decl_item | job_item }`: the four
    /// begin with different keywords, so the keyword chooses.
    fn item(&mut self) -> R<Item> {
        let start = self.pos;
        let (_, kw_end) = self.word()?;
        let keyword = &self.text[start..kw_end];
        self.pos = kw_end;
        self.skip();
        let kind = match keyword {
            "use" => ItemKind::Use(self.use_target()?),
            "let" => {
                let (name, value) = self.named_value()?;
                ItemKind::Let { name, value }
            }
            "job" => {
                let name = self.ident()?;
                self.skip();
                let body = self.block()?.0;
                ItemKind::Job { name, body }
            }
            _ => {
                let kind = DeclKind::from_keyword(keyword)?;
                let (name, value) = self.named_value()?;
                ItemKind::Decl { kind, name, value }
            }
        };
        Some(Item {
            kind,
            span: self.span(start, self.pos),
        })
    }

    /// `ident ~ "=" ~ expr`, the rest of `let_item` and `decl_item`,
    /// ending where pest's `expr` rule ends (`expr_with_tail`).
    fn named_value(&mut self) -> R<(Ident, Expr)> {
        let name = self.ident()?;
        self.skip();
        self.expect(b'=')?;
        self.skip();
        let ((value, _), tail) = self.expr_with_tail()?;
        if tail {
            self.skip();
        }
        Some((name, value))
    }

    /// `(string | std_path)` after `use`.
    fn use_target(&mut self) -> R<UseTarget> {
        if self.peek() == b'"' {
            let (path, span) = self.string()?;
            return Some(UseTarget::File { path, span });
        }
        // std_path = { param_name ~ ("::" ~ param_name)+ }
        let mut segments = vec![self.param_name()?];
        loop {
            let save = self.pos;
            self.skip();
            if !self.at(b"::") {
                self.pos = save;
                break;
            }
            self.pos += 2;
            self.skip();
            segments.push(self.param_name()?);
        }
        // pest reads `x+` as `x ~ x*`: one `::` segment and the rule ends
        // past the blanks after it (see `expr_with_tail`).
        if segments.len() == 2 {
            self.skip();
        }
        (segments.len() > 1).then_some(UseTarget::Std(segments))
    }

    /// `expr = { prefix* ~ operand ~ (infix ~ prefix* ~ operand)* }`, with
    /// the precedence and associativity of `parser::PRATT` applied as
    /// pest's Pratt parser does (the same binding powers).
    fn expr(&mut self) -> R<Node> {
        Some(self.expr_with_tail()?.0)
    }

    /// `expr`, and whether pest's `expr` rule ends after the blanks and
    /// comments that follow it. In `a ~ b*` pest skips blanks before
    /// trying `b*` and keeps them when `b*` matches nothing, so `operand`
    /// without a postfix and `expr` without an infix end past the blanks;
    /// an operand after an infix ends the rule where it ends.
    fn expr_with_tail(&mut self) -> R<(Node, bool)> {
        let outer = std::mem::replace(&mut self.infixes, 0);
        let node = self.climb(0);
        let tail = self.infixes == 0 || !self.last_postfix;
        self.infixes = outer;
        Some((node?, tail))
    }

    fn climb(&mut self, rbp: u8) -> R<Node> {
        let (mut lhs, mut dl) = if self.peek() == b'-' {
            // prefix: `neg`, binding power 50; its operand is parsed at 49.
            let start = self.pos;
            self.pos += 1;
            self.skip();
            let (rhs, d) = self.climb(49)?;
            let span = self.span(start, start + 1).to(rhs.span);
            let kind = ExprKind::Unary {
                op: UnaryOp::Neg,
                operand: Box::new(rhs),
            };
            bounded(Expr { kind, span }, d + 1)?
        } else {
            self.operand()?
        };
        loop {
            let save = self.pos;
            self.skip();
            let Some((op, len, lbp)) = self.infix() else {
                self.pos = save;
                break;
            };
            if lbp <= rbp {
                self.pos = save;
                break;
            }
            self.pos += len;
            self.infixes += 1;
            self.skip();
            let next = if op == BinaryOp::Pow { lbp - 1 } else { lbp };
            let (rhs, dr) = self.climb(next)?;
            let span = lhs.span.to(rhs.span);
            let kind = ExprKind::Binary {
                op,
                lhs: Box::new(lhs),
                rhs: Box::new(rhs),
            };
            (lhs, dl) = bounded(Expr { kind, span }, dl.max(dr) + 1)?;
        }
        Some((lhs, dl))
    }

    /// The infix operator here: which, its length and binding power
    /// (`range_op` 20, `add`/`sub` 30, `mul`/`div` 40, `pow` 60).
    fn infix(&self) -> Option<(BinaryOp, usize, u8)> {
        Some(match self.peek() {
            b'.' if self.at(b"..") => (BinaryOp::Range, 2, 20),
            b'+' => (BinaryOp::Add, 1, 30),
            b'-' => (BinaryOp::Sub, 1, 30),
            b'*' => (BinaryOp::Mul, 1, 40),
            b'/' => (BinaryOp::Div, 1, 40),
            b'^' => (BinaryOp::Pow, 1, 60),
            _ => return None,
        })
    }

    /// `operand = { primary ~ postfix* }`, `postfix = _{ call_args | block }`.
    fn operand(&mut self) -> R<Node> {
        let (mut e, mut d) = self.primary()?;
        let mut postfixes = 0;
        loop {
            let save = self.pos;
            self.skip();
            let start = e.span.start;
            let (kind, inner) = match self.peek() {
                b'(' => {
                    let (args, inner) = self.call_args()?;
                    let callee = Box::new(e);
                    (ExprKind::Call { callee, args }, inner)
                }
                b'{' => {
                    let (block, inner) = self.block()?;
                    let base = Box::new(e);
                    (ExprKind::WithBlock { base, block }, inner)
                }
                _ => {
                    self.pos = save;
                    self.last_postfix = postfixes > 0;
                    return Some((e, d));
                }
            };
            let span = Span {
                start,
                end: self.pos as u32 + self.offset,
            };
            (e, d) = bounded(Expr { kind, span }, d.max(inner) + 1)?;
            postfixes += 1;
        }
    }

    /// `primary = _{ quantity | string | list | block | paren | ident }`:
    /// the first byte tells which can match.
    fn primary(&mut self) -> R<Node> {
        let start = self.pos;
        let kind = match self.peek() {
            b'0'..=b'9' => return self.quantity().map(|e| (e, 1)),
            b'"' => ExprKind::Str(self.string()?.0),
            b'[' => {
                self.pos += 1;
                let (items, d) = self.list_of(b']', Self::expr)?;
                let items = items.into_iter().map(|(e, _)| e).collect();
                return bounded(
                    Expr {
                        kind: ExprKind::List(items),
                        span: self.span(start, self.pos),
                    },
                    d + 1,
                );
            }
            b'{' => {
                let (block, d) = self.block()?;
                return bounded(
                    Expr {
                        kind: ExprKind::Block(block),
                        span: self.span(start, self.pos),
                    },
                    d + 1,
                );
            }
            b'(' => {
                // paren = { "(" ~ expr ~ ")" }: the inner tree, the paren's span.
                self.pos += 1;
                self.skip();
                let (inner, d) = self.expr()?;
                self.skip();
                self.expect(b')')?;
                let e = Expr {
                    kind: inner.kind,
                    span: self.span(start, self.pos),
                };
                return Some((e, d));
            }
            _ => ExprKind::Name(self.ident()?.name),
        };
        Some((
            Expr {
                kind,
                span: self.span(start, self.pos),
            },
            1,
        ))
    }

    /// `"(" ~ (arg ~ ("," ~ arg)* ~ ","?)? ~ ")"`, at the `(`.
    fn call_args(&mut self) -> R<(Vec<Arg>, u32)> {
        self.pos += 1;
        let (args, d) = self.list_of(b')', Self::arg)?;
        Some((args.into_iter().map(|(a, _)| a).collect(), d))
    }

    /// The rest of `list` or `call_args` after the opening bracket:
    /// `(x ~ ("," ~ x)* ~ ","?)? ~ close`, and the deepest element.
    fn list_of<T>(
        &mut self,
        close: u8,
        mut element: impl FnMut(&mut Self) -> R<(T, u32)>,
    ) -> R<(Vec<(T, u32)>, u32)> {
        let mut items = Vec::new();
        let mut deepest = 0;
        self.skip();
        while !self.eat(close) {
            if !items.is_empty() {
                self.expect(b',')?;
                self.skip();
                if self.eat(close) {
                    break;
                }
            }
            let (x, d) = element(self)?;
            deepest = deepest.max(d);
            items.push((x, d));
            self.skip();
        }
        Some((items, deepest))
    }

    /// `arg = { (param_name ~ ":" ~ !":")? ~ expr }`
    fn arg(&mut self) -> R<(Arg, u32)> {
        let save = self.pos;
        let mut name = None;
        if self.word().is_some() {
            let n = self.param_name()?;
            self.skip();
            if self.eat(b':') {
                self.skip();
                if self.peek() != b':' {
                    name = Some(n);
                }
            }
            if name.is_none() {
                self.pos = save;
            }
        }
        let (value, d) = self.expr()?;
        Some((Arg { name, value }, d))
    }

    /// `block = { "{" ~ (entry ~ ","?)* ~ "}" }` at the `{`, and the
    /// depth of its deepest entry.
    fn block(&mut self) -> R<(Block, u32)> {
        let start = self.pos;
        self.expect(b'{')?;
        let mut entries = Vec::new();
        let mut deepest = 0;
        loop {
            self.skip();
            if self.eat(b'}') {
                break;
            }
            let (entry, d) = self.entry()?;
            deepest = deepest.max(d);
            entries.push(entry);
            self.skip();
            self.eat(b',');
        }
        let span = self.span(start, self.pos);
        Some((Block { entries, span }, deepest))
    }

    /// `entry = _{ param_entry | formula_entry }`: `name: value` or
    /// `name(x, y) = body`.
    fn entry(&mut self) -> R<(Entry, u32)> {
        let name = self.param_name()?;
        self.skip();
        if self.eat(b':') {
            self.skip();
            let (value, d) = self.expr()?;
            return Some((Entry::Param { name, value }, d));
        }
        self.expect(b'(')?;
        self.skip();
        let mut params = vec![self.ident()?];
        loop {
            self.skip();
            if !self.eat(b',') {
                break;
            }
            self.skip();
            params.push(self.ident()?);
        }
        self.expect(b')')?;
        self.skip();
        self.expect(b'=')?;
        self.skip();
        let (body, d) = self.expr()?;
        Some((Entry::Formula { name, params, body }, d))
    }

    /// `quantity = ${ number ~ (unit_gap ~ unit)? }`
    fn quantity(&mut self) -> R<Expr> {
        let start = self.pos;
        let end = self.number();
        let value: f64 = self.text[start..end].parse().unwrap_or(f64::INFINITY);
        if !value.is_finite() {
            return None;
        }
        self.pos = end;
        let gap = self.s[end..]
            .iter()
            .take_while(|&&b| b == b' ' || b == b'\t')
            .count();
        self.pos = end + gap;
        let unit = self.unit()?;
        if unit.is_none() {
            self.pos = end;
        }
        Some(Expr {
            kind: ExprKind::Quantity { value, unit },
            span: self.span(start, self.pos),
        })
    }

    /// `number = @{ DIGIT+ ~ ("." ~ DIGIT+)? ~ (("e" | "E") ~ ("+" | "-")? ~ DIGIT+)? }`:
    /// where it ends (it starts at a digit).
    fn number(&self) -> usize {
        let digits = |from: usize| {
            from + self.s[from..]
                .iter()
                .take_while(|b| b.is_ascii_digit())
                .count()
        };
        let mut end = digits(self.pos);
        if self.s.get(end) == Some(&b'.') && digits(end + 1) > end + 1 {
            end = digits(end + 1);
        }
        if matches!(self.s.get(end), Some(b'e' | b'E')) {
            let sign = usize::from(matches!(self.s.get(end + 1), Some(b'+' | b'-')));
            let exp_end = digits(end + 1 + sign);
            if exp_end > end + 1 + sign {
                end = exp_end;
            }
        }
        end
    }

    /// `unit = ${ unit_part ~ ("/" ~ unit_part)* ~ !((" " | "\t")* ~ (":" | "=")) }`:
    /// `Some(None)` where no unit matches here (the number stands alone),
    /// `None` where pest must take over (a power of zero).
    fn unit(&mut self) -> R<Option<Unit>> {
        let start = self.pos;
        let Some(first) = self.unit_part(true)? else {
            return Some(None);
        };
        let mut parts = vec![first];
        while self.peek() == b'/' {
            let save = self.pos;
            self.pos += 1;
            match self.unit_part(false)? {
                Some(part) => parts.push(part),
                None => {
                    self.pos = save;
                    break;
                }
            }
        }
        let end = self.pos;
        let gap = self.s[end..]
            .iter()
            .take_while(|&&b| b == b' ' || b == b'\t')
            .count();
        if matches!(self.s.get(end + gap), Some(b':' | b'=')) {
            return Some(None);
        }
        Some(Some(Unit {
            parts,
            span: self.span(start, end),
        }))
    }

    /// `unit_part = ${ unit_name ~ ("^" ~ unit_power)? }`; a part after a
    /// `/` has its power negated, as `Builder::quantity` does.
    fn unit_part(&mut self, first: bool) -> R<Option<UnitPart>> {
        let start = self.pos;
        let Some(name_end) = self.unit_name() else {
            return Some(None);
        };
        self.pos = name_end;
        let mut power = 1;
        if self.peek() == b'^' {
            let neg = usize::from(self.s.get(self.pos + 1) == Some(&b'-'));
            let from = self.pos + 1 + neg;
            let n = self.s[from..]
                .iter()
                .take(2)
                .take_while(|b| b.is_ascii_digit())
                .count();
            if n > 0 {
                power = self.text[self.pos + 1..from + n].parse().unwrap_or(1);
                self.pos = from + n;
            }
        }
        if power == 0 {
            return None;
        }
        Some(Some(UnitPart {
            name: self.text[start..name_end].to_string(),
            power: if first { power } else { -power },
            span: self.span(start, self.pos),
        }))
    }

    /// `unit_name = @{ "°" | (("µ" | "μ") ~ ASCII_ALPHA+) | (!keyword ~ ASCII_ALPHA ~ ident_char*) }`:
    /// where the name ends, if one starts here.
    fn unit_name(&self) -> Option<usize> {
        if self.at("°".as_bytes()) {
            return Some(self.pos + "°".len());
        }
        for micro in ["µ", "μ"] {
            if self.at(micro.as_bytes()) {
                let from = self.pos + micro.len();
                let n = self.s[from..]
                    .iter()
                    .take_while(|b| b.is_ascii_alphabetic())
                    .count();
                return (n > 0).then_some(from + n);
            }
        }
        if !self.peek().is_ascii_alphabetic() {
            return None;
        }
        let end = self.word_end(self.pos);
        (!KEYWORDS.contains(&&self.text[self.pos..end])).then_some(end)
    }

    /// `string = ${ "\"" ~ string_body ~ "\"" }` at the quote: the text
    /// with its escapes replaced, and the string's span (quotes included).
    fn string(&mut self) -> R<(String, Span)> {
        let start = self.pos;
        self.pos += 1;
        let mut out = String::new();
        loop {
            let run = self.s[self.pos..]
                .iter()
                .take_while(|&&b| !matches!(b, b'"' | b'\\' | b'\n'))
                .count();
            out.push_str(&self.text[self.pos..self.pos + run]);
            self.pos += run;
            match self.peek() {
                b'"' => break,
                b'\\' => {
                    out.push(match self.s.get(self.pos + 1) {
                        Some(b'"') => '"',
                        Some(b'\\') => '\\',
                        Some(b'n') => '\n',
                        Some(b't') => '\t',
                        _ => return None,
                    });
                    self.pos += 2;
                }
                _ => return None,
            }
        }
        self.pos += 1;
        Some((out, self.span(start, self.pos)))
    }
}

fn memchr_newline(s: &[u8]) -> Option<usize> {
    s.iter().position(|&b| b == b'\n')
}
