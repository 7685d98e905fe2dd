//! Where each column of modes sits in the stereo field.

use crate::dsp::COLUMNS;

/// Pan of each accumulator column at full width, -1 (left) to 1 (right). Modes are sorted by
/// frequency and dealt round the columns, so column 0 holds the lowest mode, usually the
/// strongest: it sits in the centre. The next ones fan out alternately left and right, so
/// partials alternate sides and the image stays balanced; the last column is centred again.
const COLUMN_PAN: [f32; COLUMNS] = [0.0, -0.35, 0.35, -0.7, 0.7, -1.0, 1.0, 0.0];

/// Left and right gains of each column at `width` (0 = mono, 1 = full spread). Constant power:
/// `l^2 + r^2 = 2`, so a centred column has gain 1 in each channel.
pub fn lane_weights(width: f32) -> ([f32; COLUMNS], [f32; COLUMNS]) {
    let mut l = [0.0; COLUMNS];
    let mut r = [0.0; COLUMNS];
    for j in 0..COLUMNS {
        let pan = COLUMN_PAN[j] * width.clamp(0.0, 1.0);
        l[j] = (1.0 - pan).sqrt();
        r[j] = (1.0 + pan).sqrt();
    }
    (l, r)
}
