//! The tools that make banks: fitting them to recordings, designing them from analytic shapes
//! and from 3-D meshes, the materials those use, mode compression, and the recipes of the
//! analytic factory banks.
//!
//! What they make is a [`crate::bank::Bank`]; the engine and everything that plays never import
//! this module. Nothing here runs on the audio thread: code in this module may allocate and may
//! fail.

pub mod compress;
pub mod factory_recipes;
pub mod fit;
pub mod limen;
pub mod materials;
pub mod mesh;
pub mod shapes;
