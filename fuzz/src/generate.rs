//! The structure-aware generator: whole `.lens` files in the grammar, with
//! the kinds, parameters, types and ranges drawn from the checker's own
//! schema (`lensc_lang::schema`), values in right and wrong units, extreme
//! numbers, `let`s, references, formulas, `use`s and random nesting. Most
//! of what it writes parses; much of it is rejected by the checker, which
//! is the point: every rejection must be a coded diagnostic with a span.

use std::fmt::Write;

use lensc_lang::schema::{self, Category, Check, JOB_PARAMS, KINDS, Kind, Param, Ty};
use lensc_lang::units::Dim;

use crate::rng::Rng;

/// Items the standard library offers, with what they are.
const STD_ITEMS: &[(&str, &str, Category)] = &[
    ("machines", "linuxcnc_lathe", Category::Machine),
    ("machines", "ultra_precision_lathe", Category::Machine),
    ("machines", "nanoform_x_fts5000", Category::Machine),
    ("machines", "generic_3axis_mill", Category::Machine),
    ("machines", "nano_grinder", Category::Machine),
    ("machines", "moore_nanotech_450fg", Category::Machine),
    ("tools", "diamond_r500um", Category::Tool),
    ("tools", "diamond_r496um", Category::Tool),
    ("tools", "microshaper_r85um", Category::Tool),
    ("tools", "wheel_d4mm", Category::Tool),
    ("strategies", "finish_turning", Category::Strategy),
    ("dialects", "linuxcnc", Category::Dialect),
    ("dialects", "fanuc_0i_lathe", Category::Dialect),
    ("dialects", "siemens_840d_lathe", Category::Dialect),
    ("dialects", "heidenhain_iso", Category::Dialect),
    ("dialects", "heidenhain_tnc_klartext", Category::Dialect),
];

/// Dimensions a wrong unit is drawn from.
const DIMS: &[Dim] = &[
    Dim::NONE,
    Dim::LENGTH,
    Dim::ANGLE,
    Dim::TIME,
    Dim::SPEED,
    Dim::FEED_PER_REV,
    Dim::ROTATIONAL_SPEED,
    Dim::FREQUENCY,
    Dim::ACCELERATION,
    Dim::new(-3, 0, 0),
    Dim::new(0, 1, -2),
];

/// Numbers at the edges of what a file can say (as written).
const EXTREMES: &[&str] = &[
    "0",
    "0.0",
    "1e308",
    "1.7976931348623157e308",
    "1e309",
    "1e999",
    "5e-324",
    "1e-300",
    "1e-12",
    "99999999999999999999999",
    "0.000000000000000000001",
    "4294967296",
    "100001",
    "65536",
];

/// Expressions that make NaN or infinity from finite numbers.
const NAN_MAKERS: &[&str] = &[
    "(0 / 0)",
    "sqrt(-1)",
    "ln(0)",
    "(1e308 * 10)",
    "(1e999 - 1e999)",
    "exp(1000)",
    "acos(2)",
    "(0 ^ -1)",
    "(-8) ^ 0.5",
];

/// Names that are not fresh: words, built-in functions, kinds, std items.
const AWKWARD_NAMES: &[&str] = &[
    "convex", "sin", "x", "y", "z", "conic", "circle", "std", "pi", "linuxcnc", "mm", "_", "A4",
];

pub struct Gen<'a> {
    rng: &'a mut Rng,
    out: String,
    /// Names declared so far and what they are.
    decls: Vec<(String, Category)>,
    lets: Vec<String>,
    depth: u32,
    fresh: u32,
    /// How wrong this file is, 0 to 1: every mistake the generator makes
    /// on purpose is scaled by it, so that some files are nearly valid and
    /// reach the checks behind the first errors.
    chaos: f64,
}

/// One generated file.
pub fn file(rng: &mut Rng) -> String {
    let mut g = Gen {
        rng,
        out: String::new(),
        decls: Vec::new(),
        lets: Vec::new(),
        depth: 0,
        fresh: 0,
        chaos: 0.0,
    };
    g.chaos = g.rng.unit().powi(2);
    let uses = g.rng.below(4);
    for _ in 0..uses {
        g.use_item();
    }
    let items = 1 + g.rng.below(10);
    for _ in 0..items {
        match g.rng.below(10) {
            0 | 1 => g.let_item(),
            2..=7 => g.decl_item(),
            _ => g.job_item(),
        }
    }
    if g.rng.chance(0.7) {
        g.job_item();
    }
    g.out
}

impl Gen<'_> {
    /// A deliberate mistake, with probability `p` at full chaos.
    fn oops(&mut self, p: f64) -> bool {
        let chaos = self.chaos;
        self.rng.chance(p * chaos)
    }

    fn name(&mut self, prefix: &str) -> String {
        if self.oops(0.1) {
            return (*self.rng.pick(AWKWARD_NAMES)).to_string();
        }
        if self.oops(0.1) && !self.decls.is_empty() {
            let i = self.rng.below(self.decls.len());
            return self.decls[i].0.clone();
        }
        self.fresh += 1;
        format!("{prefix}{}", self.fresh)
    }

    fn sep(&mut self) -> &'static str {
        ["\n    ", ", ", " ", ",\n    "][self.rng.below(4)]
    }

    fn use_item(&mut self) {
        let (module, item, cat) = *self.rng.pick(STD_ITEMS);
        match self.rng.below(8) {
            0 => {
                let _ = writeln!(self.out, "use std::{module}");
                for (m, i, c) in STD_ITEMS {
                    if *m == module {
                        self.decls.push((i.to_string(), *c));
                    }
                }
            }
            1 => {
                let path = self.rng.pick(&[
                    "part.lens",
                    "missing.lens",
                    "../up.lens",
                    "/abs.lens",
                    "",
                    "self.lens",
                    "dir/",
                    "big.lens",
                ]);
                let _ = writeln!(self.out, "use \"{path}\"");
                self.decls.push(("part_surface".into(), Category::Surface));
            }
            2 => {
                let _ = writeln!(self.out, "use std::{module}::nothing_here");
            }
            _ => {
                let _ = writeln!(self.out, "use std::{module}::{item}");
                self.decls.push((item.to_string(), cat));
            }
        }
    }

    fn let_item(&mut self) {
        let name = self.name("v");
        let dim = *self.rng.pick(DIMS);
        let _ = write!(self.out, "let {name} = ");
        self.expr(dim, &[]);
        self.out.push('\n');
        self.lets.push(name);
    }

    fn decl_item(&mut self) {
        let cat = *self.rng.pick(&[
            Category::Surface,
            Category::Surface,
            Category::Surface,
            Category::Tool,
            Category::Machine,
            Category::Strategy,
            Category::Dialect,
        ]);
        let word = match cat {
            Category::Surface => "surface",
            Category::Tool => "tool",
            Category::Machine => "machine",
            Category::Strategy => "strategy",
            _ => "dialect",
        };
        // Now and then the declared word and the kind's category disagree.
        let made = if self.oops(0.15) {
            *self
                .rng
                .pick(&[Category::Aperture, Category::Tool, Category::Surface])
        } else {
            cat
        };
        let name = self.name(&word[..1]);
        let _ = write!(self.out, "{word} {name} = ");
        self.object(made);
        self.out.push('\n');
        self.decls.push((name, cat));
    }

    fn job_item(&mut self) {
        let name = self.name("job");
        let _ = write!(self.out, "job {name} {{ ");
        self.entries(JOB_PARAMS, None);
        self.out.push_str(" }\n");
    }

    /// A value of this category: a name declared before, or a kind
    /// constructed in place (block or call syntax), or an override of a
    /// declared name.
    fn object(&mut self, cat: Category) {
        let known: Vec<String> = self
            .decls
            .iter()
            .filter(|(_, c)| *c == cat)
            .map(|(n, _)| n.clone())
            .collect();
        if !known.is_empty() && self.rng.chance(if self.depth > 2 { 0.9 } else { 0.4 }) {
            let name = self.rng.pick(&known).clone();
            self.out.push_str(&name);
            if self.rng.chance(0.15) {
                // An override: `base { a few parameters }`.
                self.out.push_str(" { ");
                if let Some(kind) = KINDS.iter().find(|k| k.category == cat) {
                    let p = self.rng.pick(kind.params);
                    self.entry(p);
                }
                self.out.push_str(" }");
            }
            return;
        }
        let kinds: Vec<&'static Kind> = KINDS.iter().filter(|k| k.category == cat).collect();
        if kinds.is_empty() || self.depth > 4 {
            self.out.push_str("nothing");
            return;
        }
        let kind = *self.rng.pick(&kinds);
        self.construct(kind);
    }

    fn construct(&mut self, kind: &'static Kind) {
        self.depth += 1;
        self.out.push_str(kind.name);
        if self.rng.chance(0.3) || !kind.positional.is_empty() && self.rng.chance(0.5) {
            self.out.push('(');
            for pos in kind.positional {
                if let Some(p) = kind.param(pos) {
                    self.value(p);
                    self.out.push_str(", ");
                }
            }
            self.params_of(kind, ", ");
            self.out.push(')');
        } else {
            self.out.push_str(" { ");
            self.entries(kind.params, kind.family);
            self.out.push_str(" }");
        }
        self.depth -= 1;
    }

    /// Named arguments in call syntax (no formulas there).
    fn params_of(&mut self, kind: &'static Kind, sep: &str) {
        for p in kind.params {
            if matches!(p.ty, Ty::Formula { .. })
                || kind.positional.contains(&p.name)
                || !self.wanted(p)
            {
                continue;
            }
            let _ = write!(self.out, "{}: ", p.name);
            self.value(p);
            self.out.push_str(sep);
        }
    }

    fn wanted(&mut self, p: &Param) -> bool {
        self.rng.chance(if p.required { 0.95 } else { 0.3 })
    }

    fn entries(&mut self, params: &'static [Param], family: Option<&'static schema::Family>) {
        for p in params {
            if self.wanted(p) {
                self.entry(p);
                let sep = self.sep();
                self.out.push_str(sep);
            }
            if self.oops(0.06) {
                // A parameter given twice.
                self.entry(p);
                self.out.push_str(", ");
            }
        }
        if let Some(family) = family {
            for _ in 0..self.rng.below(5) {
                let name = self.coefficient_name();
                let param = (family.param)(&name);
                if param.is_none() && !self.oops(0.3) {
                    continue;
                }
                let _ = write!(self.out, "{name}: ");
                match param {
                    Some(p) => self.value(&p),
                    None => self.quantity(Dim::LENGTH, Check::Any),
                }
                self.out.push_str(", ");
            }
        }
        if self.oops(0.12) {
            let _ = write!(self.out, "no_such_parameter: 1 mm, ");
        }
    }

    fn coefficient_name(&mut self) -> String {
        let n = self.rng.below(25);
        match self.rng.below(4) {
            0 => format!("A{n}"),
            1 => format!("X{}Y{}", self.rng.below(12), self.rng.below(12)),
            2 => format!("Z{}", self.rng.below(240)),
            _ => format!("Q{n}"),
        }
    }

    fn entry(&mut self, p: &Param) {
        if let Ty::Formula { coords, result } = p.ty {
            let _ = write!(self.out, "{}({}) = ", p.name, coords.join(", "));
            self.expr(result, coords);
        } else {
            let _ = write!(self.out, "{}: ", p.name);
            self.value(p);
        }
    }

    /// A value for a parameter, mostly of its type, sometimes not.
    fn value(&mut self, p: &Param) {
        if self.oops(0.12) {
            // Any type at all.
            let ty = self.rng.pick(&[
                Ty::Text,
                schema::LENGTH,
                Ty::Objects(Category::Surface),
                Ty::Range(Dim::ANGLE),
                Ty::Word(&["sideways"]),
            ]);
            return self.value_of(*ty, Check::Any);
        }
        self.value_of(p.ty, p.check);
    }

    fn value_of(&mut self, ty: Ty, check: Check) {
        match ty {
            Ty::Quantity(dims) => {
                if !self.lets.is_empty() && self.rng.chance(0.1) {
                    let name = self.rng.pick(&self.lets).clone();
                    self.out.push_str(&name);
                } else if self.rng.chance(0.15) {
                    self.expr(dims[0], &[]);
                } else {
                    let dim = if self.oops(0.25) {
                        *self.rng.pick(DIMS)
                    } else {
                        *self.rng.pick(dims)
                    };
                    self.quantity(dim, check);
                }
            }
            Ty::Word(words) => {
                let w = if self.oops(0.15) {
                    "sideways"
                } else {
                    self.rng.pick(words)
                };
                self.out.push_str(w);
            }
            Ty::Object(cat) => self.object(cat),
            Ty::Objects(cat) => {
                self.out.push('[');
                for _ in 0..self.rng.below(3) {
                    self.object(cat);
                    self.out.push_str(", ");
                }
                self.out.push(']');
            }
            Ty::Text => self.string(),
            Ty::Texts => {
                self.out.push('[');
                for _ in 0..self.rng.below(4) {
                    self.string();
                    self.out.push_str(", ");
                }
                self.out.push(']');
            }
            Ty::BlockOr(_, words) if self.rng.chance(0.2) => {
                let w = self.rng.pick(words);
                self.out.push_str(w);
            }
            Ty::Block(params) | Ty::BlockOr(params, _) => {
                if self.depth > 4 {
                    self.out.push_str("{}");
                    return;
                }
                self.depth += 1;
                self.out.push_str("{ ");
                self.entries(params, None);
                self.out.push_str(" }");
                self.depth -= 1;
            }
            Ty::Range(dim) => {
                self.quantity(dim, Check::Any);
                self.out.push_str(" .. ");
                self.quantity(dim, Check::Any);
            }
            Ty::Formula { result, .. } => self.expr(result, &[]),
        }
    }

    fn string(&mut self) {
        let s = self.rng.pick(&[
            "",
            "%",
            "O1000",
            "G90 G21",
            "\\n",
            "\\\"",
            "(comment)",
            "é ü µ",
            "a\\tb",
            "{x}",
            "N10",
        ]);
        let _ = write!(self.out, "\"{s}\"");
    }

    /// A number with a unit of `dim` (in one of its spellings), mostly in
    /// the range `check` allows.
    pub fn quantity(&mut self, dim: Dim, check: Check) {
        let (unit, factor) = self.unit(dim);
        if self.oops(0.3) {
            let n = self.rng.pick(EXTREMES);
            let _ = write!(self.out, "{n}{unit}");
            return;
        }
        let base = match check {
            Check::Positive => self.rng.log_uniform(1e-4, 1e3),
            Check::NonNegative => self.rng.log_uniform(1e-4, 1e3) * self.rng.below(2) as f64,
            Check::HalfOpen(lo, hi) | Check::Open(lo, hi) => lo + self.rng.unit() * (hi - lo),
            Check::Count => (1 + self.rng.below(20)) as f64,
            Check::Any => {
                self.rng.log_uniform(1e-4, 1e3) * if self.rng.chance(0.3) { -1.0 } else { 1.0 }
            }
        };
        let base = if self.oops(0.15) { -base } else { base };
        let written = base / factor;
        if written < 0.0 {
            self.out.push('-');
        }
        let mag = written.abs();
        if self.rng.chance(0.5) {
            let _ = write!(self.out, "{mag:e}{unit}");
        } else if check == Check::Count {
            let _ = write!(self.out, "{}{unit}", mag.round());
        } else {
            let _ = write!(self.out, "{:.4}{unit}", mag);
        }
    }

    /// A spelling of a unit of `dim` (with its leading space) and its size
    /// in base units.
    fn unit(&mut self, dim: Dim) -> (String, f64) {
        let spellings: &[(&str, f64)] = if dim == Dim::NONE {
            &[("", 1.0)]
        } else if dim == Dim::LENGTH {
            &[
                (" mm", 1.0),
                (" um", 1e-3),
                (" nm", 1e-6),
                (" µm", 1e-3),
                (" m", 1e3),
                (" in", 25.4),
            ]
        } else if dim == Dim::ANGLE {
            &[
                (" deg", 0.017453292519943295),
                ("°", 0.017453292519943295),
                (" rad", 1.0),
                (" mrad", 1e-3),
            ]
        } else if dim == Dim::TIME {
            &[(" s", 1.0), (" ms", 1e-3), (" min", 60.0), (" us", 1e-6)]
        } else if dim == Dim::SPEED {
            &[
                (" mm/min", 1.0 / 60.0),
                (" um/s", 1e-3),
                (" m/min", 1000.0 / 60.0),
                (" mm/s", 1.0),
            ]
        } else if dim == Dim::FEED_PER_REV {
            &[
                (" um/rev", 1e-3 / std::f64::consts::TAU),
                (" mm/rev", 1.0 / std::f64::consts::TAU),
                (" nm/rev", 1e-6 / std::f64::consts::TAU),
            ]
        } else if dim == Dim::ROTATIONAL_SPEED {
            &[
                (" rpm", std::f64::consts::TAU / 60.0),
                (" rad/s", 1.0),
                (" rev/min", std::f64::consts::TAU / 60.0),
            ]
        } else if dim == Dim::FREQUENCY {
            &[(" Hz", 1.0), (" kHz", 1e3), (" s^-1", 1.0)]
        } else if dim == Dim::ACCELERATION {
            &[(" g", 9806.65), (" m/s^2", 1e3), (" mm/s^2", 1.0)]
        } else {
            return (format!(" {}", generic_unit(dim)), 1.0);
        };
        let (u, f) = *self.rng.pick(spellings);
        (u.to_string(), f)
    }

    /// An expression of roughly dimension `dim`, over `coords` when it is a
    /// formula's body.
    fn expr(&mut self, dim: Dim, coords: &[&str]) {
        if self.depth > 6 || self.rng.chance(0.35) {
            return self.leaf(dim, coords);
        }
        self.depth += 1;
        match self.rng.below(9) {
            0 => {
                self.out.push('(');
                self.expr(dim, coords);
                self.out.push(')');
            }
            1 => {
                self.out.push('-');
                self.expr(dim, coords);
            }
            2 | 3 => {
                self.expr(dim, coords);
                let op = *self.rng.pick(&[" + ", " - "]);
                self.out.push_str(op);
                self.expr(dim, coords);
            }
            4 => {
                self.expr(dim, coords);
                self.out.push_str(" * ");
                self.expr(Dim::NONE, coords);
            }
            5 => {
                self.expr(dim, coords);
                self.out.push_str(" / ");
                self.expr(Dim::NONE, coords);
            }
            6 => {
                self.out.push('(');
                self.expr(Dim::NONE, coords);
                self.out.push_str(") ^ ");
                let p = *self.rng.pick(&["2", "0.5", "-1", "3", "1e9", "x"]);
                self.out.push_str(p);
            }
            7 => {
                let f = *self.rng.pick(&[
                    "sin", "cos", "tan", "asin", "acos", "atan", "sqrt", "abs", "exp", "ln",
                    "atan2", "min", "max", "nowhere",
                ]);
                let _ = write!(self.out, "{f}(");
                for i in 0..1 + self.rng.below(3) {
                    if i > 0 {
                        self.out.push_str(", ");
                    }
                    let d = if self.rng.chance(0.5) { dim } else { Dim::NONE };
                    self.expr(d, coords);
                }
                self.out.push(')');
            }
            _ if self.oops(1.0) => {
                let n = *self.rng.pick(NAN_MAKERS);
                self.out.push_str(n);
            }
            _ => self.leaf(dim, coords),
        }
        self.depth -= 1;
    }

    fn leaf(&mut self, dim: Dim, coords: &[&str]) {
        if !coords.is_empty() && self.rng.chance(0.5) {
            let c = self.rng.pick(coords);
            self.out.push_str(c);
        } else if !self.lets.is_empty() && self.rng.chance(0.2) {
            let name = self.rng.pick(&self.lets).clone();
            self.out.push_str(&name);
        } else {
            self.quantity(dim, Check::Any);
        }
    }
}

/// `mm^a rad^b s^c` written with `/` as the grammar allows, e.g. `mm^-3`.
fn generic_unit(dim: Dim) -> String {
    let parts = [("mm", dim.length), ("rad", dim.angle), ("s", dim.time)];
    let mut out = String::new();
    for (name, e) in parts.into_iter().filter(|(_, e)| *e != 0) {
        if out.is_empty() {
            out.push_str(name);
            if e != 1 {
                let _ = write!(out, "^{e}");
            }
        } else {
            out.push('/');
            out.push_str(name);
            if e != -1 {
                let _ = write!(out, "^{}", -e);
            }
        }
    }
    out
}
