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

/// Length of the frames the noise-to-mask ratio is measured over, in seconds.
pub const NMR_FRAME_S: f64 = 0.02;

/// Noise-to-mask ratios of a difference signal against the masking threshold of the signal it
/// was taken from, per 20 ms frame and critical band.
pub struct Nmr {
    /// Frame-bands measured.
    pub cells: usize,
    /// Share of them at or below 0 dB.
    pub share_ok: f64,
    /// The 99th percentile, in dB.
    pub p99_db: f64,
    /// The worst, in dB, its critical band and the time of its frame in seconds.
    pub worst: (f64, usize, f64),
    /// The frame-bands over 0 dB: the frame's start in seconds, the band, and the difference's
    /// level over the signal's there in dB (above 0 only where the unpruned signal cancels
    /// itself, as two modes of nearly one frequency in opposite phase do, and pruning took one).
    pub over: Vec<(f64, usize, f64)>,
    /// The worst frame, band by band: signal, difference, masking curve and threshold in quiet,
    /// in dB SPL.
    pub worst_frame: Vec<[f64; 4]>,
}

/// Mean square of `x` (each channel's averaged) in each critical band, per frame of
/// [`NMR_FRAME_S`]: Hann-windowed frames half a frame apart, zero-padded to a power of two, the
/// power normalised so a sine of amplitude `A` has mean square `A^2 / 2` in its band.
pub fn frame_band_power(channels: [&[f32]; 2]) -> Vec<[f64; 25]> {
    let len = (NMR_FRAME_S * RATE_HZ) as usize;
    let hop = len / 2;
    let n = len.next_power_of_two();
    let window: Vec<f64> = (0..len)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / len as f64).cos())
        .collect();
    let window_power: f64 = window.iter().map(|w| w * w).sum();
    let band_of: Vec<usize> = (0..n / 2)
        .map(|k| (hz_to_bark(k as f64 * RATE_HZ / n as f64) as usize).min(24))
        .collect();
    let frames = (channels[0].len().min(channels[1].len()) + hop).saturating_sub(len) / hop;
    let (mut re, mut im) = (vec![0.0; n], vec![0.0; n]);
    (0..frames)
        .map(|f| {
            let mut bands = [0.0; 25];
            for x in channels {
                re.fill(0.0);
                im.fill(0.0);
                for (i, w) in window.iter().enumerate() {
                    re[i] = x[f * hop + i] as f64 * w;
                }
                fft(&mut re, &mut im);
                // One side of the spectrum holds half of `n` times the windowed frame's sum of
                // squares; two channels are averaged.
                for k in 1..n / 2 {
                    bands[band_of[k]] +=
                        (re[k] * re[k] + im[k] * im[k]) / (n as f64 * window_power);
                }
            }
            bands
        })
        .collect()
}

/// The level in dB SPL of a mean square, with a sine of amplitude 1 at `playback_db_spl`.
pub fn spl(mean_square: f64, playback_db_spl: f64) -> f64 {
    playback_db_spl + db(2.0 * mean_square)
}

/// The noise-to-mask ratio of `diff` against `signal` (both stereo): in each 20 ms frame (half a
/// frame apart), each
/// critical band's level of the signal, in dB SPL with a sine of amplitude 1 at
/// `playback_db_spl`, is a masker at the band's centre with the two-slope curve at masking offset
/// `offset_db` (seed 001 eq. 4); the threshold of a band is the highest of those curves and the
/// threshold in quiet (its lowest over the band); the ratio is the difference's level in the band
/// over that threshold.
pub fn nmr(signal: [&[f32]; 2], diff: [&[f32]; 2], playback_db_spl: f64, offset_db: f64) -> Nmr {
    use modal_resonator::dsp::masking::{masking_curve_db, threshold_in_quiet_db};
    let spl = |mean_square: f64| spl(mean_square, playback_db_spl);
    let quiet: Vec<f64> = (0..25)
        .map(|b| {
            let lo = bark_to_hz(b as f64).max(20.0);
            let hi = bark_to_hz(b as f64 + 1.0).clamp(lo, 20_000.0);
            (0..=8)
                .map(|i| threshold_in_quiet_db(lo * (hi / lo).powf(i as f64 / 8.0)))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let (s, d) = (frame_band_power(signal), frame_band_power(diff));
    let s = hold_maskers(&s);
    let mut ratios = Vec::with_capacity(25 * s.len());
    let mut worst = (f64::NEG_INFINITY, 0, 0.0);
    let (mut over, mut worst_frame) = (Vec::new(), Vec::new());
    let curve = |s: &[f64; 25], b: usize| {
        (0..25)
            .filter(|&j| s[j] > 0.0)
            .map(|j| {
                masking_curve_db(
                    j as f32 + 0.5,
                    spl(s[j]) as f32,
                    offset_db as f32,
                    b as f32 + 0.5,
                ) as f64
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for (f, (s, d)) in s.iter().zip(&d).enumerate() {
        let start_s = f as f64 * 0.5 * NMR_FRAME_S;
        let mut frame_worst = false;
        for b in 0..25 {
            let ratio = spl(d[b]) - curve(s, b).max(quiet[b]);
            if ratio > 0.0 {
                over.push((start_s, b, spl(d[b]) - spl(s[b])));
            }
            if ratio > worst.0 {
                worst = (ratio, b, start_s);
                frame_worst = true;
            }
            ratios.push(ratio);
        }
        if frame_worst {
            worst_frame = (0..25)
                .map(|b| [spl(s[b]), spl(d[b]), curve(s, b), quiet[b]])
                .collect();
        }
    }
    let cells = ratios.len();
    let ok = ratios.iter().filter(|&&r| r <= 0.0).count();
    ratios.sort_by(f64::total_cmp);
    let p99 = ratios
        .get(((cells as f64 * 0.99) as usize).min(cells.saturating_sub(1)))
        .copied()
        .unwrap_or(f64::NEG_INFINITY);
    Nmr {
        cells,
        share_ok: ok as f64 / cells.max(1) as f64,
        p99_db: p99,
        worst,
        over,
        worst_frame,
    }
}

/// The signal's band powers as maskers: with `PRUNING_MASK_HOLD_MS` (default 0, the measure as
/// defined), each band's level is the highest over that many milliseconds of frames before and
/// this one, a crude stand-in for forward masking (which in hearing lasts 100-200 ms). Without
/// it, a frame where the unpruned signal dips (two modes of one band beating, a null between
/// strikes) is judged as though nothing had sounded just before.
fn hold_maskers(s: &[[f64; 25]]) -> Vec<[f64; 25]> {
    let hold_ms: f64 = std::env::var("PRUNING_MASK_HOLD_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    let frames = (hold_ms * 1e-3 / (0.5 * NMR_FRAME_S)).round() as usize;
    (0..s.len())
        .map(|f| {
            std::array::from_fn(|b| {
                s[f.saturating_sub(frames)..=f]
                    .iter()
                    .map(|frame| frame[b])
                    .fold(0.0, f64::max)
            })
        })
        .collect()
}

/// Third difference: a steep high-pass (18 dB per octave), under which a step or a kink stands
/// out of ringing modes.
fn third_difference(x: &[f32]) -> Vec<f32> {
    x.windows(4)
        .map(|w| w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0])
        .collect()
}

/// The worst click of a pruned render: over the control ticks (every `period` samples) from 1 to
/// 50 ms after each strike in `strikes`, where the difference's high band stands more than four
/// times out of its neighbourhood, the largest ratio of the difference's high band there to the
/// unpruned signal's own around it, and the sample of that tick; 0 (at sample 0) where no tick
/// stands out. A click is many times the signal's own.
pub fn worst_click(signal: &[f32], diff: &[f32], strikes: &[usize], period: usize) -> (f64, usize) {
    let (d, f) = (third_difference(diff), third_difference(signal));
    let abs_max = |x: &[f32]| x.iter().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
    let ms = (RATE_HZ * 1e-3) as usize;
    let mut worst = (0.0, 0);
    for &at in strikes {
        let to = (at + 50 * ms).min(d.len().saturating_sub(period + 1));
        let mut tick = (at + ms).next_multiple_of(period);
        while tick < to {
            let here = abs_max(&d[tick - 3..tick]);
            let around =
                abs_max(&d[tick - period..tick - 4]).max(abs_max(&d[tick + 1..tick + period - 4]));
            let own = abs_max(&f[tick - period..tick + period]).max(1e-30);
            if here > 4.0 * around && here / own > worst.0 {
                worst = (here / own, tick);
            }
            tick += period;
        }
    }
    worst
}
