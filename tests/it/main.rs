//! The integration tests, as one test binary (one link of cranelift,
//! plotters and the whole compiler instead of fifteen): each module is one
//! concern, run alone with `cargo test --test it -- MODULE::`.
//!
//! Data lives beside this folder: `tests/bad/` and `tests/bad_builds/` (the
//! bad-input corpora), `tests/jobs/` (small jobs), `tests/fixtures/`,
//! `tests/seed_sketches/` and `tests/snapshots/` (insta's, reached from
//! here as `../snapshots/...`).

mod common;

mod architecture;
mod bad_programs;
mod build_errors;
mod chords;
mod cli;
mod compensate;
mod complete_programs;
mod control_point;
mod delivery;
mod determinism;
mod diagnostics;
mod dialects;
mod differential;
mod docs;
mod edge_profile;
mod editors;
mod examples;
mod explain;
mod floods;
mod fmt;
mod fts_advice;
mod fuzz_properties;
mod headers;
mod import;
mod interrupt;
mod lenslet_kinds;
mod limits;
mod linear;
mod list;
mod lsp;
mod measure;
mod measure_lenslet_field;
mod measure_lenslets;
mod measure_stepped_rim;
mod nurbs_linuxcnc;
mod plots;
mod progress;
mod read_back;
mod rs274;
mod sandbox;
mod seed_sketches;
mod servo_lead;
mod spline_examples;
mod splines;
mod surface_fixtures;
mod surface_kinds;
mod toolpaths;
mod tutorial;
mod verification;
mod view;
