//! Real-time signal processing.
//!
//! Nothing here imports the plugin framework. Everything takes plain slices in natural units at a
//! documented sample rate. Storage is sized in `new`/`prepare` style constructors; the per-sample
//! paths never allocate.

pub mod coeffs;
pub mod coeffs_batch;
pub mod contact;
pub mod denormal;
pub mod exciter;
pub mod kernels;
pub mod masking;
pub mod onset;
pub mod prefetch;
pub mod pruning;
pub mod resonator_bank;

pub use coeffs::ModeCoeffs;
pub use exciter::{Excitation, Exciter, ExciterKind, StrikeKind};
pub use kernels::Kernel;
pub use resonator_bank::{ResonatorBank, COLUMNS};
