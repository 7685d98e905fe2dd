#!/usr/bin/env python3
"""Draws the spectrogram of a 16-bit WAV file (as `modal-resonator render --bits 16` writes it)
into a PNG image: time across, frequency up (logarithmic), level in dB below the loudest point.

    python3 tools/spectrogram.py render.wav image.png --title "Scraped steel sheet"

Needs numpy and matplotlib (`pip install numpy matplotlib`).
"""

import argparse
import wave

import numpy as np


def read_wav(path):
    with wave.open(path, "rb") as w:
        if w.getsampwidth() != 2:
            raise SystemExit(f"{path}: expected 16-bit samples, found {8 * w.getsampwidth()}-bit")
        rate = w.getframerate()
        data = np.frombuffer(w.readframes(w.getnframes()), dtype="<i2").astype(np.float64)
        data = data.reshape(-1, w.getnchannels()).mean(axis=1) / 32768.0
    return data, rate


def spectrogram(x, rate, frame=4096, hop=512):
    window = np.hanning(frame)
    starts = range(0, max(1, len(x) - frame), hop)
    frames = np.array([x[s : s + frame] * window for s in starts])
    power = np.abs(np.fft.rfft(frames, axis=1)) ** 2
    db = 10 * np.log10(power + 1e-20)
    times = (np.array(list(starts)) + frame / 2) / rate
    freqs = np.fft.rfftfreq(frame, 1 / rate)
    return times, freqs, db - db.max()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("wav")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    parser.add_argument("--range-db", type=float, default=80.0)
    parser.add_argument("--min-hz", type=float, default=50.0)
    parser.add_argument("--max-hz", type=float, default=16000.0)
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x, rate = read_wav(args.wav)
    times, freqs, db = spectrogram(x, rate)
    keep = (freqs >= args.min_hz) & (freqs <= args.max_hz)
    fig, ax = plt.subplots(figsize=(8, 3.6), dpi=100)
    mesh = ax.pcolormesh(
        times, freqs[keep], db[:, keep].T, shading="auto", cmap="magma",
        vmin=-args.range_db, vmax=0,
    )
    ax.set_yscale("log")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(args.title)
    fig.colorbar(mesh, ax=ax, label="dB")
    fig.tight_layout()
    fig.savefig(args.png)


if __name__ == "__main__":
    main()
