//! Spectra by critical band for the benchmark's difference signals.

use modal_resonator::dsp::masking::hz_to_bark;

use crate::RATE_HZ;

/// In-place iterative radix-2 FFT of `re`, `im` (length a power of two).
pub fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let twiddles: Vec<(f64, f64)> = (0..n / 2)
        .map(|k| (-std::f64::consts::TAU * k as f64 / n as f64).sin_cos())
        .collect();
    let mut len = 2;
    while len <= n {
        let stride = n / len;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = twiddles[k * stride];
                let (a, b) = (start + k, start + k + len / 2);
                let (tr, ti) = (re[b] * c - im[b] * s, re[b] * s + im[b] * c);
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len <<= 1;
    }
}

/// Power of `x` in each critical band (Bark 0-1, 1-2, ... 24-25), averaged over Hann-windowed
/// frames (Welch).
pub fn band_power(x: &[f32]) -> [f64; 25] {
    const N: usize = 4096;
    let window: Vec<f64> = (0..N)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / N as f64).cos())
        .collect();
    let band_of: Vec<usize> = (0..N / 2)
        .map(|k| (hz_to_bark(k as f64 * RATE_HZ / N as f64) as usize).min(24))
        .collect();
    let mut bands = [0.0; 25];
    let (mut re, mut im) = (vec![0.0; N], vec![0.0; N]);
    for frame in x.chunks_exact(N / 2).collect::<Vec<_>>().windows(2) {
        for i in 0..N / 2 {
            re[i] = frame[0][i] as f64 * window[i];
            re[i + N / 2] = frame[1][i] as f64 * window[i + N / 2];
        }
        im.fill(0.0);
        fft(&mut re, &mut im);
        for k in 1..N / 2 {
            bands[band_of[k]] += re[k] * re[k] + im[k] * im[k];
        }
    }
    bands
}

pub fn db(x: f64) -> f64 {
    10.0 * x.max(1e-300).log10()
}

/// The frequency in Hz at `bark` on the Bark scale, by bisection of [`hz_to_bark`].
pub fn bark_to_hz(bark: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 30_000.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if hz_to_bark(mid) < bark {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}
