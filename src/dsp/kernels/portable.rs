//! Two rows at a time in plain arrays: the compiler turns the lane loops into vector code for the
//! baseline target. Two rows measured about 2.7 times faster than four (`cargo bench --bench
//! resonator`): the state and coefficients of four rows are 32 SSE2 registers' worth, twice what
//! the CPU has.

use super::{Rows, COLUMNS};

/// Rows advanced together (the kernel's row block, so no rows are left over).
const GROUP: usize = super::Kernel::Portable.row_block();
const _: () = assert!(GROUP == 2, "the output sum below adds two rows");

type Lanes = [[f32; COLUMNS]; GROUP];

fn load(src: &[f32]) -> Lanes {
    let mut out = [[0.0; COLUMNS]; GROUP];
    for (row, chunk) in out.iter_mut().zip(src.chunks_exact(COLUMNS)) {
        row.copy_from_slice(chunk);
    }
    out
}

fn store(dst: &mut [f32], lanes: &Lanes) {
    for (chunk, row) in dst.chunks_exact_mut(COLUMNS).zip(lanes) {
        chunk.copy_from_slice(row);
    }
}

pub(super) fn process(rows: Rows<'_>, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
    const STRIDE: usize = GROUP * COLUMNS;
    for start in (0..rows.re.len()).step_by(STRIDE) {
        let span = start..start + STRIDE;
        let (q_re, q_im, gain) = (
            load(&rows.q_re[span.clone()]),
            load(&rows.q_im[span.clone()]),
            load(&rows.gain[span.clone()]),
        );
        let (mut re, mut im) = (load(&rows.re[span.clone()]), load(&rows.im[span.clone()]));
        for (n, sum) in acc.iter_mut().enumerate() {
            let x = input.map_or(0.0, |x| x[n]);
            for g in 0..GROUP {
                for l in 0..COLUMNS {
                    let (r, i) = (re[g][l], im[g][l]);
                    re[g][l] = r + q_re[g][l] * r - q_im[g][l] * i + gain[g][l] * x;
                    im[g][l] = i + q_im[g][l] * r + q_re[g][l] * i;
                }
            }
            for l in 0..COLUMNS {
                sum[l] += im[0][l] + im[1][l];
            }
        }
        store(&mut rows.re[span.clone()], &re);
        store(&mut rows.im[span], &im);
    }
}
