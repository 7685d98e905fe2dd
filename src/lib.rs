//! Modal Resonator: a modal-synthesis instrument.
//!
//! A *modal bank* ([`bank::Bank`]) describes how an object rings: modes with a frequency, a decay
//! rate and a gain for each strike position. The [`engine::Engine`] plays banks polyphonically
//! through SIMD resonator banks ([`dsp`]); [`render`] drives the same engine offline. What is
//! played, the bank as data, is [`bank`]; what makes banks (fitting recordings, analytic
//! shapes, meshes) is [`authoring`], which nothing that plays imports.

pub mod authoring;
pub mod bank;
pub mod dsp;
pub mod editor;
pub mod engine;
pub mod params;
pub mod plugin;
pub mod render;
pub mod rng;
pub mod scene;
pub mod units;

pub use plugin::{ModalResonator, ModalResonatorFx};
