//! `lensc list`: the kinds and the standard library as a person reads them
//! (snapshots) and as a tool reads them (the JSON shape docs/usage/list-and-explain.md documents),
//! both drawn from the checker's schema and the stdlib's doc comments.

use crate::common::{lensc, root, text};

fn list(args: &[&str]) -> String {
    let mut all = vec!["list"];
    all.extend(args);
    let out = lensc(&root(), &all);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    text(&out.stdout)
}

#[test]
fn machines_and_one_tool_read_as_snapshotted() {
    insta::with_settings!({ snapshot_path => "../snapshots/cli", prepend_module_to_snapshot => false, omit_expression => true }, {
        insta::assert_snapshot!("list_machines", list(&["machines"]));
        insta::assert_snapshot!("list_tools_round_nose", list(&["tools", "round_nose"]));
        insta::assert_snapshot!("list_machines_nanoform_x_fts5000", list(&["machines", "nanoform_x_fts5000"]));
    });
}

#[test]
fn json_has_the_documented_shape() {
    let v: serde_json::Value = serde_json::from_str(&list(&["--format", "json"])).expect("JSON");
    let cats: Vec<&str> = v["categories"]
        .as_array()
        .expect("categories")
        .iter()
        .map(|c| c["category"].as_str().expect("category"))
        .collect();
    assert_eq!(
        cats,
        ["machines", "tools", "dialects", "strategies", "surfaces"]
    );
    for c in v["categories"].as_array().expect("categories") {
        for k in c["kinds"].as_array().expect("kinds") {
            for key in [
                "name",
                "makes",
                "doc",
                "params",
                "coefficients",
                "exclusive",
            ] {
                assert!(k.get(key).is_some(), "kind {} lacks {key}", k["name"]);
            }
            for p in k["params"].as_array().expect("params") {
                for key in [
                    "name", "required", "takes", "unit", "range", "default", "doc", "params",
                ] {
                    assert!(p.get(key).is_some(), "param {} lacks {key}", p["name"]);
                }
            }
        }
        for i in c["items"].as_array().expect("items") {
            for key in ["name", "kind", "use", "doc", "values"] {
                assert!(i.get(key).is_some(), "item {} lacks {key}", i["name"]);
            }
        }
    }
    // One machine's limits, as the stdlib declares them.
    let one: serde_json::Value =
        serde_json::from_str(&list(&["machines", "linuxcnc_lathe", "--format", "json"]))
            .expect("JSON");
    let item = &one["categories"][0]["items"][0];
    assert_eq!(item["kind"], "lathe");
    assert_eq!(item["use"], "use std::machines::linuxcnc_lathe");
    let value = |name: &str| {
        item["values"]
            .as_array()
            .expect("values")
            .iter()
            .find(|v| v["name"] == name)
            .map(|v| v["value"].as_str().expect("text").to_string())
    };
    assert_eq!(value("max_feed").as_deref(), Some("2000 mm/min"));
    assert_eq!(value("spindle").as_deref(), Some("{ max_speed: 3000 rpm }"));
    assert_eq!(value("dialect").as_deref(), Some("linuxcnc"));
    // A parameter's range, in its display unit.
    let tool: serde_json::Value =
        serde_json::from_str(&list(&["tools", "round_nose", "--format", "json"])).expect("JSON");
    let clearance = &tool["categories"][0]["kinds"][0]["params"][1];
    assert_eq!(clearance["name"], "clearance");
    assert_eq!(clearance["unit"], "deg");
    assert_eq!(clearance["range"], "0 ≤ v < 90");
}

#[test]
fn an_unknown_name_is_a_usage_error_with_a_suggestion() {
    let out = lensc(&root(), &["list", "machines", "linuxcnc_lath"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("did you mean `linuxcnc_lathe`?"),
        "{}",
        text(&out.stderr)
    );
}
