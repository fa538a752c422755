//! LinuxCNC's parameters and expressions, as its interpreter reads them
//! (LinuxCNC documentation 2.9, chapter 11, sections 11.4.3 "Parameters"
//! to 11.4.7 "Functions", pp. 843–850): a word's value may be a number,
//! a parameter (`#12`, `#<name>`, `#<_global>`) or an expression in
//! brackets (`[#1 * 2 + SIN[30]]`); `#n=value` and `#<name>=value` set a
//! parameter, taking effect once the whole line is read. A numbered
//! parameter never set reads 0; a named one never set is refused, as the
//! interpreter refuses it. Angles of the trigonometric functions are in
//! degrees.

use std::collections::HashMap;

/// The parameters set so far.
#[derive(Default, Debug)]
pub(crate) struct Parameters {
    numbered: HashMap<u32, f64>,
    named: HashMap<String, f64>,
}

/// Which parameter a `#` names.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Name {
    Numbered(u32),
    Named(String),
}

impl Parameters {
    pub fn get(&self, n: &Name) -> Result<f64, String> {
        match n {
            Name::Numbered(k) => Ok(self.numbered.get(k).copied().unwrap_or(0.0)),
            Name::Named(s) => self
                .named
                .get(s)
                .copied()
                .ok_or_else(|| format!("the parameter #<{s}> is read before it is set")),
        }
    }

    pub fn set(&mut self, n: Name, v: f64) {
        match n {
            Name::Numbered(k) => {
                self.numbered.insert(k, v);
            }
            Name::Named(s) => {
                self.named.insert(s, v);
            }
        }
    }
}

/// Reads at `code[i..]` a value: a number, a parameter or a bracketed
/// expression, with a sign before it; returns it and where it ends.
pub(crate) fn value(code: &str, i: usize, p: &Parameters) -> Result<(f64, usize), String> {
    Reader { code, i, p }.unary()
}

/// Reads at `code[i..]` (just after a `#`) the name of a parameter and
/// where it ends.
pub(crate) fn name(code: &str, i: usize, p: &Parameters) -> Result<(Name, usize), String> {
    let mut r = Reader { code, i, p };
    let n = r.name()?;
    Ok((n, r.i))
}

struct Reader<'a> {
    code: &'a str,
    i: usize,
    p: &'a Parameters,
}

impl Reader<'_> {
    fn skip(&mut self) {
        let b = self.code.as_bytes();
        while self.i < b.len() && b[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip();
        self.code.as_bytes().get(self.i).copied()
    }

    /// A word of letters (an operator or a function), upper-cased.
    fn word_at(&mut self) -> String {
        self.skip();
        let b = self.code.as_bytes();
        let mut j = self.i;
        while j < b.len() && b[j].is_ascii_alphabetic() {
            j += 1;
        }
        self.code[self.i..j].to_ascii_uppercase()
    }

    fn name(&mut self) -> Result<Name, String> {
        if self.peek() == Some(b'<') {
            let close = self.code[self.i..]
                .find('>')
                .ok_or("a parameter name `#<…` never closed")?;
            let n: String = self.code[self.i + 1..self.i + close]
                .chars()
                .filter(|c| !c.is_whitespace())
                .collect::<String>()
                .to_ascii_lowercase();
            self.i += close + 1;
            return Ok(Name::Named(n));
        }
        let v = self.primary()?;
        if !(1.0..=5601.0).contains(&v) || v.fract() != 0.0 {
            return Err(format!("#{v} is not a parameter number (1 to 5601)"));
        }
        Ok(Name::Numbered(v as u32))
    }

    fn unary(&mut self) -> Result<(f64, usize), String> {
        let v = match self.peek() {
            Some(b'-') => {
                self.i += 1;
                -self.primary()?
            }
            Some(b'+') => {
                self.i += 1;
                self.primary()?
            }
            _ => self.primary()?,
        };
        if !v.is_finite() {
            return Err("the value is not a finite number".into());
        }
        Ok((v, self.i))
    }

    fn primary(&mut self) -> Result<f64, String> {
        match self.peek() {
            Some(b'[') => {
                self.i += 1;
                let v = self.expression(0)?;
                if self.peek() != Some(b']') {
                    return Err("an expression's `[` never closed".into());
                }
                self.i += 1;
                Ok(v)
            }
            Some(b'#') => {
                self.i += 1;
                let n = self.name()?;
                self.p.get(&n)
            }
            Some(b'-') => {
                self.i += 1;
                Ok(-self.primary()?)
            }
            Some(b'+') => {
                self.i += 1;
                self.primary()
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let b = self.code.as_bytes();
                let start = self.i;
                while self.i < b.len() && (b[self.i].is_ascii_digit() || b[self.i] == b'.') {
                    self.i += 1;
                }
                self.code[start..self.i]
                    .parse::<f64>()
                    .map_err(|_| "a malformed number".to_string())
            }
            Some(c) if c.is_ascii_alphabetic() => self.function(),
            _ => Err("a number, parameter or expression was expected".into()),
        }
    }

    fn function(&mut self) -> Result<f64, String> {
        let f = self.word_at();
        self.i += f.len();
        if f == "EXISTS" {
            if self.peek() != Some(b'[') {
                return Err("EXISTS takes [#<name>]".into());
            }
            self.i += 1;
            if self.peek() != Some(b'#') {
                return Err("EXISTS takes [#<name>]".into());
            }
            self.i += 1;
            let n = self.name()?;
            if self.peek() != Some(b']') {
                return Err("EXISTS[ never closed".into());
            }
            self.i += 1;
            return Ok(if self.p.get(&n).is_ok() { 1.0 } else { 0.0 });
        }
        if self.peek() != Some(b'[') {
            return Err(format!("`{f}` is not a function LinuxCNC reads"));
        }
        let a = self.primary()?;
        let deg = |v: f64| v.to_radians();
        Ok(match f.as_str() {
            "ABS" => a.abs(),
            "ACOS" => a.acos().to_degrees(),
            "ASIN" => a.asin().to_degrees(),
            "ATAN" => {
                if self.peek() != Some(b'/') {
                    return Err("ATAN takes [y]/[x]".into());
                }
                self.i += 1;
                let x = self.primary()?;
                a.atan2(x).to_degrees()
            }
            "COS" => deg(a).cos(),
            "SIN" => deg(a).sin(),
            "TAN" => deg(a).tan(),
            "EXP" => a.exp(),
            "LN" => a.ln(),
            "SQRT" => a.sqrt(),
            "FIX" => a.floor(),
            "FUP" => a.ceil(),
            "ROUND" => a.round(),
            _ => return Err(format!("`{f}` is not a function LinuxCNC reads")),
        })
    }

    /// Binary operators by precedence (manual 11.4.6): `**` over `* / MOD`
    /// over `+ -` over the comparisons over `AND OR XOR`.
    fn expression(&mut self, level: u8) -> Result<f64, String> {
        if level > 4 {
            return self.primary();
        }
        let mut v = self.expression(level + 1)?;
        loop {
            let op = match self.peek() {
                Some(b'*') if self.code[self.i..].starts_with("**") => "**".to_string(),
                Some(c @ (b'*' | b'/' | b'+' | b'-')) => (c as char).to_string(),
                Some(c) if c.is_ascii_alphabetic() => self.word_at(),
                _ => return Ok(v),
            };
            let at = match op.as_str() {
                "**" => 4,
                "*" | "/" | "MOD" => 3,
                "+" | "-" => 2,
                "EQ" | "NE" | "GT" | "GE" | "LT" | "LE" => 1,
                "AND" | "OR" | "XOR" => 0,
                _ => return Err(format!("`{op}` is not an operator LinuxCNC reads")),
            };
            if at != level {
                return Ok(v);
            }
            self.i += op.len();
            let w = self.expression(level + 1)?;
            let truth = |b: bool| if b { 1.0 } else { 0.0 };
            v = match op.as_str() {
                "**" => v.powf(w),
                "*" => v * w,
                "/" if w == 0.0 => return Err("a division by zero".into()),
                "/" => v / w,
                "MOD" => v.rem_euclid(w),
                "+" => v + w,
                "-" => v - w,
                "EQ" => truth(v == w),
                "NE" => truth(v != w),
                "GT" => truth(v > w),
                "GE" => truth(v >= w),
                "LT" => truth(v < w),
                "LE" => truth(v <= w),
                "AND" => truth(v != 0.0 && w != 0.0),
                "OR" => truth(v != 0.0 || w != 0.0),
                _ => truth((v != 0.0) != (w != 0.0)),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(s: &str, p: &Parameters) -> Result<f64, String> {
        value(s, 0, p).map(|(v, _)| v)
    }

    #[test]
    fn expressions_read_as_linuxcnc_reads_them() {
        let mut p = Parameters::default();
        p.set(Name::Numbered(1), 2.0);
        p.set(Name::Named("depth".into()), -0.5);
        for (text, want) in [
            ("[1+1]", 2.0),
            ("[#1*3+1]", 7.0),
            ("[2**3*2]", 16.0),
            ("[1+2*3]", 7.0),
            ("[[1+2]*3]", 9.0),
            ("#1", 2.0),
            ("-#1", -2.0),
            ("#<depth>", -0.5),
            ("#<_x>", f64::NAN),
            ("#7", 0.0),
            ("[SIN[30]]", 0.5),
            ("[ATAN[1]/[1]]", 45.0),
            ("[7 MOD 4]", 3.0),
            ("[1 LT 2]", 1.0),
            ("[ABS[-3] + SQRT[16]]", 7.0),
            ("[EXISTS[#<depth>]]", 1.0),
        ] {
            match eval(text, &p) {
                Ok(v) => assert!((v - want).abs() < 1e-12, "{text}: {v}"),
                Err(e) => assert!(want.is_nan(), "{text}: {e}"),
            }
        }
        assert!(eval("[1+", &p).is_err());
        assert!(eval("[1/0]", &p).is_err());
        assert!(eval("[FOO[1]]", &p).is_err());
    }
}
