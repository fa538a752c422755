//! Every seed-job sketch in tests/seed_sketches/ parses: the syntax can
//! say every job of the five papers (the kinds they use come later).

use std::path::Path;

#[test]
fn every_seed_sketch_parses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/seed_sketches");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).expect("seed_sketches/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "lens") {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("read");
        let (file, diags) = lensc_grammar::parse(&text, lensc_grammar::FileId(0));
        assert!(diags.is_empty(), "{}: {diags:?}", path.display());
        assert!(!file.items.is_empty());
        n += 1;
    }
    assert!(n >= 6);
}
