//! Real-time signal processing: no plugin framework, no allocation after `prepare`.
