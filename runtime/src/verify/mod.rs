//! What a program will cut: the profile simulation, height maps of a
//! surface swept by the nose, and the servo's following error.

pub mod figures;
pub mod follow;
pub mod heightmap;
pub mod lenslets;
pub mod simulate;
pub mod tiles;
pub mod window;
