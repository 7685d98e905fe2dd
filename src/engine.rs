//! Voices and routing: the single entry used by the plugin, the renderer, tests and benches.
