//! The lowest modes of rectangles: modes indexed by two whole numbers `(m, n)`, both from 1, whose
//! frequency grows with each (simply supported plates, fixed membranes).

/// Every `(m, n)` with `freq_hz(m, n)` below a bound that holds at least `max_modes` of them
/// (or below `max_freq_hz`, when fewer lie there), in order of `m`, then `n`.
///
/// The bound starts at `first_bound_hz` and doubles until it holds enough, so a large, thin
/// object does not list millions of modes to keep a few hundred. `freq_hz` must grow with `m`
/// and with `n`.
pub(super) fn lowest_lattice_modes(
    freq_hz: impl Fn(usize, usize) -> f64,
    first_bound_hz: f64,
    max_freq_hz: f64,
    max_modes: usize,
) -> Vec<(usize, usize)> {
    let mut bound_hz = first_bound_hz.min(max_freq_hz);
    loop {
        let mut indices = Vec::new();
        for m in 1.. {
            if freq_hz(m, 1) >= bound_hz {
                break;
            }
            for n in 1.. {
                if freq_hz(m, n) >= bound_hz {
                    break;
                }
                indices.push((m, n));
            }
        }
        if indices.len() >= max_modes || bound_hz >= max_freq_hz {
            return indices;
        }
        bound_hz = (2.0 * bound_hz).min(max_freq_hz);
    }
}
