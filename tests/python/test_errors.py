# Effect errors come back as EffectError with exactly the lines `tickfx check` prints.
import pickle
import re

import pytest
import tickfx
from conftest import run_cli

BAD_EFFECT = """\
format_version = 1

[simulation]
step_rate = "fast"
integratr = "rk4"

[[emitters]]
shape = "point"
rate = 100.0
lifetime = 1.0

[output]
fps = 24
seconds = 1.0
"""

DIAGNOSTIC = re.compile(r"^.+:\d+:\d+: error: [a-z_.0-9]+: .+$")


def cli_check_lines(cli, path, *args, expect):
    _, err = run_cli(cli, "check", path, *args, expect=expect)
    return [line for line in err.splitlines() if ": error: " in line or ": warning: " in line]


@pytest.fixture
def bad_effect(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BAD_EFFECT)
    return path


def test_bad_effect_raises_the_cli_diagnostics(cli, bad_effect):
    expected = cli_check_lines(cli, bad_effect, expect=2)
    assert len(expected) == 2
    assert all(DIAGNOSTIC.match(line) for line in expected)
    assert expected[0].startswith(f"{bad_effect}:4:13: error: simulation.step_rate: ")
    assert expected[1].startswith(f"{bad_effect}:5:1: error: simulation.integratr: ")
    assert "integrator" in expected[1]  # did you mean

    with pytest.raises(tickfx.EffectError) as raised:
        tickfx.load_effect(bad_effect)
    assert raised.value.diagnostics == expected
    assert str(raised.value) == "\n".join(expected)
    assert isinstance(raised.value, ValueError)

    with pytest.raises(tickfx.EffectError) as checked:
        tickfx.check(str(bad_effect))
    assert checked.value.diagnostics == expected

    copy = pickle.loads(pickle.dumps(raised.value))
    assert copy.diagnostics == expected and str(copy) == str(raised.value)


def test_bad_override_names_the_override(cli, samples):
    effect = samples / "fountain.toml"
    expected = cli_check_lines(
        cli, effect, "--set", "simulation.step_rate=0", "--set", "emitters.0.sped=3", expect=2
    )
    assert len(expected) == 2
    with pytest.raises(tickfx.EffectError) as raised:
        tickfx.load_effect(effect, {"simulation.step_rate": 0, "emitters.0.sped": 3})
    assert raised.value.diagnostics == expected
    assert expected[0].startswith("--set simulation.step_rate: error: ")


def test_missing_file(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(tickfx.EffectError, match=re.escape(str(missing))):
        tickfx.load_effect(missing)


def test_check_returns_the_cli_warnings(cli, samples):
    effect = samples / "wind_aliasing.toml"
    expected = cli_check_lines(cli, effect, expect=0)
    assert len(expected) == 1 and ": warning: forces.0.frequency: " in expected[0]
    assert tickfx.check(effect) == expected
    assert tickfx.check(samples / "wind_aliasing_fixed.toml") == []
    # A wind sampled fast enough no longer warns.
    assert tickfx.check(effect, {"simulation.step_rate": 240}) == []


def test_override_values_are_checked(samples):
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", {"simulation.seed": object()})
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", [("simulation.seed", 1)])
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", {1: 2})


# The flag under explicit Euler at 30 Hz: `tickfx run` stops at tick 19 (test_cli.cpp); here the
# same event comes back as a value, and the system runs no further.
UNSTABLE_FLAG = {"simulation.step_rate": 30, "simulation.integrator": "explicit_euler"}


def test_nonfinite_stop_is_reported_as_a_value(samples):
    system = tickfx.load_effect(samples / "flag.toml", UNSTABLE_FLAG)
    assert system.nonfinite_stop is None
    system.advance(1.0)
    event = system.nonfinite_stop
    assert isinstance(event, tickfx.NonfiniteEvent)
    assert (event.tick, event.particles, event.first_ids) == (19, 58, list(range(10, 18)))
    assert event.time == pytest.approx(19 / 30, rel=1e-15)
    assert str(event) == (
        "tick 19 (t = 0.633333333 s): 58 particles have a non-finite position or velocity "
        "(ids 10, 11, 12, 13, 14, 15, 16, 17, ...)"
    )
    assert system.tick == 19
    system.step(10)
    system.advance(1.0)
    assert system.tick == 19, "a stopped system runs no more ticks"


def test_nonfinite_kill_counts_the_removed(samples):
    system = tickfx.load_effect(
        samples / "flag.toml", {**UNSTABLE_FLAG, "simulation.nonfinite": "kill"}
    )
    system.advance(10.0)
    assert system.nonfinite_stop is None
    assert (system.nonfinite_killed, system.count) == (150, 10)
