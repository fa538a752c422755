//! Gathers the long explanations of the diagnostic codes
//! (`explain/CODE.md`, one file per code) into one table for
//! `lensc_lang::explain`: adding a code's explanation is adding its file.

use std::fmt::Write as _;
use std::path::Path;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("explain");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("compiler/lang/explain")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    files.sort();
    let mut table = String::from("&[\n");
    for path in files {
        let code = path
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("a UTF-8 name");
        writeln!(
            table,
            "    ({code:?}, include_str!({:?})),",
            path.display().to_string()
        )
        .expect("writing to a String");
    }
    table.push(']');
    let out = Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("explanations.rs");
    std::fs::write(out, table).expect("writing the explanation table");
}
