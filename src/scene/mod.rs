//! Scene description, parsing and building.
pub mod build;
pub mod desc;
pub mod obj;
pub mod parse;
