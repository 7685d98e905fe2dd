"""The built VST3 bundle in pedalboard (a JUCE host): parameters, MIDI notes in, pitch and level
out, and the effect processing audio.

Needs the bundle: `cargo xtask bundle modal-resonator --release`.
"""

import pathlib

import mido
import numpy as np
import pytest
from pedalboard import load_plugin

RATE = 48_000
ROOT = pathlib.Path(__file__).resolve().parents[2]
BUNDLE = ROOT / "target" / "bundled" / "Modal Resonator.vst3"


def pitch_hz(x, lo, hi):
    """Fundamental by autocorrelation peak with parabolic refinement."""
    x = x[: RATE // 2].astype(np.float64)
    ac = np.correlate(x, x, mode="full")[len(x) - 1 :]
    lo_lag, hi_lag = int(RATE / hi), int(RATE / lo)
    lag = lo_lag + int(np.argmax(ac[lo_lag:hi_lag]))
    a, b, c = ac[lag - 1], ac[lag], ac[lag + 1]
    shift = 0.5 * (a - c) / (a - 2 * b + c)
    return RATE / (lag + shift)


@pytest.fixture(scope="module")
def instrument():
    assert BUNDLE.exists(), f"{BUNDLE} is missing: run cargo xtask bundle modal-resonator --release"
    return load_plugin(str(BUNDLE), plugin_name="Modal Resonator", initialization_timeout=120)


@pytest.fixture(scope="module")
def effect():
    return load_plugin(str(BUNDLE), plugin_name="Modal Resonator FX", initialization_timeout=120)


def test_the_instrument_lists_its_parameters(instrument):
    assert instrument.is_instrument
    names = set(instrument.parameters.keys())
    for name in ["material", "size_x", "strike_position", "hardness_ms", "polyphony", "output_gain_db", "input_mode"]:
        assert name in names, f"{name} missing from {sorted(names)[:40]}"


def test_a_note_sounds_at_its_pitch_and_level_and_nothing_leaks(instrument):
    instrument.reset()
    notes = [mido.Message("note_on", note=69, velocity=127, time=0.1), mido.Message("note_off", note=69, time=0.9)]
    out = instrument(notes, duration=1.0, sample_rate=RATE, buffer_size=512)
    assert out.shape == (2, RATE)
    # Nothing before the note: no test note of the host leaks in.
    assert np.max(np.abs(out[:, : int(0.1 * RATE)])) == 0.0
    peak = float(np.max(np.abs(out)))
    assert 0.06 < peak < 1.0, peak
    got = pitch_hz(out[0, int(0.1 * RATE) + 100 :], 300, 600)
    assert abs(got / 440.0 - 1) < 0.005, got


def test_size_lowers_the_pitch(instrument):
    instrument.reset()
    instrument.size_x = 2.0
    try:
        out = instrument([mido.Message("note_on", note=69, velocity=127, time=0.0)], duration=0.6, sample_rate=RATE)
        got = pitch_hz(out[0, 100:], 150, 300)
        assert abs(got / 220.0 - 1) < 0.005, got
    finally:
        instrument.size_x = 1.0


def test_the_effect_rings_its_input(effect):
    assert not effect.is_instrument
    rng = np.random.default_rng(1)
    x = np.zeros((2, RATE), dtype=np.float32)
    x[:, : RATE // 20] = rng.uniform(-0.25, 0.25, (2, RATE // 20))
    effect.dry_wet = 100.0
    out = effect(x, RATE)
    assert out.shape == x.shape
    assert np.all(np.isfinite(out))
    tail = float(np.max(np.abs(out[:, RATE // 10 :])))
    assert tail > 1e-3, tail
