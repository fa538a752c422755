//! The layout rules, one small input each, and the property every input
//! must keep: formatting twice changes nothing.

use super::format_source;

/// Formats `input`, checks that formatting the result again changes
/// nothing, and returns it.
fn fmt(input: &str) -> String {
    let once = format_source(input).unwrap_or_else(|d| panic!("{input:?}: {d:?}"));
    let twice = format_source(&once).unwrap_or_else(|d| panic!("{once:?}: {d:?}"));
    assert_eq!(once, twice, "not idempotent for {input:?}");
    once
}

#[test]
fn spacing_is_normalised() {
    assert_eq!(
        fmt("let   a=1+2*  3\nsurface s=conic{radius:5mm,conic:-1}\n"),
        "let a = 1 + 2 * 3\nsurface s = conic { radius: 5 mm, conic: -1 }\n"
    );
    assert_eq!(
        fmt("tool t = w { clearance: 10 ° }"),
        "tool t = w { clearance: 10° }\n"
    );
    assert_eq!(
        fmt("let r = -10mm..2.5e-3 mm^-1"),
        "let r = -10 mm .. 2.5e-3 mm^-1\n"
    );
    assert_eq!(fmt("let e = 5 em"), "let e = 5 em\n");
    assert_eq!(
        fmt("let k = 10 rad / (3 mm) + 1 mm / (x) + (1 mm)/(2) + 1/(2)"),
        "let k = 10 rad/(3 mm) + 1 mm/(x) + (1 mm) / (2) + 1 / (2)\n"
    );
}

#[test]
fn a_block_stays_on_one_line_unless_its_author_broke_it() {
    assert_eq!(
        fmt("job j {surface: s, tool: t}\n"),
        "job j { surface: s, tool: t }\n"
    );
    assert_eq!(
        fmt("job j { surface: s,\n tool: t, }\n"),
        "job j {\n    surface: s\n    tool: t\n}\n"
    );
    assert_eq!(
        fmt("let b = {}\nlet l = [ ]\nlet c = f( )"),
        "let b = {}\nlet l = []\nlet c = f()\n"
    );
    assert_eq!(
        fmt("let l = [1,\n2]\nlet c = f(a: 1,\n b: [x, y])"),
        "let l = [\n    1,\n    2,\n]\nlet c = f(\n    a: 1,\n    b: [x, y],\n)\n"
    );
    // A broken block inside forces its parents over lines too.
    assert_eq!(
        fmt("machine m = lathe { spindle: {\nmax_speed: 1 rpm } }"),
        "machine m = lathe {\n    spindle: {\n        max_speed: 1 rpm\n    }\n}\n"
    );
}

#[test]
fn comments_stay_where_they_were() {
    let src = "// head\n\n\n// about a\nlet a = 1 // trailing\n/* own */\nlet b = 2\nsurface s = conic { // opener\n    radius: 1 mm, /* after radius */ conic: -1\n\n    // before sense\n    sense: convex\n    // dangling\n}\n// end\n";
    assert_eq!(
        fmt(src),
        "// head\n\n// about a\nlet a = 1 // trailing\n/* own */\nlet b = 2\nsurface s = conic { // opener\n    radius: 1 mm\n    /* after radius */ conic: -1\n\n    // before sense\n    sense: convex\n    // dangling\n}\n// end\n"
    );
    // A comment inside a one-line block breaks it.
    assert_eq!(
        fmt("job j { surface: s /* the lens */, tool: t }"),
        "job j {\n    surface: s /* the lens */\n    tool: t\n}\n"
    );
    // Comments between the tokens of one element stay between them.
    assert_eq!(
        fmt("let a = /* x */ 1 + // y\n  2"),
        "let a = /* x */ 1 + // y\n    2\n"
    );
    assert_eq!(fmt("let a = (1 /* in */)"), "let a = (1 /* in */)\n");
}

#[test]
fn parentheses_and_strings_are_kept_as_written() {
    assert_eq!(
        fmt("let a = ((1+2))*(3) - (-x)^2\nuse \"a b.lens\"\nlet s = \"x // not a comment\""),
        "let a = ((1 + 2)) * (3) - (-x) ^ 2\nuse \"a b.lens\"\nlet s = \"x // not a comment\"\n"
    );
    assert_eq!(
        fmt("let a = (f)(x) + (b) { c: 1 }"),
        "let a = (f)(x) + (b) { c: 1 }\n"
    );
    // `2 mm ^ 2` is a power of a quantity, `2 mm^2` a unit: the space stays.
    assert_eq!(fmt("let a = 2 mm ^ 2"), "let a = 2 mm ^ 2\n");
}

#[test]
fn formulas_uses_and_blank_lines() {
    assert_eq!(
        fmt("\n\nuse std::machines::x\n\n\n\nsurface f = freeform {\n\n  z(x,y)=x*y\n\n}\n\n\n"),
        "use std::machines::x\n\nsurface f = freeform {\n    z(x, y) = x * y\n}\n"
    );
    assert_eq!(fmt("\r\n// c \r\nlet a = 1\r\n"), "// c\nlet a = 1\n");
    assert_eq!(fmt(""), "");
    assert_eq!(fmt("// only\n"), "// only\n");
}

#[test]
fn a_file_that_does_not_parse_is_refused_with_the_parser_s_diagnostics() {
    let d = format_source("surface s = conic {").unwrap_err();
    assert!(
        !d.is_empty() && d.iter().all(|d| d.code.starts_with("E000")),
        "{d:?}"
    );
}
