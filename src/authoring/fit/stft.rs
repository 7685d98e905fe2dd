//! Short-time Fourier transform with a Hann window (seed 000 section 3.3): power spectra of
//! overlapping frames, zero-padded so peaks can be located between bins.

use realfft::RealFftPlanner;

/// A Hann window of `len` samples, symmetric about `(len - 1) / 2` so a frame's time is its
/// centre.
pub fn hann(len: usize) -> Vec<f64> {
    let denom = (len.max(2) - 1) as f64;
    (0..len)
        .map(|k| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / denom).cos())
        .collect()
}

/// Power spectra of the frames of a signal.
#[derive(Debug, Clone)]
pub struct Spectrogram {
    /// FFT length: the window zero-padded by `pad`.
    pub fft_len: usize,
    /// Zero-padding factor: FFT bins per bin of the unpadded window.
    pub pad: usize,
    /// Width of one FFT bin in Hz.
    pub bin_hz: f64,
    /// `|X|^2` of each frame, `fft_len / 2 + 1` bins.
    pub power: Vec<Vec<f64>>,
}

impl Spectrogram {
    /// Frames of `window_len` samples every `hop` samples over the whole of `x` (a last partial
    /// frame is dropped), each windowed, zero-padded to `pad * window_len` and transformed.
    pub fn new(x: &[f64], sample_rate_hz: f64, window_len: usize, hop: usize, pad: usize) -> Self {
        let fft_len = window_len * pad;
        let mut planner = RealFftPlanner::<f64>::new();
        let fft = planner.plan_fft_forward(fft_len);
        let window = hann(window_len);
        let mut input = fft.make_input_vec();
        let mut output = fft.make_output_vec();
        let mut power = Vec::new();
        let mut start = 0;
        while start + window_len <= x.len() {
            input.fill(0.0);
            for ((i, w), v) in input.iter_mut().zip(&window).zip(&x[start..]) {
                *i = w * v;
            }
            fft.process(&mut input, &mut output)
                .expect("buffers sized by the planner");
            power.push(output.iter().map(|c| c.norm_sqr()).collect());
            start += hop.max(1);
        }
        Self {
            fft_len,
            pad,
            bin_hz: sample_rate_hz / fft_len as f64,
            power,
        }
    }

    /// Number of bins per frame.
    pub fn num_bins(&self) -> usize {
        self.fft_len / 2 + 1
    }

    /// The bin nearest `freq_hz`, clamped to the spectrum.
    pub fn bin_of(&self, freq_hz: f64) -> usize {
        ((freq_hz / self.bin_hz).round().max(0.0) as usize).min(self.num_bins() - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sinusoid_peaks_at_its_bin_with_the_window_gain() {
        let rate = 48_000.0;
        let (len, pad) = (1024, 2);
        let f = 30.0 * rate / (len * pad) as f64; // exactly on bin 30
        let x: Vec<f64> = (0..4096)
            .map(|n| (std::f64::consts::TAU * f * n as f64 / rate).cos())
            .collect();
        let s = Spectrogram::new(&x, rate, len, len / 4, pad);
        assert_eq!(s.power.len(), (4096 - len) / (len / 4) + 1);
        let frame = &s.power[0];
        let peak = (0..s.num_bins())
            .max_by(|&a, &b| frame[a].total_cmp(&frame[b]))
            .unwrap();
        assert_eq!(peak, 30);
        // |X| of a unit cosine on a bin is half the window's sum.
        let sum: f64 = hann(len).iter().sum();
        let magnitude = frame[30].sqrt();
        assert!(
            (magnitude / (0.5 * sum) - 1.0).abs() < 1e-3,
            "{magnitude} vs {}",
            0.5 * sum
        );
    }
}
