//! Scene description, parsing and building.
pub mod build;
pub mod desc;
pub mod error;
pub mod gather;
pub mod instances;
pub mod lens;
pub mod limits;
pub mod mesh;
pub mod obj;
pub mod parse;
pub mod perturb;
pub mod pinhole;
pub mod ptracer_check;
pub mod sensor;
pub mod texturing;
pub mod xml;
