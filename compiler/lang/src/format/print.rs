//! The printer: walks the syntax tree and writes each token in the
//! canonical layout, emitting every comment just before the first token
//! written after it (own-line comments on their own lines, trailing ones
//! after their element), so none is lost or moved past another token.

use lensc_grammar::ast::*;

use super::trivia::{Comment, Trivia};

/// One level of indentation.
const INDENT: &str = "    ";

pub(super) struct Printer<'t, 's> {
    t: &'t Trivia<'s>,
    /// Comments before this index are written.
    next: usize,
    out: String,
    indent: usize,
}

/// How the elements of a sequence are separated when one a line.
#[derive(Clone, Copy)]
enum Sep {
    /// Block entries and items: the line break is enough.
    Line,
    /// List elements and call arguments: a comma after each, the last too.
    Comma,
}

impl<'t, 's> Printer<'t, 's> {
    pub fn new(t: &'t Trivia<'s>) -> Self {
        Printer {
            t,
            next: 0,
            out: String::with_capacity(t.src.len() + t.src.len() / 8),
            indent: 0,
        }
    }

    /// The whole file: its items one after another, blank lines kept
    /// (at most one in a row), ending in one line break.
    pub fn file(mut self, file: &File) -> String {
        let spans: Vec<Span> = file.items.iter().map(|i| self.item_span(i)).collect();
        self.seq(0, self.t.src.len(), &spans, Sep::Line, true, &mut |p, k| {
            p.item(&file.items[k])
        });
        if !self.out.is_empty() {
            self.out.push('\n');
        }
        self.out
    }

    // ---- writing ----

    fn src(&self, a: usize, b: usize) -> &'s str {
        &self.t.src[a..b]
    }

    fn peek(&self) -> Option<Comment> {
        self.t.comments.get(self.next).copied()
    }

    /// A line break and the current indentation (nothing at the very start).
    fn newline(&mut self) {
        if self.out.is_empty() {
            return;
        }
        self.out.push('\n');
        for _ in 0..self.indent {
            self.out.push_str(INDENT);
        }
    }

    /// An empty line before the next line (nothing at the very start).
    fn blank_line(&mut self) {
        if !self.out.is_empty() {
            self.out.push('\n');
        }
    }

    fn comment(&mut self, c: Comment) {
        let text = self.t.text(c);
        self.out.push_str(&text);
        self.next += 1;
    }

    /// Writes the comments that lie before `pos` inside an element, where
    /// they were: a block comment between the tokens around it, a line
    /// comment ending its line (the element continues on the next line,
    /// indented one more level).
    fn flush_before(&mut self, pos: usize) {
        while let Some(c) = self.peek().filter(|c| c.start < pos) {
            if !self.out.is_empty() && !self.out.ends_with([' ', '\n', '(', '[']) {
                self.out.push(' ');
            }
            self.comment(c);
            if c.line {
                self.indent += 1;
                self.newline();
                self.indent -= 1;
            } else {
                self.out.push(' ');
            }
        }
    }

    /// A token written at source position `pos`, after the comments before it.
    fn tok(&mut self, pos: usize, text: &str) {
        self.flush_before(pos);
        self.out.push_str(text);
    }

    /// Comments on the same source line as `*prev` and before `limit`,
    /// written after the element that ends there; a block comment after
    /// the comma, which the element at `limit` (`next`) follows on its
    /// line, is left to lead that element.
    fn trailing(&mut self, prev: &mut usize, limit: usize, next: bool) {
        while let Some(c) = self.peek().filter(|c| c.start < limit) {
            let after_comma = self
                .t
                .src
                .get(*prev..c.start)
                .is_some_and(|s| s.contains(','));
            if self.t.newlines(*prev, c.start) > 0 || (after_comma && self.leads(c, limit, next)) {
                return;
            }
            self.out.push(' ');
            self.comment(c);
            *prev = c.end;
            if c.line {
                return;
            }
        }
    }

    /// Whether the block comment `c` leads the element starting at `limit`
    /// (`next`: an element starts there, not a closing bracket): the
    /// element follows it on its line.
    fn leads(&self, c: Comment, limit: usize, next: bool) -> bool {
        next && !c.line && self.t.newlines(c.end, limit) == 0
    }

    /// Comments before `limit` on lines of their own, with the blank lines
    /// before them kept (none right after an opening bracket). Returns
    /// whether the last one leads the element at `limit` on its line.
    fn own_lines(&mut self, prev: &mut usize, limit: usize, next: bool, first: &mut bool) -> bool {
        while let Some(c) = self.peek().filter(|c| c.start < limit) {
            if !*first && self.t.newlines(*prev, c.start) > 1 {
                self.blank_line();
            }
            self.newline();
            self.comment(c);
            *prev = c.end;
            *first = false;
            if self.leads(c, limit, next) {
                self.out.push(' ');
                return true;
            }
            self.trailing(prev, limit, next);
        }
        false
    }

    /// A sequence laid out one element a line, between an opening bracket
    /// ending at `open_end` and a closing one at `close` (for the file: its
    /// start and end). `top`: the file, not indented.
    fn seq(
        &mut self,
        open_end: usize,
        close: usize,
        spans: &[Span],
        sep: Sep,
        top: bool,
        print: &mut dyn FnMut(&mut Self, usize),
    ) {
        let mut prev = open_end;
        if !top {
            let limit = spans.first().map_or(close, |s| s.start as usize);
            self.trailing(&mut prev, limit, !spans.is_empty());
            self.indent += 1;
        }
        let mut first = true;
        for (k, span) in spans.iter().enumerate() {
            let start = span.start as usize;
            if !self.own_lines(&mut prev, start, true, &mut first) {
                if !first && self.t.newlines(prev, start) > 1 {
                    self.blank_line();
                }
                self.newline();
            }
            first = false;
            print(self, k);
            if let Sep::Comma = sep {
                self.out.push(',');
            }
            prev = span.end as usize;
            let next = spans.get(k + 1);
            let limit = next.map_or(close, |s| s.start as usize);
            self.trailing(&mut prev, limit, next.is_some());
        }
        self.own_lines(&mut prev, close, false, &mut first);
        if !top {
            self.indent -= 1;
            self.newline();
        }
    }

    /// Elements between brackets at `open` and `close`: on one line
    /// (`flat`) or one a line; the brackets are written by the caller.
    fn elements(
        &mut self,
        open: usize,
        close: usize,
        spans: &[Span],
        sep: Sep,
        pad: &str,
        print: &mut dyn FnMut(&mut Self, usize),
    ) {
        let broken = if spans.is_empty() {
            self.t.has_comment(open, close)
        } else {
            self.t.broken(open, close)
        };
        if broken {
            self.seq(open + 1, close, spans, sep, false, print);
        } else if !spans.is_empty() {
            self.out.push_str(pad);
            for k in 0..spans.len() {
                if k > 0 {
                    self.out.push_str(", ");
                }
                print(self, k);
            }
            self.out.push_str(pad);
        }
        self.tok(close, "");
    }

    // ---- items ----

    /// From an item's keyword to its last token (the parser's item span
    /// may run on over the blanks and comments after it).
    fn item_span(&self, item: &Item) -> Span {
        let end = match &item.kind {
            ItemKind::Use(UseTarget::Std(segments)) => {
                segments.last().map_or(item.span, |s| s.span)
            }
            ItemKind::Use(UseTarget::File { span, .. }) => *span,
            ItemKind::Let { value, .. } | ItemKind::Decl { value, .. } => value.span,
            ItemKind::Job { body, .. } => body.span,
        };
        Span::new(
            self.t.skip_forward(item.span.start as usize),
            end.end as usize,
        )
    }

    fn item(&mut self, item: &Item) {
        let start = self.t.skip_forward(item.span.start as usize);
        match &item.kind {
            ItemKind::Use(UseTarget::Std(segments)) => {
                self.tok(start, "use ");
                for (k, s) in segments.iter().enumerate() {
                    if k > 0 {
                        self.out.push_str("::");
                    }
                    self.tok(s.span.start as usize, &s.name);
                }
            }
            ItemKind::Use(UseTarget::File { span, .. }) => {
                self.tok(start, "use ");
                let text = self.src(span.start as usize, span.end as usize);
                self.tok(span.start as usize, text);
            }
            ItemKind::Let { name, value } => {
                self.tok(start, "let ");
                self.binding(name, value);
            }
            ItemKind::Decl { kind, name, value } => {
                self.tok(start, kind.keyword());
                self.out.push(' ');
                self.binding(name, value);
            }
            ItemKind::Job { name, body } => {
                self.tok(start, "job ");
                self.tok(name.span.start as usize, &name.name);
                self.out.push(' ');
                self.block(body);
            }
        }
    }

    /// `name = value`
    fn binding(&mut self, name: &Ident, value: &Expr) {
        self.tok(name.span.start as usize, &name.name);
        self.out.push_str(" = ");
        self.expr(value);
    }

    fn block(&mut self, b: &Block) {
        let (open, close) = (b.span.start as usize, b.span.end as usize - 1);
        self.tok(open, "{");
        let spans: Vec<Span> = b.entries.iter().map(Entry::span).collect();
        self.elements(open, close, &spans, Sep::Line, " ", &mut |p, k| {
            p.entry(&b.entries[k])
        });
        self.out.push('}');
    }

    fn entry(&mut self, e: &Entry) {
        match e {
            Entry::Param { name, value } => {
                self.tok(name.span.start as usize, &name.name);
                self.out.push_str(": ");
                self.expr(value);
            }
            Entry::Formula { name, params, body } => {
                self.tok(name.span.start as usize, &name.name);
                self.out.push('(');
                for (k, p) in params.iter().enumerate() {
                    if k > 0 {
                        self.out.push_str(", ");
                    }
                    self.tok(p.span.start as usize, &p.name);
                }
                self.out.push_str(") = ");
                self.expr(body);
            }
        }
    }

    // ---- expressions ----

    /// The parentheses around `e` as written (the parser keeps the
    /// expression, not the brackets): how many, and where its own text
    /// starts and ends inside them.
    fn parens(&self, e: &Expr) -> (usize, usize, usize) {
        let own_start = match &e.kind {
            ExprKind::Binary { lhs: first, .. }
            | ExprKind::Call { callee: first, .. }
            | ExprKind::WithBlock { base: first, .. } => first.span.start as usize,
            _ => usize::MAX,
        };
        let bytes = self.t.src.as_bytes();
        let (mut n, mut start) = (0, e.span.start as usize);
        loop {
            let p = self.t.skip_forward(start);
            if p < own_start && bytes.get(p) == Some(&b'(') {
                n += 1;
                start = p + 1;
            } else {
                start = p;
                break;
            }
        }
        let mut end = e.span.end as usize;
        for _ in 0..n {
            end = self.t.skip_back(end) - 1;
        }
        (n, start, self.t.skip_back(end))
    }

    fn expr(&mut self, e: &Expr) {
        let (layers, start, end) = self.parens(e);
        if layers > 0 {
            self.tok(e.span.start as usize, "(");
            for _ in 1..layers {
                self.out.push('(');
            }
        }
        match &e.kind {
            ExprKind::Quantity { unit, .. } => {
                let text = quantity(self.t.src, start, unit.as_ref());
                self.tok(start, &text);
            }
            ExprKind::Str(_) => {
                let text = self.src(start, end);
                self.tok(start, text);
            }
            ExprKind::Name(n) => self.tok(start, n),
            ExprKind::Unary { operand, .. } => {
                self.tok(start, "-");
                self.expr(operand);
            }
            ExprKind::Binary { op, lhs, rhs } => {
                // `10 rad/(3 mm)`: a quantity over a bracketed one reads as
                // the compound unit it is (and parses as a division: no
                // unit part starts with `(`).
                let per = *op == BinaryOp::Div
                    && matches!(lhs.kind, ExprKind::Quantity { unit: Some(_), .. })
                    && self.parens(lhs).0 == 0
                    && self.parens(rhs).0 > 0;
                self.expr(lhs);
                if per {
                    self.out.push('/');
                } else {
                    self.out.push(' ');
                    self.out.push_str(op.symbol());
                    self.out.push(' ');
                }
                self.expr(rhs);
            }
            ExprKind::Call { callee, args } => {
                self.expr(callee);
                let open = self.t.skip_forward(callee.span.end as usize);
                self.tok(open, "(");
                let spans: Vec<Span> = args.iter().map(arg_span).collect();
                self.elements(open, end - 1, &spans, Sep::Comma, "", &mut |p, k| {
                    p.arg(&args[k])
                });
                self.out.push(')');
            }
            ExprKind::WithBlock { base, block } => {
                self.expr(base);
                self.out.push(' ');
                self.block(block);
            }
            ExprKind::Block(b) => self.block(b),
            ExprKind::List(items) => {
                self.tok(start, "[");
                let spans: Vec<Span> = items.iter().map(|i| i.span).collect();
                self.elements(start, end - 1, &spans, Sep::Comma, "", &mut |p, k| {
                    p.expr(&items[k])
                });
                self.out.push(']');
            }
            // Only in a tree with syntax errors, which is never printed.
            ExprKind::Invalid => {
                let text = self.src(start, end);
                self.tok(start, text);
            }
        }
        if layers > 0 {
            self.flush_before(e.span.end as usize - 1);
            // `(1 /* why */)`: no space between a comment and the bracket.
            if self.out.ends_with("*/ ") {
                self.out.pop();
            }
            for _ in 0..layers {
                self.out.push(')');
            }
        }
    }

    fn arg(&mut self, a: &Arg) {
        if let Some(name) = &a.name {
            self.tok(name.span.start as usize, &name.name);
            self.out.push_str(": ");
        }
        self.expr(&a.value);
    }
}

fn arg_span(a: &Arg) -> Span {
    match &a.name {
        Some(n) => n.span.to(a.value.span),
        None => a.value.span,
    }
}

/// A number and its unit as written, one space between them (none before
/// `°`): `85 um`, `1.2e-5 mm^-3`, `7°`.
fn quantity(src: &str, start: usize, unit: Option<&Unit>) -> String {
    let b = src.as_bytes();
    let digits = |mut i: usize| {
        while b.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    let mut end = digits(start);
    if b.get(end) == Some(&b'.') && b.get(end + 1).is_some_and(u8::is_ascii_digit) {
        end = digits(end + 1);
    }
    if matches!(b.get(end), Some(b'e' | b'E')) {
        let mut i = end + 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        if b.get(i).is_some_and(u8::is_ascii_digit) {
            end = digits(i);
        }
    }
    let mut text = src[start..end].to_string();
    if let Some(u) = unit {
        let u = &src[u.span.start as usize..u.span.end as usize];
        if !u.starts_with('°') {
            text.push(' ');
        }
        text.push_str(u);
    }
    text
}
