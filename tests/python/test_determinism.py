# The module runs the command line's simulation: same effect, same frames, same state bits.
from fractions import Fraction

import pytest
import tickfx
from conftest import cli_hash, run_frames

HASH_SAMPLES = ["fountain.toml", "burst.toml", "rope_swing.toml"]


@pytest.mark.parametrize("name", HASH_SAMPLES)
def test_state_hash_matches_cli(cli, samples, name):
    expected_hash, expected_ticks = cli_hash(cli, samples / name)
    system = tickfx.load_effect(samples / name)
    run_frames(system)
    assert system.tick == expected_ticks
    assert system.state_hash() == expected_hash
    assert system.count > 0


@pytest.mark.parametrize("name", HASH_SAMPLES)
def test_views_taken_from_the_start_change_nothing(cli, samples, name):
    # The first view reserves max_particles rows: the storage must not change the bits.
    expected_hash, expected_ticks = cli_hash(cli, samples / name)
    system = tickfx.load_effect(samples / name, threads=1)
    views = [system.positions, system.velocities, system.ids]
    frame = 1 / system.output_fps
    for _ in range(system.output_frames):
        system.advance(frame)
        views.append(system.ages)
    assert system.tick == expected_ticks
    assert system.state_hash() == expected_hash


def test_thread_counts_agree(cli, samples):
    expected_hash, _ = cli_hash(cli, samples / "burst.toml", "--threads", "1")
    for threads in (1, 2, 3):
        system = tickfx.load_effect(samples / "burst.toml", threads=threads)
        run_frames(system)
        assert system.state_hash() == expected_hash, f"threads={threads}"


def test_overrides_match_cli_set(cli, samples):
    overrides = {
        "simulation.step_rate": 240,
        "simulation.integrator": "velocity_verlet",
        "emitters.1.surface": False,
        "emitters.1.bursts": [{"time": 0.5, "count": 300}, {"time": 1.25, "count": 40}],
        "emitters.0.direction": [0.0, -1.0, 0.5],
        "forces.1.k": 0.75,
    }
    expected_hash, expected_ticks = cli_hash(
        cli,
        samples / "burst.toml",
        "--set", "simulation.step_rate=240",
        "--set", "simulation.integrator=velocity_verlet",
        "--set", "emitters.1.surface=false",
        "--set", "emitters.1.bursts=[{time = 0.5, count = 300}, {time = 1.25, count = 40}]",
        "--set", "emitters.0.direction=[0.0, -1.0, 0.5]",
        "--set", "forces.1.k=0.75",
    )
    default_hash, _ = cli_hash(cli, samples / "burst.toml")
    assert expected_hash != default_hash

    system = tickfx.load_effect(samples / "burst.toml", overrides)
    assert system.step_rate == 240
    run_frames(system)
    assert system.tick == expected_ticks == 960
    assert system.state_hash() == expected_hash


def test_float_and_fraction_durations_reach_the_same_state(samples):
    exact = tickfx.load_effect(samples / "fountain.toml")
    approx = tickfx.load_effect(samples / "fountain.toml")
    for _ in range(48):
        exact.advance(Fraction(1, 24))
        approx.advance(1 / 24)  # 0.041666666666666664 s: the nearest flick is 1/24 s exactly
    assert exact.tick == approx.tick == 240
    assert exact.time == approx.time == 2.0
    assert exact.state_hash() == approx.state_hash()


def test_step_runs_ticks_like_advance(samples):
    stepped = tickfx.load_effect(samples / "rope_swing.toml")
    advanced = tickfx.load_effect(samples / "rope_swing.toml")
    stepped.step(stepped.step_rate)  # one second of ticks
    result = advanced.advance(1)
    assert result == tickfx.AdvanceResult(ticks=advanced.step_rate, dropped=0)
    assert stepped.tick == advanced.tick == advanced.step_rate
    assert stepped.alpha == advanced.alpha == 1.0
    assert stepped.time == advanced.time == 1.0
    assert stepped.state_hash() == advanced.state_hash()
    stepped.step(0)
    assert stepped.tick == advanced.step_rate
    with pytest.raises(ValueError):
        stepped.step(-1)
