//! `lensc explain CODE`: a diagnostic code's long explanation with an
//! example that causes it and its fix (as `rustc --explain` does), or
//! `--list` every code with its title; for people or as JSON. The text is
//! `lensc_lang::explain`'s, one Markdown file per code.

use lensc_lang::explain::{self, Expect};
use serde::Serialize;

/// `lensc explain CODE --format json`.
#[derive(Serialize)]
struct Explained<'a> {
    code: &'a str,
    severity: &'a str,
    title: &'a str,
    /// The whole explanation, Markdown.
    text: &'a str,
    examples: Vec<ExampleJson>,
}

#[derive(Serialize)]
struct ExampleJson {
    /// `error`: this file gives the code; `fix`: the same file corrected.
    expect: &'static str,
    /// Arguments `lensc build` needs to show it (`--dialect=…`).
    args: Vec<String>,
    source: String,
}

/// Runs the subcommand; returns the exit code.
pub fn run(code: Option<&str>, list: bool, json: bool) -> u8 {
    if list || code.is_none() {
        return list_codes(json);
    }
    let asked = code.unwrap_or_default();
    let Some((code, text)) = explain::explain(asked) else {
        eprintln!(
            "error: `{asked}` is not a code lensc uses; `lensc explain --list` shows every code"
        );
        return 2;
    };
    if json {
        let v = Explained {
            code,
            severity: severity(code),
            title: explain::title(text),
            text,
            examples: explain::examples(text)
                .into_iter()
                .map(|e| ExampleJson {
                    expect: match e.expect {
                        Expect::Error => "error",
                        Expect::Fix => "fix",
                    },
                    args: e.args,
                    source: e.source,
                })
                .collect(),
        };
        println!("{:#}", serde_json::json!(v));
    } else {
        print!("{}", explain::for_terminal(text));
    }
    0
}

fn severity(code: &str) -> &'static str {
    if code.starts_with('W') {
        "warning"
    } else {
        "error"
    }
}

/// Every code and its title, one a line (or a JSON array).
fn list_codes(json: bool) -> u8 {
    let all = explain::all();
    if json {
        let v: Vec<_> = all
            .iter()
            .map(|(c, t)| {
                serde_json::json!({"code": c, "severity": severity(c), "title": explain::title(t)})
            })
            .collect();
        println!("{:#}", serde_json::json!(v));
    } else {
        for (c, t) in all {
            println!("{c}  {}", explain::title(t));
        }
    }
    0
}
