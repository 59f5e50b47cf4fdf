//! Scene description, parsing and building.
pub mod desc;
pub mod parse;
pub mod build;
pub mod obj;
