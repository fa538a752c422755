//! lensc: the last step of the pipeline (source text → syntax tree →
//! checked values → typed jobs → toolpath → move stream → program →
//! report). The binary parses the command line (clap, one file per
//! subcommand under `commands/`), calls `lensc-build` and `lensc-lang`,
//! and renders what they return; this library half holds the rendering of
//! diagnostics (ariadne for people, JSON lines for tools), so the tests
//! can render as the binary does, and the command line's clap definition
//! (`cli`) with the book's page rendered from it (`cli_page`).

pub mod cli;
pub mod cli_page;
pub mod render;
pub mod summary;
