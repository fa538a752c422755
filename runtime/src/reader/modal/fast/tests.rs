//! The fast path against the whole path: generated programs, lines valid
//! and subtly not, read by two states side by side, one reading the
//! common block in one pass and one reading every line whole; after
//! every line the findings and the whole modal state (every float by its
//! bits, the moves made) must be the same.

use super::super::State;
use crate::dialect::{CommentStyle, Dialect, WordFormat};
use crate::reader::{Controller, MachineLimits};

/// A small deterministic generator (xorshift64).
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// 0 .. n
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }

    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len() as u64) as usize]
    }

    /// Digits, `n` of them.
    fn digits(&mut self, n: u64) -> String {
        (0..n)
            .map(|_| char::from(b'0' + self.below(10) as u8))
            .collect()
    }

    /// `least` digits and up to `more - 1` more.
    fn some_digits(&mut self, least: u64, more: u64) -> String {
        let n = least + self.below(more);
        self.digits(n)
    }

    /// A number as a word carries it: mostly as lensc writes them, and
    /// every way one can be subtly wrong or unusual.
    fn number(&mut self) -> String {
        match self.below(40) {
            0 => String::new(),
            1 => self
                .pick(&["-", "+", ".", "-.", "+.", "..", "-0", "+0", "-0.", "0.0"])
                .into(),
            2 => format!("{}{}", self.pick(&["", "-"]), self.some_digits(16, 8)),
            3 => format!("{}.{}", self.some_digits(1, 9), self.some_digits(8, 10)),
            4 => format!("00{}.{}", self.digits(2), self.digits(3)),
            5 => format!("{}.{}.{}", self.digits(1), self.digits(2), self.digits(1)),
            6 => format!(".{}", self.some_digits(1, 6)),
            7 => format!("{}.", self.some_digits(1, 4)),
            8 => format!("+{}.{}", self.digits(1), self.digits(3)),
            9 => "NaN".into(),
            10 => format!("{}e3", self.digits(2)),
            _ => {
                let sign = if self.chance(30) { "-" } else { "" };
                let whole = self.below(12);
                let decimals = self.below(7);
                let mut t = format!("{sign}{whole}");
                if decimals > 0 || self.chance(50) {
                    t.push('.');
                    t += &self.digits(decimals);
                }
                t
            }
        }
    }

    /// A G word's number: mostly G1 in its spellings.
    fn g_number(&mut self) -> String {
        if self.chance(80) {
            self.pick(&[
                "1",
                "1",
                "1",
                "01",
                "1.",
                "1.0",
                "001",
                "+1",
                "1.00000000001",
            ])
            .into()
        } else {
            self.pick(&[
                "0",
                "2",
                "3",
                "-1",
                "0.9999999",
                "1.1",
                "10",
                "93",
                "94",
                "95",
                "64",
                "",
                "1.000000001",
            ])
            .into()
        }
    }

    /// A word: mostly the common block's letters, sometimes another word,
    /// a comment, a keyword or a stray character.
    fn word(&mut self) -> String {
        match self.below(100) {
            0..=14 => format!("G{}", self.g_number()),
            15..=34 => format!("X{}", self.number()),
            35..=39 => format!("Y{}", self.number()),
            40..=59 => format!("Z{}", self.number()),
            60..=79 => format!("C{}", self.number()),
            80..=91 => {
                let f = if self.chance(60) {
                    self.pick(&[
                        "864000.",
                        "60.",
                        "32.155",
                        "1000",
                        "0.5",
                        "1500",
                        "1500.0000001",
                    ])
                    .to_string()
                } else {
                    self.number()
                };
                format!("F{f}")
            }
            _ => self
                .pick(&[
                    "x1.5",
                    "g1",
                    "f100",
                    "I-1",
                    "K0.5",
                    "R2",
                    "S500",
                    "M3",
                    "M5",
                    "T1",
                    "N10",
                    "E3",
                    "(a comment)",
                    "(open",
                    "; note",
                    "%",
                    "DIAMON",
                    "LIMS=3000",
                    "G93",
                    "G94",
                    "G0",
                    "Q1",
                    "#",
                    "é",
                    "X=1",
                    "C=2",
                ])
                .into(),
        }
    }

    /// A move as the writer prints the common block, within the test
    /// machine's limits more often than not.
    fn common(&mut self) -> String {
        let mut t = String::new();
        if self.chance(70) {
            t += "G1 ";
        }
        if self.chance(70) {
            t += &format!("X{}.{} ", 2 + self.below(2), self.some_digits(0, 7));
        }
        if self.chance(20) {
            t += &format!("Y{}.{} ", self.below(3), self.digits(3));
        }
        if self.chance(50) {
            let sign = self.pick(&["", "-"]);
            t += &format!("Z{sign}0.{} ", self.some_digits(1, 6));
        }
        if self.chance(70) {
            t += &format!("C{}.{} ", self.below(400), self.some_digits(0, 6));
        }
        if self.chance(80) {
            t += &format!(
                "F{} ",
                self.pick(&["60.", "0.002", "100", "864000.", "32.155", "1000"])
            );
        }
        t.pop();
        t
    }

    /// `line` with one byte changed, dropped or added.
    fn mutate(&mut self, line: String) -> String {
        let mut b = line.into_bytes();
        let at = self.below(b.len() as u64 + 1) as usize;
        let marks = b"0123456789.-+ XYZCFGxIKN(;\t%=";
        let c = marks[self.below(marks.len() as u64) as usize];
        match self.below(3) {
            0 if at < b.len() => b[at] = c,
            1 if at < b.len() => {
                b.remove(at);
            }
            _ => b.insert(at, c),
        }
        String::from_utf8(b).expect("ASCII")
    }

    /// A line: a few words with their separators.
    fn line(&mut self) -> String {
        if self.chance(60) {
            let line = self.common();
            return if self.chance(25) {
                self.mutate(line)
            } else {
                line
            };
        }
        let mut t = String::new();
        if self.chance(3) {
            t.push(' ');
        }
        for k in 0..1 + self.below(5) {
            if k > 0 {
                t += match self.below(40) {
                    0 => "",
                    1 => "  ",
                    2 => "\t",
                    _ => " ",
                };
            }
            t += &self.word();
        }
        if self.chance(3) {
            t += self.pick(&[" ", "\t", " \u{a0}", "\r"]);
        }
        t
    }
}

/// Blocks that change the modal state, dropped in among the moves.
const SETUP: &[&str] = &[
    "G18 G21 G90 G8 G40 G49 G80 G94",
    "G17 G21 G90 G40 G49 G80 G94",
    "G18 G71 G90 DIAMOF G40 G94",
    "G20",
    "G21",
    "G70",
    "G71",
    "G90",
    "G91",
    "G93",
    "G94",
    "G95",
    "G96 D2000 S50",
    "G50 S2000",
    "G96 S50",
    "G97 S500",
    "G7",
    "G8",
    "T1 M6 G43",
    "T0101",
    "T1 D1",
    "M3",
    "M5",
    "S500 M3",
    "G97 S500 M3",
    "M19",
    "M18",
    "SPCON",
    "SPOS=0",
    "DIAMON",
    "G0 X5 Z1",
    "G0 Z-1",
    "G0 X3 C0",
    "G1 X1 Z0",
    "G2 X1 Z0 I-1 K0",
    "G93 G1 X3.071765 F60.",
    "G94 G1 Z0.1 F100.",
    "(+X out of the material)",
    "(+Z out of the material)",
    "M2",
    "%",
];

/// The modal state, every float by its bits.
fn snapshot(s: &State) -> String {
    let bits = |v: Option<f64>| v.map(f64::to_bits);
    format!(
        "{:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {} {} {} {} {} {:?} {} {:?} {} {:?}",
        s.metric,
        s.plane,
        s.absolute,
        s.feed_mode,
        s.motion,
        bits(s.feed),
        s.css,
        bits(s.css_speed),
        bits(s.cap),
        bits(s.rpm),
        s.spindle_on,
        s.position_mode,
        s.tool_selected,
        s.tool_loaded,
        s.diameter,
        s.pos.map(bits),
        s.away,
        bits(s.top),
        s.ended,
        // The moves made so far: how many, and the last one.
        s.moves.as_ref().map(|m| (
            m.len(),
            m.last()
                .map(|e| (e.from.map(bits), e.to.map(bits), format!("{:?}", e.path)))
        )),
    )
}

/// The dialects read: each controller's rules, and number formats that
/// limit the common block's own words.
fn dialects() -> Vec<(&'static str, Dialect)> {
    let linuxcnc = Dialect::linuxcnc();
    let mut fanuc = Dialect::linuxcnc();
    fanuc.start = vec!["%".into(), "O{number} ({JOB})".into()];
    fanuc.lathe_setup = vec!["G18 G21 G40 G80 G90 G94".into()];
    fanuc.word_formats = ["X4.4", "Z4.4", "I4.4", "K4.4", "S5", "T4", "M3"]
        .iter()
        .map(|f| WordFormat::parse(f).expect("format"))
        .collect();
    fanuc.max_decimals = Some(4);
    fanuc.max_digits = Some(8);
    fanuc.max_line_length = Some(24);
    fanuc.lathe_x_diameter = true;
    fanuc.c_axis_on = vec!["M19".into()];
    fanuc.c_axis_off = vec!["M18".into()];
    let mut siemens = Dialect::linuxcnc();
    siemens.comment = CommentStyle::Semicolon;
    let mut ultra = Dialect::linuxcnc();
    ultra.lathe_setup = vec!["G18 G71 G90".into()];
    ultra.mill_setup = vec!["G17 G71 G90".into()];
    ultra.word_formats = ["F5", "C3.3", "G2.1", "Y1.2"]
        .iter()
        .map(|f| WordFormat::parse(f).expect("format"))
        .collect();
    ultra.max_decimals = Some(5);
    let mut heidenhain = Dialect::linuxcnc();
    heidenhain.comment = CommentStyle::Semicolon;
    heidenhain.block_end = " *".into();
    heidenhain.line_numbers = Some(1);
    let out = vec![
        ("linuxcnc", linuxcnc),
        ("fanuc", fanuc),
        ("siemens", siemens),
        ("ultra-precision", ultra),
        ("heidenhain", heidenhain),
    ];
    let want = [
        Controller::LinuxCnc,
        Controller::Fanuc,
        Controller::Siemens,
        Controller::UltraPrecision,
        Controller::HeidenhainIso,
    ];
    for ((name, d), c) in out.iter().zip(want) {
        assert_eq!(Controller::of(d), c, "{name}");
    }
    out
}

fn machines() -> Vec<MachineLimits> {
    vec![
        // A lathe whose limits the generated moves often break.
        MachineLimits {
            lathe: true,
            travel: [
                Some((-1.0, 8.0)),
                None,
                Some((-5.0, 5.0)),
                Some((-1.0, 1e4)),
            ],
            max_feed: Some(1500.0),
            max_spindle_rpm: Some(3000.0),
            servo: None,
        },
        // A mill with no limits stated.
        MachineLimits {
            lathe: false,
            travel: [None; 4],
            max_feed: None,
            max_spindle_rpm: None,
            servo: None,
        },
    ]
}

/// A program's start that leaves the fast path open: units, distance,
/// tool, spindle or position mode, feed mode and a feed.
fn opening(g: &mut Gen) -> Vec<String> {
    let mut lines: Vec<String> = vec![
        g.pick(&[
            "G18 G21 G90 G8 G40 G49 G80 G94",
            "G18 G71 G90",
            "G17 G20 G91",
        ])
        .into(),
        g.pick(&["T1 M6 G43", "T0101", "T1", "T1 M6"]).into(),
    ];
    lines.push(
        g.pick(&["G97 S500 M3", "M19", "G0 X3 C0", "S500 M3"])
            .into(),
    );
    lines.push(
        g.pick(&[
            "G93 G1 X3.071765 F60.",
            "G94 G1 Z0.1 F100.",
            "G95 G1 Z0.1 F0.002",
        ])
        .into(),
    );
    lines
}

/// Reads `program` both ways line by line; the lines the fast path took.
fn read_both_ways(name: &str, d: &Dialect, m: &MachineLimits, program: &[String]) -> usize {
    let mut fast = State::new(d, m);
    let mut whole = State::new(d, m);
    whole.fast_on = false;
    fast.moves = Some(Vec::new());
    whole.moves = Some(Vec::new());
    for (n, line) in program.iter().enumerate() {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        fast.line(line, &mut a);
        whole.line(line, &mut b);
        assert_eq!(a, b, "{name}, line {n}: `{line}`");
        assert_eq!(
            snapshot(&fast),
            snapshot(&whole),
            "{name}, line {n}: `{line}`"
        );
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    fast.finish(&mut a);
    whole.finish(&mut b);
    assert_eq!(a, b, "{name}: the end");
    assert_eq!(fast.moves, whole.moves, "{name}: the moves");
    assert_eq!(whole.fast_taken, 0);
    fast.fast_taken
}

#[test]
fn generated_programs_read_the_same_both_ways() {
    let mut g = Gen(0x2545_f491_4f6c_dd1d);
    for (name, d) in dialects() {
        for (k, m) in machines().iter().enumerate() {
            let (mut lines, mut taken) = (0, 0);
            for _ in 0..300 {
                let mut program = opening(&mut g);
                for _ in 0..200 {
                    program.push(if g.chance(4) {
                        g.pick(SETUP).into()
                    } else {
                        g.line()
                    });
                }
                lines += program.len();
                taken += read_both_ways(&format!("{name}, machine {k}"), &d, m, &program);
            }
            if name == "heidenhain" {
                assert_eq!(taken, 0, "numbered blocks are never read fast");
            } else {
                // The generator reaches the fast path (and its refusals):
                // on LinuxCNC about a fifth of the lines are read fast,
                // under tight number formats and line lengths one to three in 100.
                println!("{name}, machine {k}: {taken} of {lines} lines read fast");
                assert!(
                    taken * 100 > lines,
                    "{name}, machine {k}: {taken} of {lines}"
                );
            }
        }
    }
}

/// Every line as the writer prints the common block, through each way it
/// can be refused: read both ways from one clean state.
#[test]
fn the_common_block_and_its_near_misses_read_the_same_both_ways() {
    let d = Dialect::linuxcnc();
    let m = &machines()[0];
    let head: Vec<String> = [
        "(+X out of the material)",
        "G18 G21 G90 G8 G40 G49 G80 G94",
        "T1 M6 G43",
        "G0 X4.07424",
        "G0 Z-3. C0.",
        "G93 G1 X3.071765 F60.",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let lines = [
        "G1 X3.071257 C0.025 F864000.",
        "G1 X3.070744 Z-2.999999 C0.05 F864000.",
        "X3.070238 C0.075 F864000.",
        "G01 X3.070238 C0.075 F864000.",
        "G1 X3.070238 C0.075",
        "G1 X3.070238 C0.075 F0",
        "G1 X3.070238 C0.075 F-1.",
        "G1 X3.070238 C0.075 F1e5",
        "G1 X3.070238 X3. F864000.",
        "G1 X3.070238 C0.075 F864000. F864000.",
        "G1 G1 X3.070238 F864000.",
        "G1 x3.070238 C0.075 F864000.",
        "G1 X3.070238 C0.075 F864000. ",
        "G1  X3.070238\tC0.075 F864000.",
        "G1 X3.070238C0.075 F864000.",
        "G1 X+3.070238 C+0.075 F+864000.",
        "G1 X0003.070238 C00.075 F864000.",
        "G1 X3.0702381234567891 C0.075 F864000.",
        "G1 X3.070238 C0.075 F864000. (a note)",
        "G1 X300. C0.075 F864000.",
        "G1 X-3. C0.075 F864000.",
        "G1 X3.070238 C4000. F864000.",
        "G1 X3.070238 C0.075 F99999999.",
        "G1 X3.07 Z-3. C0.1 F864000.",
        "G1 Z-3.",
        "G1 F100.",
        "G1",
        "",
        "G0 X4.",
        "G1 X3.070238 Y0. C0.075 F864000.",
        "G1 X3.070238 C0.075 F864000. M2",
        "G1 X3.070238 C0.075 F864000. S100",
        "G1.00000000001 X3.070238 C0.075 F864000.",
        "G1.000001 X3.070238 C0.075 F864000.",
        "G0.99999999999 X3.070238 C0.075 F864000.",
        "G1 X. C0.075 F864000.",
        "G1 X- C0.075 F864000.",
        "G1 X3.070238 C0.075 F864000.\r",
    ];
    let mut taken = 0;
    for line in lines {
        let mut program = head.clone();
        program.push(line.to_string());
        program.push("G1 X3.071257 C0.1 F864000.".into());
        program.push("M2".into());
        taken += read_both_ways(line, &d, m, &program);
    }
    // Each line's follower is read fast where its line left the state
    // clean; most of the listed lines are refused by the fast path.
    assert!(taken >= lines.len(), "{taken}");
}
