//! One mode at a time: the oracle the vector kernels are tested against.

use super::{Rows, COLUMNS};

pub(super) fn process(rows: Rows<'_>, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
    for slot in 0..rows.re.len() {
        let column = slot % COLUMNS;
        let (q_re, q_im, gain) = (rows.q_re[slot], rows.q_im[slot], rows.gain[slot]);
        let (mut re, mut im) = (rows.re[slot], rows.im[slot]);
        for (n, sum) in acc.iter_mut().enumerate() {
            let x = input.map_or(0.0, |x| x[n]);
            // z += q z + g x
            let next_re = re + q_re * re - q_im * im + gain * x;
            let next_im = im + q_im * re + q_re * im;
            re = next_re;
            im = next_im;
            sum[column] += im;
        }
        rows.re[slot] = re;
        rows.im[slot] = im;
    }
}
