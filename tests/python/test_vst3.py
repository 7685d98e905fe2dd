"""The built VST3 bundle in pedalboard (a JUCE host): parameters, MIDI notes in, pitch and level
out, and the effect processing audio.

Needs the bundle: `cargo xtask bundle modal-resonator --release`.
"""

import pathlib

import mido
import numpy as np
import pytest
from pedalboard import load_plugin

# The VST3 carries hidden parameters that stand for the MIDI controllers it reads on each channel
# ("MIDI CC 0|1" ... "MIDI CC 15|129", as JUCE names them): that is how VST3 delivers pitch bend,
# the mod wheel and pressure. pedalboard leaves parameters so named out of its list, and MIDI
# messages still reach the plugin through them.

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


# The instrument's own parameters (src/params.rs), the bypass among them.
INSTRUMENT_PARAMETERS = 40


def test_pedalboard_lists_the_parameters_and_not_the_controller_proxies(instrument):
    names = list(instrument.parameters.keys())
    assert not [n for n in names if n.startswith("midi")], names
    assert len(names) == INSTRUMENT_PARAMETERS, f"{len(names)} parameters: {names}"


def test_pitch_bend_reaches_the_plugin_through_the_skipped_proxies(instrument):
    instrument.reset()
    # Full bend up is +2 semitones at the default bend range.
    messages = [
        mido.Message("pitchwheel", pitch=8191, time=0.0),
        mido.Message("note_on", note=69, velocity=127, time=0.05),
    ]
    try:
        out = instrument(messages, duration=0.6, sample_rate=RATE, buffer_size=512)
        got = pitch_hz(out[0, int(0.05 * RATE) + 100 :], 300, 700)
        want = 440.0 * 2 ** (2 / 12)
        assert abs(got / want - 1) < 0.005, got
    finally:
        instrument.reset()
        instrument([mido.Message("pitchwheel", pitch=0, time=0.0)], duration=0.01, sample_rate=RATE)


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


TINY = np.finfo(np.float32).tiny


def subnormal_samples(x):
    x = np.asarray(x, dtype=np.float32)
    return int(np.count_nonzero((x != 0) & (np.abs(x) < TINY)))


@pytest.mark.parametrize("rate", [1_234.5678, 11_025.0, 96_000.0, 1_234_567.8])
def test_both_plugins_play_at_any_rate_and_no_subnormal_sample_leaves_them(instrument, effect, rate):
    n = int(rate * 0.5)
    # A burst, then a tail of subnormal input the dry path would pass through.
    rng = np.random.default_rng(7)
    x = np.zeros((2, n), dtype=np.float32)
    burst = max(n // 20, 8)
    x[:, :burst] = rng.uniform(-0.25, 0.25, (2, burst))
    x[:, burst:] = (rng.uniform(-1, 1, (2, n - burst)) * 2 * TINY).astype(np.float32)
    assert subnormal_samples(x) > 0
    effect.reset()
    effect.dry_wet = 50.0
    out = effect(x, rate, buffer_size=256)
    assert np.all(np.isfinite(out))
    assert subnormal_samples(out) == 0, f"{subnormal_samples(out)} subnormal samples at {rate} Hz"
    assert np.max(np.abs(out)) > 0.01

    instrument.reset()
    messages = [mido.Message("note_on", note=69, velocity=127, time=0.0)]
    out = instrument(messages, duration=0.5, sample_rate=rate, buffer_size=256)
    assert np.all(np.isfinite(out))
    assert subnormal_samples(out) == 0, f"{subnormal_samples(out)} subnormal samples at {rate} Hz"
    if rate >= 11_025:
        assert np.max(np.abs(out)) > 0.06
