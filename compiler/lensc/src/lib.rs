//! The `lensc` command's library half: what the binary renders for people
//! (diagnostics through ariadne), kept here so the tests can render too.

pub mod render;
