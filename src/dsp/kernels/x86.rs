//! AVX2 + FMA and AVX-512 kernels.
//!
//! Each loads a group of modes into registers, runs the whole span of samples with the state held
//! there, and stores it back. Four independent vectors are in flight so the two dependent FMAs of
//! each step (8 cycles of latency) overlap with the other vectors' work. Per vector and sample:
//! four FMA-pipe operations for the recursion (`re += q_re re - q_im im`, `im += q_im re + q_re im`),
//! one more when the group has input, and one add to accumulate the output.

use std::arch::x86_64::*;

use super::{Rows, COLUMNS};

/// Input sample `n`, or zero without input.
#[inline(always)]
fn input_at(input: Option<&[f32]>, n: usize) -> f32 {
    match input {
        // SAFETY of the unchecked read: callers only pass n < len, and `process` checked that the
        // input has the accumulator's length.
        Some(x) => unsafe { *x.get_unchecked(n) },
        None => 0.0,
    }
}

/// AVX2 + FMA: 4 vectors of 8 modes.
///
/// # Safety
/// The CPU must support AVX2 and FMA; slice lengths must have been checked by `process`.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn process_avx2(
    rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    if input.is_some() {
        avx2_span::<true>(rows, input, acc)
    } else {
        avx2_span::<false>(rows, input, acc)
    }
}

#[target_feature(enable = "avx2,fma")]
unsafe fn avx2_span<const INPUT: bool>(
    rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 8;
    const STRIDE: usize = 4 * W;
    let len = acc.len();
    let accp = acc.as_mut_ptr() as *mut f32;
    for start in (0..rows.re.len()).step_by(STRIDE) {
        // SAFETY: `process` checked every slice holds whole blocks of 64 modes, so
        // start..start + 32 is in bounds of each.
        unsafe {
            let re = rows.re.as_mut_ptr().add(start);
            let im = rows.im.as_mut_ptr().add(start);
            let qr = rows.q_re.as_ptr().add(start);
            let qi = rows.q_im.as_ptr().add(start);
            let g = rows.gain.as_ptr().add(start);
            let (mut r0, mut r1, mut r2, mut r3) = (
                _mm256_loadu_ps(re),
                _mm256_loadu_ps(re.add(W)),
                _mm256_loadu_ps(re.add(2 * W)),
                _mm256_loadu_ps(re.add(3 * W)),
            );
            let (mut i0, mut i1, mut i2, mut i3) = (
                _mm256_loadu_ps(im),
                _mm256_loadu_ps(im.add(W)),
                _mm256_loadu_ps(im.add(2 * W)),
                _mm256_loadu_ps(im.add(3 * W)),
            );
            let (qr0, qr1, qr2, qr3) = (
                _mm256_loadu_ps(qr),
                _mm256_loadu_ps(qr.add(W)),
                _mm256_loadu_ps(qr.add(2 * W)),
                _mm256_loadu_ps(qr.add(3 * W)),
            );
            let (qi0, qi1, qi2, qi3) = (
                _mm256_loadu_ps(qi),
                _mm256_loadu_ps(qi.add(W)),
                _mm256_loadu_ps(qi.add(2 * W)),
                _mm256_loadu_ps(qi.add(3 * W)),
            );
            let (g0, g1, g2, g3) = if INPUT {
                (
                    _mm256_loadu_ps(g),
                    _mm256_loadu_ps(g.add(W)),
                    _mm256_loadu_ps(g.add(2 * W)),
                    _mm256_loadu_ps(g.add(3 * W)),
                )
            } else {
                let z = _mm256_setzero_ps();
                (z, z, z, z)
            };
            for n in 0..len {
                macro_rules! step {
                    ($r:ident, $i:ident, $qr:ident, $qi:ident, $g:ident) => {{
                        let mut nr = _mm256_fnmadd_ps($qi, $i, _mm256_fmadd_ps($qr, $r, $r));
                        if INPUT {
                            nr = _mm256_fmadd_ps($g, _mm256_set1_ps(input_at(input, n)), nr);
                        }
                        $i = _mm256_fmadd_ps($qi, $r, _mm256_fmadd_ps($qr, $i, $i));
                        $r = nr;
                    }};
                }
                step!(r0, i0, qr0, qi0, g0);
                step!(r1, i1, qr1, qi1, g1);
                step!(r2, i2, qr2, qi2, g2);
                step!(r3, i3, qr3, qi3, g3);
                let s = _mm256_add_ps(_mm256_add_ps(i0, i1), _mm256_add_ps(i2, i3));
                let a = accp.add(n * COLUMNS);
                _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), s));
            }
            _mm256_storeu_ps(re, r0);
            _mm256_storeu_ps(re.add(W), r1);
            _mm256_storeu_ps(re.add(2 * W), r2);
            _mm256_storeu_ps(re.add(3 * W), r3);
            _mm256_storeu_ps(im, i0);
            _mm256_storeu_ps(im.add(W), i1);
            _mm256_storeu_ps(im.add(2 * W), i2);
            _mm256_storeu_ps(im.add(3 * W), i3);
        }
    }
}

/// AVX-512: 4 vectors of 16 modes (two rows each).
///
/// # Safety
/// The CPU must support AVX-512 F and DQ; slice lengths must have been checked by `process`.
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) unsafe fn process_avx512(
    rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    if input.is_some() {
        avx512_span::<true>(rows, input, acc)
    } else {
        avx512_span::<false>(rows, input, acc)
    }
}

#[target_feature(enable = "avx512f,avx512dq")]
unsafe fn avx512_span<const INPUT: bool>(
    rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 16;
    const STRIDE: usize = 4 * W;
    let len = acc.len();
    let accp = acc.as_mut_ptr() as *mut f32;
    for start in (0..rows.re.len()).step_by(STRIDE) {
        // SAFETY: `process` checked every slice holds whole blocks of 64 modes, so
        // start..start + 64 is in bounds of each.
        unsafe {
            let re = rows.re.as_mut_ptr().add(start);
            let im = rows.im.as_mut_ptr().add(start);
            let qr = rows.q_re.as_ptr().add(start);
            let qi = rows.q_im.as_ptr().add(start);
            let g = rows.gain.as_ptr().add(start);
            let (mut r0, mut r1, mut r2, mut r3) = (
                _mm512_loadu_ps(re),
                _mm512_loadu_ps(re.add(W)),
                _mm512_loadu_ps(re.add(2 * W)),
                _mm512_loadu_ps(re.add(3 * W)),
            );
            let (mut i0, mut i1, mut i2, mut i3) = (
                _mm512_loadu_ps(im),
                _mm512_loadu_ps(im.add(W)),
                _mm512_loadu_ps(im.add(2 * W)),
                _mm512_loadu_ps(im.add(3 * W)),
            );
            let (qr0, qr1, qr2, qr3) = (
                _mm512_loadu_ps(qr),
                _mm512_loadu_ps(qr.add(W)),
                _mm512_loadu_ps(qr.add(2 * W)),
                _mm512_loadu_ps(qr.add(3 * W)),
            );
            let (qi0, qi1, qi2, qi3) = (
                _mm512_loadu_ps(qi),
                _mm512_loadu_ps(qi.add(W)),
                _mm512_loadu_ps(qi.add(2 * W)),
                _mm512_loadu_ps(qi.add(3 * W)),
            );
            let (g0, g1, g2, g3) = if INPUT {
                (
                    _mm512_loadu_ps(g),
                    _mm512_loadu_ps(g.add(W)),
                    _mm512_loadu_ps(g.add(2 * W)),
                    _mm512_loadu_ps(g.add(3 * W)),
                )
            } else {
                let z = _mm512_setzero_ps();
                (z, z, z, z)
            };
            for n in 0..len {
                macro_rules! step {
                    ($r:ident, $i:ident, $qr:ident, $qi:ident, $g:ident) => {{
                        let mut nr = _mm512_fnmadd_ps($qi, $i, _mm512_fmadd_ps($qr, $r, $r));
                        if INPUT {
                            nr = _mm512_fmadd_ps($g, _mm512_set1_ps(input_at(input, n)), nr);
                        }
                        $i = _mm512_fmadd_ps($qi, $r, _mm512_fmadd_ps($qr, $i, $i));
                        $r = nr;
                    }};
                }
                step!(r0, i0, qr0, qi0, g0);
                step!(r1, i1, qr1, qi1, g1);
                step!(r2, i2, qr2, qi2, g2);
                step!(r3, i3, qr3, qi3, g3);
                let s = _mm512_add_ps(_mm512_add_ps(i0, i1), _mm512_add_ps(i2, i3));
                // Lanes 0-7 hold one row's columns, lanes 8-15 the next row's: fold them.
                let folded =
                    _mm256_add_ps(_mm512_castps512_ps256(s), _mm512_extractf32x8_ps::<1>(s));
                let a = accp.add(n * COLUMNS);
                _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), folded));
            }
            _mm512_storeu_ps(re, r0);
            _mm512_storeu_ps(re.add(W), r1);
            _mm512_storeu_ps(re.add(2 * W), r2);
            _mm512_storeu_ps(re.add(3 * W), r3);
            _mm512_storeu_ps(im, i0);
            _mm512_storeu_ps(im.add(W), i1);
            _mm512_storeu_ps(im.add(2 * W), i2);
            _mm512_storeu_ps(im.add(3 * W), i3);
        }
    }
}
