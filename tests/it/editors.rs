//! The editor support in `editors/` against the compiler: the TextMate
//! grammar highlights exactly the checker's kinds and functions, and the
//! VS Code extension ties that grammar to `.lens` files. (The grammar's
//! tokenisation of every example is checked in node, by
//! `editors/test/grammar.test.js`, which `.ci/run` runs.)

use std::collections::BTreeSet;

use serde_json::Value;

use crate::common::root;

fn json(path: &str) -> Value {
    let text = std::fs::read_to_string(root().join(path)).expect(path);
    serde_json::from_str(&text).expect(path)
}

/// The names of a `\b(?:a|b|c)\b` alternation.
fn alternation(pattern: &str) -> BTreeSet<String> {
    let inner = pattern
        .split_once("(?:")
        .and_then(|(_, rest)| rest.split_once(')'))
        .map(|(names, _)| names)
        .expect("an alternation");
    inner.split('|').map(str::to_string).collect()
}

#[test]
fn the_grammar_knows_the_checkers_kinds_and_functions() {
    let g = json("editors/vscode/syntaxes/lens.tmLanguage.json");
    assert_eq!(g["scopeName"], "source.lens");
    let kinds = alternation(g["repository"]["kinds"]["match"].as_str().expect("kinds"));
    let schema: BTreeSet<String> = lensc_lang::schema::KINDS
        .iter()
        .map(|k| k.name.to_string())
        .collect();
    assert_eq!(
        kinds, schema,
        "editors/vscode/syntaxes/lens.tmLanguage.json's kinds"
    );
    let functions = alternation(g["repository"]["functions"]["match"].as_str().expect("fns"));
    let checker: BTreeSet<String> = lensc_lang::check::FUNCTIONS
        .iter()
        .map(|f| f.to_string())
        .collect();
    assert_eq!(
        functions, checker,
        "editors/vscode/syntaxes/lens.tmLanguage.json's functions"
    );
}

#[test]
fn the_vscode_extension_ties_the_grammar_and_server_to_lens_files() {
    let p = json("editors/vscode/package.json");
    let lang = &p["contributes"]["languages"][0];
    assert_eq!(lang["id"], "lens");
    assert_eq!(lang["extensions"][0], ".lens");
    let grammar = &p["contributes"]["grammars"][0];
    assert_eq!(grammar["scopeName"], "source.lens");
    assert_eq!(grammar["language"], "lens");
    // The grammar the extension names is committed (a fresh clone's F5
    // highlights, issue #32), not made by a build step.
    let path = grammar["path"].as_str().expect("a grammar path");
    assert!(
        root().join("editors/vscode").join(path).is_file(),
        "{path} is not in the clone"
    );
    let ignored =
        std::fs::read_to_string(root().join("editors/vscode/.gitignore")).unwrap_or_default();
    assert!(
        !ignored
            .lines()
            .any(|l| path.contains(l.trim_end_matches('/')) && !l.is_empty()),
        "{path} is git-ignored"
    );
    for needed in ["LICENSE", ".vscodeignore", "README.md"] {
        assert!(
            root().join("editors/vscode").join(needed).is_file(),
            "the extension has no {needed}"
        );
    }
    let conf = json("editors/vscode/language-configuration.json");
    assert_eq!(conf["comments"]["lineComment"], "//");
    let ext = std::fs::read_to_string(root().join("editors/vscode/extension.js")).expect("js");
    assert!(
        ext.contains("args: ['lsp']"),
        "the extension runs `lensc lsp`"
    );
}
