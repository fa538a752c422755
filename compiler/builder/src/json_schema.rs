//! The JSON Schemas of the reports lensc writes (the build's and the
//! measurement's): generated from their structs, and held to the copies
//! committed under `docs/`.

/// The JSON Schema (draft 2020-12) of a report lensc writes, as written.
pub fn schema_of<T: schemars::JsonSchema>() -> schemars::Schema {
    schemars::generate::SchemaSettings::draft2020_12()
        .for_serialize()
        .into_generator()
        .into_root_schema_for::<T>()
}

/// That schema as the text committed under `docs/`.
pub fn schema_text_of<T: schemars::JsonSchema>() -> String {
    serde_json::to_string_pretty(&schema_of::<T>()).expect("a schema prints") + "\n"
}

/// Holds the schema committed at `docs/NAME` to `generated`, or with
/// `LENSC_BLESS` set writes it; `module` names the tests that regenerate
/// it.
#[cfg(test)]
pub fn assert_schema_committed(name: &str, generated: &str, module: &str) {
    let path = format!("{}/../../docs/{name}", env!("CARGO_MANIFEST_DIR"));
    if std::env::var_os("LENSC_BLESS").is_some() {
        std::fs::write(&path, generated).unwrap_or_else(|e| panic!("write docs/{name}: {e}"));
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/{name} is stale: regenerate it with\n    LENSC_BLESS=1 cargo test -p lensc-build --lib {module}"
    );
}
