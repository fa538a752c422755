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

/// `editors/nvim/lensc.lua` as the README tells a Neovim user to load it,
/// in a real Neovim (Debian 12's 0.7.2 in CI, which `.ci/run` installs),
/// headless: a `.lens` buffer gets the filetype, `//` comments, `K` and
/// `gd`, and the server's diagnostics with their codes. Without `nvim`
/// the test says so and passes, except under CI, where it fails.
#[test]
fn neovim_gets_the_servers_diagnostics_from_the_shipped_setup() {
    if !editor_on_path("nvim", "neovim") {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let job = dir.path().join("bad.lens");
    std::fs::write(
        &job,
        "surface s = sphere { radius: 10 mm, aperture: 5 mmm }\n",
    )
    .expect("job");
    let out = dir.path().join("seen.txt");
    let probe = dir.path().join("probe.lua");
    std::fs::write(
        &probe,
        r#"vim.wait(20000, function() return #vim.diagnostic.get(0) > 1 end, 100)
local out = { 'filetype=' .. vim.bo.filetype, 'commentstring=' .. vim.bo.commentstring,
  'K=' .. vim.fn.maparg('K', 'n'), 'gd=' .. vim.fn.maparg('gd', 'n') }
for _, d in ipairs(vim.diagnostic.get(0)) do
  table.insert(out, string.format('%d:%d %s', d.lnum, d.col, tostring(d.code)))
end
vim.fn.writefile(out, vim.env.LENSC_NVIM_OUT)
vim.cmd('qa!')
"#,
    )
    .expect("probe");
    let path = path_with_lensc();
    let run = std::process::Command::new("nvim")
        .args(["--headless", "-u"])
        .arg(root().join("editors/nvim/lensc.lua"))
        .arg(&job)
        .arg("-c")
        .arg(format!("luafile {}", probe.display()))
        .env("PATH", path)
        .env("LENSC_NVIM_OUT", &out)
        .env("XDG_CONFIG_HOME", dir.path())
        .env("XDG_DATA_HOME", dir.path())
        .env("XDG_STATE_HOME", dir.path())
        .current_dir(dir.path())
        .stdin(std::process::Stdio::null())
        .output()
        .expect("nvim runs");
    let seen = std::fs::read_to_string(&out).unwrap_or_default();
    assert!(
        run.status.success(),
        "nvim: {}\n{seen}",
        String::from_utf8_lossy(&run.stderr)
    );
    let lines: Vec<&str> = seen.lines().collect();
    assert_eq!(lines.first(), Some(&"filetype=lens"), "{seen}");
    assert!(seen.contains("commentstring=// %s"), "{seen}");
    assert!(!seen.contains("K=\n") && !seen.contains("gd=\n"), "{seen}");
    // Both of the checker's findings, with their codes and places.
    assert!(seen.contains("0:48 E0110"), "{seen}");
    assert!(seen.contains("0:12 E0121"), "{seen}");
}

/// `editors/emacs/lensc.el` as the README tells an Emacs user to load it,
/// in Debian 12's Emacs 28.2 with its elpa-eglot (which `.ci/run`
/// installs), headless: a `.lens` buffer is in `lens-mode` with `//`
/// comments, eglot connects to `lensc lsp`, and flymake shows the server's
/// diagnostics. Without `emacs` the test says so and passes, except under
/// CI, where it fails.
#[test]
fn emacs_eglot_gets_the_servers_diagnostics_from_the_shipped_setup() {
    if !editor_on_path("emacs", "emacs-nox and elpa-eglot") {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let job = dir.path().join("bad.lens");
    std::fs::write(
        &job,
        "surface s = sphere { radius: 10 mm, aperture: 5 mmm }\n",
    )
    .expect("job");
    let out = dir.path().join("seen.txt");
    let probe = dir.path().join("probe.el");
    std::fs::write(
        &probe,
        r#"(find-file (getenv "LENSC_JOB"))
;; eglot-ensure connects after the next command, which batch never runs.
(run-hooks 'post-command-hook)
(let ((deadline (+ (float-time) 20)))
  (while (and (< (length (flymake-diagnostics)) 2) (< (float-time) deadline))
    (accept-process-output nil 0.2))
  (let ((lines (list (format "mode=%s" major-mode)
                     (format "comment=%s" comment-start)
                     (format "eglot=%s" (if (eglot-current-server) "yes" "no")))))
    (dolist (d (flymake-diagnostics))
      (push (car (split-string (flymake-diagnostic-text d) "\n")) lines))
    (with-temp-file (getenv "LENSC_EMACS_OUT")
      (insert (mapconcat #'identity lines "\n") "\n"))))
(kill-emacs 0)
"#,
    )
    .expect("probe");
    let path = path_with_lensc();
    let run = std::process::Command::new("emacs")
        .args(["--batch", "-l"])
        .arg(root().join("editors/emacs/lensc.el"))
        .arg("-l")
        .arg(&probe)
        .env("PATH", path)
        .env("HOME", dir.path())
        .env("LENSC_JOB", &job)
        .env("LENSC_EMACS_OUT", &out)
        .current_dir(dir.path())
        .stdin(std::process::Stdio::null())
        .output()
        .expect("emacs runs");
    let seen = std::fs::read_to_string(&out).unwrap_or_default();
    assert!(
        run.status.success(),
        "emacs: {}\n{seen}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(seen.contains("mode=lens-mode"), "{seen}");
    assert!(seen.contains("comment=// "), "{seen}");
    assert!(seen.contains("eglot=yes"), "{seen}");
    assert!(seen.contains("[E0110]: unknown unit `mmm`"), "{seen}");
    assert!(seen.contains("[E0121]"), "{seen}");
}

/// Whether the editor `program` runs here. Without it an editor test says
/// so and passes, except under CI, which must install `package`.
fn editor_on_path(program: &str, package: &str) -> bool {
    let found = std::process::Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must install {package} for this test"
        );
        eprintln!("skipped: no {program} on PATH");
    }
    found
}

/// PATH with the `lensc` under test first, as an editor finds the server.
fn path_with_lensc() -> std::ffi::OsString {
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_lensc"))
        .parent()
        .expect("bin dir")
        .to_path_buf();
    std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .expect("PATH")
}
