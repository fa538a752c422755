use super::*;

const SINGLET: &str = "VERS 190000\nMODE SEQ\nUNIT MM X W X CM MR CPMM\n\
SURF 0\n  TYPE STANDARD\n  CURV 0.0\n  DISZ INFINITY\n\
SURF 1\n  TYPE EVENASPH\n  COMM front\n  CURV 0.02\n  CONI -1.5\n  PARM 1 0\n  PARM 2 1.5E-5\n  PARM 3 -2E-8\n  DISZ 4\n  GLAS N-BK7 0 0 1.5168 64.17\n  DIAM 6 1 0 0 1 \"\"\n\
SURF 2\n  TYPE STANDARD\n  CURV -0.01\n  DISZ 90\n  DIAM 6\n\
SURF 3\n  TYPE STANDARD\n  CURV 0\n  DIAM 1\n";

fn rotational(e: &Entry) -> (f64, f64, Vec<(u32, f64)>, Option<String>) {
    match &e.what {
        What::Surface(Surface {
            shape:
                Shape::Rotational {
                    curvature,
                    conic,
                    terms,
                },
            rear_of,
            ..
        }) => (*curvature, *conic, terms.clone(), rear_of.clone()),
        other => panic!("surface {}: {other:?}", e.number),
    }
}

#[test]
fn zemax_even_asphere_terms_start_at_r_squared() {
    let mut diags = Vec::new();
    let p = zemax::read("s.zmx", SINGLET, &mut diags).expect("reads");
    assert!(diags.is_empty(), "{diags:?}");
    assert_eq!(p.entries.len(), 4);
    assert!(matches!(p.entries[0].what, What::Skipped(_)));
    let (c, k, terms, rear) = rotational(&p.entries[1]);
    assert_eq!((c, k, rear), (0.02, -1.5, None));
    assert_eq!(terms, vec![(4, 1.5e-5), (6, -2e-8)]);
    assert_eq!(p.entries[1].comment, "front");
    // The back of the N-BK7 element: glass before it, air after.
    let (c, _, _, rear) = rotational(&p.entries[2]);
    assert_eq!((c, rear.as_deref()), (-0.01, Some("N-BK7")));
}

#[test]
fn zemax_lens_units_convert_to_mm() {
    let inches = SINGLET.replace("UNIT MM", "UNIT IN");
    let p = zemax::read("s.zmx", &inches, &mut Vec::new()).expect("reads");
    let (c, _, terms, _) = rotational(&p.entries[1]);
    assert!((c - 0.02 / 25.4).abs() < 1e-15);
    // A4 in in^-3 is A4 / 25.4^3 in mm^-3.
    assert!((terms[0].1 - 1.5e-5 / 25.4f64.powi(3)).abs() < 1e-20);
    let What::Surface(s) = &p.entries[1].what else {
        panic!()
    };
    assert_eq!(s.semi_diameter, 6.0 * 25.4);
}

#[test]
fn utf16_with_a_byte_order_mark_is_read() {
    let mut bytes = vec![0xFF, 0xFE];
    for u in SINGLET.encode_utf16() {
        bytes.extend(u.to_le_bytes());
    }
    assert_eq!(decode(&bytes), SINGLET);
    let out = import("s.zmx", &bytes);
    assert!(out.lens.is_some(), "{:?}", out.diags);
}

#[test]
fn unknown_types_and_unused_parameters_are_warned_about() {
    let text = SINGLET
        .replace("SURF 2\n  TYPE STANDARD", "SURF 2\n  TYPE GRID_SAG")
        .replace("PARM 3 -2E-8", "PARM 3 -2E-8\n  XDAT 1 7");
    let out = import("s.zmx", text.as_bytes());
    let codes: Vec<&str> = out.diags.iter().map(|d| d.code).collect();
    assert_eq!(
        codes,
        vec![
            codes::IMPORT_PARAMETER_DROPPED,
            codes::IMPORT_UNSUPPORTED_SURFACE
        ]
    );
    let lens = out.lens.expect("written");
    assert!(lens.contains("GRID_SAG"), "{lens}");
    assert!(lens.contains("Not imported: extra data 1 = 7"), "{lens}");
}

#[test]
fn non_sequential_and_garbage_are_errors() {
    let out = import("n.zmx", b"MODE NSC\nSURF 0\n");
    assert_eq!(out.diags[0].code, codes::IMPORT_NON_SEQUENTIAL);
    assert!(out.lens.is_none());
    let out = import("g.zmx", b"SURF 0\n CURV abc\n");
    assert_eq!(out.diags[0].code, codes::IMPORT_UNREADABLE);
    let out = import("g.json", b"{\"surface_group\": ");
    assert_eq!(out.diags[0].code, codes::IMPORT_UNREADABLE);
    let out = import("f.zmx", b"SURF 0\nSURF 1\n CURV 0\n DIAM 3\nSURF 2\n");
    assert_eq!(out.diags[0].code, codes::IMPORT_NOTHING);
}

#[test]
fn python_infinities_become_readable() {
    assert_eq!(
        optiland::read(
            "o.json",
            r#"{"surface_group": {"surfaces": [{"geometry": {"type": "Plane", "radius": Infinity, "cs": {}}, "comment": "Infinity"}]}}"#,
            &mut Vec::new()
        )
        .expect("reads")
        .entries
        .len(),
        1
    );
}

#[test]
fn turning_over_negates_the_sag() {
    let shapes = [
        Shape::Rotational {
            curvature: -0.05,
            conic: -0.7,
            terms: vec![(3, 1e-4), (4, -2e-5)],
        },
        Shape::Biconic {
            cx: 0.02,
            cy: -0.03,
            kx: 0.5,
            ky: -1.0,
        },
        Shape::Toroid {
            cy: 0.05,
            conic: 0.0,
            rotation_radius: Some(30.0),
            terms: vec![(4, 1e-5)],
        },
    ];
    for s in shapes {
        let t = s.turned_over();
        for (x, y) in [(0.3, 1.1), (-2.0, 0.5), (1.7, -1.9)] {
            assert!((s.sag(x, y) + t.sag(x, y)).abs() < 1e-15, "{s:?}");
        }
    }
}

#[test]
fn numbers_read_back_to_the_last_place() {
    for v in [
        1.5e-5,
        -2e-8,
        22.01359,
        1.0 / 0.0454,
        1e9,
        -0.1,
        3.0,
        1.0 / 3.0,
    ] {
        let back: f64 = write::num(v).parse().expect("a number");
        assert!((back - v).abs() <= 2.0 * f64::EPSILON * v.abs(), "{v}");
    }
    // A conversion's last-digit noise is not written.
    assert_eq!(write::num(1.0 / (0.8 / 25.4)), "31.75");
    let v = 1.86000372000744e-5;
    let back: f64 = write::num(v).parse().expect("a number");
    assert!((back - v).abs() <= 2.0 * f64::EPSILON * v);
    assert_eq!(write::num(-2e-8), "-2e-8");
    assert_eq!(write::num(0.02), "0.02");
}

#[test]
fn a_surface_without_a_semi_diameter_is_named_and_skipped() {
    let json = r#"{"surface_group": {"surfaces": [
        {"geometry": {"type": "Plane"}},
        {"geometry": {"type": "StandardGeometry", "radius": 30.0, "conic": -1.0, "cs": {"x": 0.5}}, "aperture": null},
        {"geometry": {"type": "Plane"}}]}}"#;
    let out = import("o.json", json.as_bytes());
    let codes: Vec<&str> = out.diags.iter().map(|d| d.code).collect();
    assert_eq!(
        codes,
        vec![
            codes::IMPORT_POSITION_IGNORED,
            codes::IMPORT_NO_SEMI_DIAMETER,
            codes::IMPORT_NOTHING
        ]
    );
    assert!(out.lens.is_none());
}

#[test]
fn a_toroid_sweeping_away_from_its_profile_is_not_imported() {
    let text = SINGLET.replace(
        "SURF 2\n  TYPE STANDARD\n  CURV -0.01",
        "SURF 2\n  TYPE TOROIDAL\n  CURV -0.01\n  PARM 1 40",
    );
    let out = import("t.zmx", text.as_bytes());
    assert_eq!(out.diags[0].code, codes::IMPORT_UNSUPPORTED_SURFACE);
    assert!(
        out.diags[0].message.contains("toroid"),
        "{}",
        out.diags[0].message
    );
}

#[test]
fn noll_numbers_map_to_ansi_as_opticstudio_lists_them() {
    // Z2 cos, Z3 sin, Z5 sin 2θ, Z6 cos 2θ, Z7 sin θ, Z11 spherical.
    let want = [
        (1, (0, 0)),
        (2, (1, 1)),
        (3, (1, -1)),
        (4, (2, 0)),
        (5, (2, -2)),
        (6, (2, 2)),
        (7, (3, -1)),
        (8, (3, 1)),
        (9, (3, -3)),
        (10, (3, 3)),
        (11, (4, 0)),
    ];
    for (j, nm) in want {
        assert_eq!(noll_nm(j), nm, "Z{j}");
        assert_eq!(ansi_nm(ansi_index(nm.0, nm.1)), nm);
    }
}

#[test]
fn an_optiland_biconic_is_read_by_its_own_keys() {
    let json = r#"{"surface_group": {"surfaces": [
        {"geometry": {"type": "Plane"}},
        {"geometry": {"type": "BiconicGeometry", "radius_x": 40.0, "radius_y": Infinity, "conic_x": -1.0, "conic_y": 0.0},
         "aperture": {"type": "RadialAperture", "r_max": 5.0, "r_min": 0.0}},
        {"geometry": {"type": "Plane"}}]}}"#;
    let mut diags = Vec::new();
    let p = optiland::read("b.json", json, &mut diags).expect("reads");
    assert!(diags.is_empty(), "{diags:?}");
    let What::Surface(s) = &p.entries[1].what else {
        panic!("{:?}", p.entries[1].what)
    };
    assert_eq!(
        s.shape,
        Shape::Biconic {
            cx: 1.0 / 40.0,
            cy: 0.0,
            kx: -1.0,
            ky: 0.0
        }
    );
    let out = import("b.json", json.as_bytes());
    let lens = out.lens.expect("written");
    assert!(lens.contains("acylinder"), "{lens}");
}

/// A `.lens` text over the limit is refused (E0354) and not returned; at
/// the limit it is written.
#[test]
fn a_lens_text_over_the_limit_is_refused() {
    let zmx = b"SURF 0\nSURF 1\n  CURV 0.05\n  DIAM 4\nSURF 2\n  CURV -0.05\n  DIAM 4\nSURF 3\n";
    let whole = import("two.zmx", zmx);
    let lens = whole.lens.expect("imported");
    let at = import_within("two.zmx", zmx, lens.len() as u64);
    assert_eq!(at.lens.as_deref(), Some(lens.as_str()));
    let over = import_within("two.zmx", zmx, lens.len() as u64 - 1);
    assert!(over.lens.is_none());
    let codes: Vec<&str> = over.diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, [codes::IMPORT_TOO_LARGE]);
}

/// A curvature whose radius overflows (1/1e-320) is refused (E0353), in
/// either reader, never written as a radius of 0.
#[test]
fn a_curvature_with_no_finite_radius_is_refused() {
    let zmx = b"SURF 0\nSURF 1\n  CURV 1e-320\n  DIAM 4\nSURF 2\n";
    let json = br#"{"surface_group": {"surfaces": [
        {"geometry": {"type": "Plane"}},
        {"geometry": {"type": "StandardGeometry", "radius": 1e308, "conic": 0},
         "aperture": {"type": "RadialAperture", "r_max": 2}},
        {"geometry": {"type": "StandardGeometry", "radius": 1e-320, "conic": 0},
         "aperture": {"type": "RadialAperture", "r_max": 2}},
        {"geometry": {"type": "Plane"}}
    ]}}"#;
    for (name, bytes) in [("tiny.zmx", &zmx[..]), ("tiny.json", &json[..])] {
        let i = import(name, bytes);
        assert!(i.lens.is_none(), "{name}: {:?}", i.lens);
        assert!(
            i.diags.iter().any(|d| d.code == codes::IMPORT_NOT_FINITE),
            "{name}: {:?}",
            i.diags
        );
    }
}

/// A file cut short after its last lens surface (issue #32): the last
/// surface is the image by the format's rule, so the lens surface is
/// dropped, but no longer silently: a curved last surface is warned about
/// (W0040), and the error that nothing is left names every surface
/// skipped and why, not "the warnings above" when there are none.
#[test]
fn a_file_cut_short_after_its_lens_surface_says_what_was_dropped() {
    let cut = "MODE SEQ\nUNIT MM\nSURF 0\n  CURV 0\n  DISZ INFINITY\nSURF 1\n  CURV 0.02\n  CONI -1\n  DIAM 5\n";
    let out = import("cut.zmx", cut.as_bytes());
    assert!(out.lens.is_none());
    let codes: Vec<&str> = out.diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, [codes::IMPORT_IMAGE_CURVED, codes::IMPORT_NOTHING]);
    assert!(out.diags[0].message.contains("surface 1, the last"));
    let help = out.diags[1].help.clone().unwrap_or_default();
    assert!(
        help.contains("surface 0 (the object surface)")
            && help.contains("surface 1 (the image surface)")
            && !help.contains("warnings above"),
        "{help}"
    );
    // The whole singlet, with its flat image surface last: no warning.
    let whole = import("singlet.zmx", SINGLET.as_bytes());
    assert!(whole.lens.is_some());
    assert!(
        !whole
            .diags
            .iter()
            .any(|d| d.code == codes::IMPORT_IMAGE_CURVED),
        "{:?}",
        whole.diags
    );
}

/// A number past f64's range (`1e400`) is named as what it is (E0353,
/// beyond the largest number), not "needs a number here"; a word that is
/// not a number still gets E0350.
#[test]
fn a_number_past_the_largest_is_named_as_such() {
    let big = SINGLET.replace("CURV 0.02", "CURV 1e400");
    let out = import("big.zmx", big.as_bytes());
    assert!(out.lens.is_none());
    let d = out.diags.iter().find(|d| d.is_error()).expect("an error");
    assert_eq!(d.code, codes::IMPORT_NOT_FINITE, "{d:?}");
    assert!(
        d.message.contains("1e400 is beyond the largest number"),
        "{}",
        d.message
    );
    let word = SINGLET.replace("CURV 0.02", "CURV 1/50");
    let out = import("word.zmx", word.as_bytes());
    let d = out.diags.iter().find(|d| d.is_error()).expect("an error");
    assert_eq!(d.code, codes::IMPORT_UNREADABLE);
    assert!(d.message.contains("needs a number here"), "{}", d.message);
}

#[test]
fn a_json_error_inside_a_character_is_spanned_at_its_start() {
    // The fuzzer's import target (issue #33, item 7): a string cut off in
    // the middle of a character, read as `�`; serde's column fell inside
    // the `�`, a span off a character boundary.
    let out = import("f.json", b"{\n    \"_source\": \"\xef");
    let d = &out.diags[0];
    assert_eq!(d.code, codes::IMPORT_UNREADABLE);
    let span = d.labels[0].span;
    assert!(out.source_text.is_char_boundary(span.start as usize));
    assert!(out.source_text.is_char_boundary(span.end as usize));
}
