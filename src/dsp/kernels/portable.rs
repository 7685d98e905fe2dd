//! Four rows at a time (two for a pair left over) in plain arrays: the compiler turns the lane loops into vector code for the
//! baseline target.

use super::{Rows, COLUMNS};

/// Rows advanced together, to keep independent work in flight.
const GROUP: usize = 4;

fn load<const G: usize>(src: &[f32]) -> [[f32; COLUMNS]; G] {
    let mut out = [[0.0; COLUMNS]; G];
    for (row, chunk) in out.iter_mut().zip(src.chunks_exact(COLUMNS)) {
        row.copy_from_slice(chunk);
    }
    out
}

fn store<const G: usize>(dst: &mut [f32], lanes: &[[f32; COLUMNS]; G]) {
    for (chunk, row) in dst.chunks_exact_mut(COLUMNS).zip(lanes) {
        chunk.copy_from_slice(row);
    }
}

pub(super) fn process(mut rows: Rows<'_>, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
    const STRIDE: usize = GROUP * COLUMNS;
    let total = rows.re.len();
    let whole = total - total % STRIDE;
    for start in (0..whole).step_by(STRIDE) {
        group::<GROUP>(&mut rows, start, input, acc);
    }
    // Rows come in blocks of two: at most one pair is left over.
    if whole < total {
        group::<2>(&mut rows, whole, input, acc);
    }
}

/// `G` rows from `start`, over the whole span.
fn group<const G: usize>(
    rows: &mut Rows<'_>,
    start: usize,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    let span = start..start + G * COLUMNS;
    let (q_re, q_im, gain) = (
        load::<G>(&rows.q_re[span.clone()]),
        load::<G>(&rows.q_im[span.clone()]),
        load::<G>(&rows.gain[span.clone()]),
    );
    let (mut re, mut im) = (
        load::<G>(&rows.re[span.clone()]),
        load::<G>(&rows.im[span.clone()]),
    );
    for (n, sum) in acc.iter_mut().enumerate() {
        let x = input.map_or(0.0, |x| x[n]);
        for g in 0..G {
            for l in 0..COLUMNS {
                let (r, i) = (re[g][l], im[g][l]);
                re[g][l] = r + q_re[g][l] * r - q_im[g][l] * i + gain[g][l] * x;
                im[g][l] = i + q_im[g][l] * r + q_re[g][l] * i;
            }
        }
        for l in 0..COLUMNS {
            sum[l] += match &im[..] {
                [a, b] => a[l] + b[l],
                [a, b, c, d] => (a[l] + b[l]) + (c[l] + d[l]),
                _ => unreachable!("groups of two or four rows"),
            };
        }
    }
    store(&mut rows.re[span.clone()], &re);
    store(&mut rows.im[span], &im);
}
