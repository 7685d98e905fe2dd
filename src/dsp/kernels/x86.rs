//! AVX2 + FMA and AVX-512 kernels.
//!
//! Each loads a group of modes into registers, runs the whole span of samples with the state held
//! there, and stores it back. Four independent vectors are in flight so the two dependent FMAs of
//! each step (8 cycles of latency) overlap with the other vectors' work; rows left over after the
//! last whole group (a sparse bank need not be padded to a whole group) go as one group of one to
//! three vectors. Per vector and sample:
//! four FMA-pipe operations for the recursion (`re += q_re re - q_im im`, `im += q_im re + q_re im`),
//! one more when the group has input, and one add to accumulate the output.

use std::arch::x86_64::*;

use super::{Rows, COLUMNS};

/// The slices of `Rows` as raw pointers, for groups that read and write them in place.
struct Ptrs {
    re: *mut f32,
    im: *mut f32,
    q_re: *const f32,
    q_im: *const f32,
    gain: *const f32,
    /// Length of every slice.
    len: usize,
}

impl Ptrs {
    fn of(rows: &mut Rows<'_>) -> Self {
        Self {
            re: rows.re.as_mut_ptr(),
            im: rows.im.as_mut_ptr(),
            q_re: rows.q_re.as_ptr(),
            q_im: rows.q_im.as_ptr(),
            gain: rows.gain.as_ptr(),
            len: rows.re.len(),
        }
    }
}

/// AVX2 + FMA: 4 vectors of 8 modes.
///
/// # Safety
/// The CPU must support AVX2 and FMA; slice lengths must have been checked by `process`.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn process_avx2(
    mut rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 8;
    let total = rows.re.len();
    let p = Ptrs::of(&mut rows);
    let mut start = 0;
    // SAFETY (all calls): `process` checked the slices share a length that is a whole number of
    // rows (one vector each here), and each group stays within it.
    unsafe {
        while start + 4 * W <= total {
            avx2_group::<4>(&p, start, input, acc);
            start += 4 * W;
        }
        match (total - start) / W {
            0 => {}
            1 => avx2_group::<1>(&p, start, input, acc),
            2 => avx2_group::<2>(&p, start, input, acc),
            3 => avx2_group::<3>(&p, start, input, acc),
            v => unreachable!("{v} vectors left over"),
        }
    }
}

/// Sum of one to four vectors, pairwise.
#[inline(always)]
unsafe fn sum256<const V: usize>(v: &[__m256; V]) -> __m256 {
    // SAFETY: plain arithmetic; the caller runs with AVX enabled.
    unsafe {
        match &v[..] {
            [a] => *a,
            [a, b] => _mm256_add_ps(*a, *b),
            [a, b, c] => _mm256_add_ps(_mm256_add_ps(*a, *b), *c),
            [a, b, c, d] => _mm256_add_ps(_mm256_add_ps(*a, *b), _mm256_add_ps(*c, *d)),
            _ => unreachable!("groups hold one to four vectors"),
        }
    }
}

/// `V` vectors of 8 modes from `start`, over the whole span.
///
/// # Safety
/// AVX2 and FMA; `start + 8 V` within every slice behind `p`.
#[target_feature(enable = "avx2,fma")]
unsafe fn avx2_group<const V: usize>(
    p: &Ptrs,
    start: usize,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 8;
    debug_assert!(start + V * W <= p.len, "a group runs past the rows");
    let accp = acc.as_mut_ptr() as *mut f32;
    // SAFETY: the caller keeps start..start + 8 V within the slices; each of the `acc.len()`
    // accumulator rows holds 8 lanes; `process` checked the input has `acc.len()` samples.
    unsafe {
        let zero = _mm256_setzero_ps();
        let (mut r, mut i, mut qr, mut qi, mut g) =
            ([zero; V], [zero; V], [zero; V], [zero; V], [zero; V]);
        for k in 0..V {
            let o = start + k * W;
            r[k] = _mm256_loadu_ps(p.re.add(o));
            i[k] = _mm256_loadu_ps(p.im.add(o));
            qr[k] = _mm256_loadu_ps(p.q_re.add(o));
            qi[k] = _mm256_loadu_ps(p.q_im.add(o));
            if input.is_some() {
                g[k] = _mm256_loadu_ps(p.gain.add(o));
            }
        }
        match input {
            Some(x) => {
                for n in 0..acc.len() {
                    let xn = _mm256_set1_ps(*x.get_unchecked(n));
                    for k in 0..V {
                        let nr = _mm256_fnmadd_ps(qi[k], i[k], _mm256_fmadd_ps(qr[k], r[k], r[k]));
                        i[k] = _mm256_fmadd_ps(qi[k], r[k], _mm256_fmadd_ps(qr[k], i[k], i[k]));
                        r[k] = _mm256_fmadd_ps(g[k], xn, nr);
                    }
                    let a = accp.add(n * COLUMNS);
                    _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), sum256(&i)));
                }
            }
            None => {
                for n in 0..acc.len() {
                    for k in 0..V {
                        let nr = _mm256_fnmadd_ps(qi[k], i[k], _mm256_fmadd_ps(qr[k], r[k], r[k]));
                        i[k] = _mm256_fmadd_ps(qi[k], r[k], _mm256_fmadd_ps(qr[k], i[k], i[k]));
                        r[k] = nr;
                    }
                    let a = accp.add(n * COLUMNS);
                    _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), sum256(&i)));
                }
            }
        }
        for k in 0..V {
            let o = start + k * W;
            _mm256_storeu_ps(p.re.add(o), r[k]);
            _mm256_storeu_ps(p.im.add(o), i[k]);
        }
    }
}

/// AVX-512: 4 vectors of 16 modes (two rows each).
///
/// # Safety
/// The CPU must support AVX-512 F and DQ; slice lengths must have been checked by `process`.
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) unsafe fn process_avx512(
    mut rows: Rows<'_>,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 16;
    let total = rows.re.len();
    let p = Ptrs::of(&mut rows);
    let mut start = 0;
    // SAFETY (all calls): `process` checked the slices share a length that is a whole number of
    // row blocks (two rows, one vector here), and each group stays within it.
    unsafe {
        while start + 4 * W <= total {
            avx512_group::<4>(&p, start, input, acc);
            start += 4 * W;
        }
        match (total - start) / W {
            0 => {}
            1 => avx512_group::<1>(&p, start, input, acc),
            2 => avx512_group::<2>(&p, start, input, acc),
            3 => avx512_group::<3>(&p, start, input, acc),
            v => unreachable!("{v} vectors left over"),
        }
    }
}

/// Sum of one to four vectors, pairwise.
#[inline(always)]
unsafe fn sum512<const V: usize>(v: &[__m512; V]) -> __m512 {
    // SAFETY: plain arithmetic; the caller runs with AVX-512 F enabled.
    unsafe {
        match &v[..] {
            [a] => *a,
            [a, b] => _mm512_add_ps(*a, *b),
            [a, b, c] => _mm512_add_ps(_mm512_add_ps(*a, *b), *c),
            [a, b, c, d] => _mm512_add_ps(_mm512_add_ps(*a, *b), _mm512_add_ps(*c, *d)),
            _ => unreachable!("groups hold one to four vectors"),
        }
    }
}

/// `V` vectors of 16 modes from `start`, over the whole span.
///
/// # Safety
/// AVX-512 F and DQ; `start + 16 V` within every slice behind `p`.
#[target_feature(enable = "avx512f,avx512dq")]
unsafe fn avx512_group<const V: usize>(
    p: &Ptrs,
    start: usize,
    input: Option<&[f32]>,
    acc: &mut [[f32; COLUMNS]],
) {
    const W: usize = 16;
    debug_assert!(start + V * W <= p.len, "a group runs past the rows");
    let accp = acc.as_mut_ptr() as *mut f32;
    // SAFETY: the caller keeps start..start + 16 V within the slices; each of the `acc.len()`
    // accumulator rows holds 8 lanes; `process` checked the input has `acc.len()` samples.
    unsafe {
        let zero = _mm512_setzero_ps();
        let (mut r, mut i, mut qr, mut qi, mut g) =
            ([zero; V], [zero; V], [zero; V], [zero; V], [zero; V]);
        for k in 0..V {
            let o = start + k * W;
            r[k] = _mm512_loadu_ps(p.re.add(o));
            i[k] = _mm512_loadu_ps(p.im.add(o));
            qr[k] = _mm512_loadu_ps(p.q_re.add(o));
            qi[k] = _mm512_loadu_ps(p.q_im.add(o));
            if input.is_some() {
                g[k] = _mm512_loadu_ps(p.gain.add(o));
            }
        }
        // Lanes 0-7 hold one row's columns, lanes 8-15 the next row's: fold them.
        let fold =
            |s: __m512| _mm256_add_ps(_mm512_castps512_ps256(s), _mm512_extractf32x8_ps::<1>(s));
        match input {
            Some(x) => {
                for n in 0..acc.len() {
                    let xn = _mm512_set1_ps(*x.get_unchecked(n));
                    for k in 0..V {
                        let nr = _mm512_fnmadd_ps(qi[k], i[k], _mm512_fmadd_ps(qr[k], r[k], r[k]));
                        i[k] = _mm512_fmadd_ps(qi[k], r[k], _mm512_fmadd_ps(qr[k], i[k], i[k]));
                        r[k] = _mm512_fmadd_ps(g[k], xn, nr);
                    }
                    let a = accp.add(n * COLUMNS);
                    _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), fold(sum512(&i))));
                }
            }
            None => {
                for n in 0..acc.len() {
                    for k in 0..V {
                        let nr = _mm512_fnmadd_ps(qi[k], i[k], _mm512_fmadd_ps(qr[k], r[k], r[k]));
                        i[k] = _mm512_fmadd_ps(qi[k], r[k], _mm512_fmadd_ps(qr[k], i[k], i[k]));
                        r[k] = nr;
                    }
                    let a = accp.add(n * COLUMNS);
                    _mm256_storeu_ps(a, _mm256_add_ps(_mm256_loadu_ps(a), fold(sum512(&i))));
                }
            }
        }
        for k in 0..V {
            let o = start + k * W;
            _mm512_storeu_ps(p.re.add(o), r[k]);
            _mm512_storeu_ps(p.im.add(o), i[k]);
        }
    }
}
