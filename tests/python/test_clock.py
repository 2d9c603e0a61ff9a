# advance(): durations in exact seconds, the real-time cap, what a frame between ticks shows.
from fractions import Fraction

import numpy as np
import pytest
import tickfx


@pytest.fixture
def fountain(samples):
    return tickfx.load_effect(samples / "fountain.toml")


def test_effect_properties(fountain, samples):
    assert fountain.output_fps == Fraction(24)
    assert isinstance(fountain.output_fps, Fraction)
    assert fountain.output_frames == 120  # 5 s at 24 fps
    assert fountain.step_rate == 120
    assert fountain.max_particles == 100000
    assert fountain.tick == 0 and fountain.count == 0 and fountain.time == 0.0
    assert fountain.path == str(samples / "fountain.toml")
    assert tickfx.FLICKS_PER_SECOND == 705600000


def test_durations_must_be_whole_flicks(fountain):
    with pytest.raises(ValueError, match=r"1/11 s is not a whole number of flicks.*"
                                         r"nearest is 64145455 flicks = 12829091/141120000 s"):
        fountain.advance(Fraction(1, 11))
    with pytest.raises(ValueError, match="finite"):
        fountain.advance(float("nan"))
    with pytest.raises(ValueError, match="finite"):
        fountain.advance(float("inf"))
    with pytest.raises(ValueError, match=">= 0"):
        fountain.advance(Fraction(-1, 24))
    with pytest.raises(TypeError):
        fountain.advance("0.1")
    with pytest.raises(TypeError):
        fountain.advance(True)
    assert fountain.tick == 0  # refused durations run nothing
    # 1001/30000 s (NTSC) is a whole number of flicks.
    assert fountain.advance(Fraction(1001, 30000)).ticks == 5
    assert fountain.advance(0).ticks == 0


def test_float_durations_round_to_the_nearest_flick(fountain):
    # 1e-9 s is 0.7056 flicks: one flick. Ten of them are still far from a tick (1/120 s).
    assert [fountain.advance(1e-9).ticks for _ in range(10)] == [1] + [0] * 9
    assert fountain.time == 10 / tickfx.FLICKS_PER_SECOND


def test_frame_between_ticks(fountain):
    fountain.advance(Fraction(1, 2))  # 60 ticks, on a tick
    assert (fountain.tick, fountain.alpha, fountain.time) == (60, 1.0, 0.5)
    fountain.advance(Fraction(1, 100))  # 1.2 ticks more: tick 62 runs, the frame is at 61.2
    assert fountain.tick == 62
    assert fountain.alpha == pytest.approx(0.2)
    assert fountain.time == pytest.approx(0.51, abs=1e-15)
    shown = fountain.interpolated_positions()
    assert shown.dtype == np.float32 and shown.shape == (fountain.count, 3)
    assert shown.flags.c_contiguous and shown.flags.writeable
    # The render copy is the interpolation by the frame's own alpha, bit for bit ...
    by_alpha = fountain.interpolated_positions(fountain.alpha)
    assert shown.tobytes() == by_alpha.tobytes()
    # ... and lies strictly between the ticks for moving particles.
    newest = fountain.interpolated_positions(1.0)
    previous = fountain.interpolated_positions(0.0)
    assert not np.array_equal(shown, newest) and not np.array_equal(shown, previous)
    x, y, z = fountain.positions
    assert newest[:, 0].tobytes() == x.tobytes()
    assert newest[:, 1].tobytes() == y.tobytes()
    assert newest[:, 2].tobytes() == z.tobytes()
    # capture() shows the same frame as interpolated_positions().
    assert fountain.capture()["P"].tobytes() == shown.tobytes()
    for bad in (-0.01, 1.01, float("nan")):
        with pytest.raises(ValueError, match=r"alpha must be in \[0, 1\]"):
            fountain.interpolated_positions(bad)


def test_real_time_host_gets_dropped_ticks_reported(samples):
    realtime = tickfx.load_effect(samples / "fountain.toml", offline=False)
    # A one-second hitch at 120 Hz: max_ticks_per_frame = 16 run, the rest are dropped.
    assert realtime.advance(1) == tickfx.AdvanceResult(ticks=16, dropped=104)
    assert realtime.tick == 16
    offline = tickfx.load_effect(samples / "fountain.toml")
    assert offline.advance(1) == tickfx.AdvanceResult(ticks=120, dropped=0)


def test_threads_argument_is_checked(samples):
    with pytest.raises(ValueError):
        tickfx.load_effect(samples / "fountain.toml", threads=-1)
    with pytest.raises(ValueError):
        tickfx.load_effect(samples / "fountain.toml", threads=100000)
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", threads=1.5)
