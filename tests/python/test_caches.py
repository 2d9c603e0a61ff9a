# read_cache / write_cache: every attribute back bit for bit, in every format, for caches the
# command line wrote and caches the module wrote.
from fractions import Fraction

import numpy as np
import pytest
import tickfx
from conftest import run_cli, run_frames

FORMATS = ["csv", "ply", "vdb"]
STANDARD = ["P", "v", "id", "age", "life", "mass"]


def assert_same_bits(actual, expected):
    assert list(actual) == list(expected)
    for name in expected:
        a, e = actual[name], expected[name]
        assert a.dtype == e.dtype, name
        assert a.shape == e.shape, name
        assert a.tobytes() == e.tobytes(), name


@pytest.fixture(scope="module")
def cli_frames(cli, samples, tmp_path_factory):
    """Frame 36 of the fountain (1.5 s) written by `tickfx run` in all three formats, and the
    System that reached the same frame in Python."""
    out = tmp_path_factory.mktemp("cli_caches")
    run_cli(cli, "run", samples / "fountain.toml", "--frames", "36", "--format", "csv,ply,vdb",
            "--out", out, "--quiet")
    system = tickfx.load_effect(samples / "fountain.toml")
    frame = 1 / system.output_fps
    for _ in range(36):
        system.advance(frame)
    return out, system


@pytest.mark.parametrize("fmt", FORMATS)
def test_cli_cache_reads_as_the_python_frame(cli_frames, fmt):
    out, system = cli_frames
    columns = tickfx.read_cache(out / f"frame_0036.{fmt}")
    assert list(columns) == STANDARD
    n = system.count
    assert n > 2000
    assert columns["P"].shape == (n, 3) and columns["P"].dtype == np.float32
    assert columns["v"].shape == (n, 3) and columns["v"].dtype == np.float32
    assert columns["id"].shape == (n,) and columns["id"].dtype == np.int64
    for name in ("age", "life", "mass"):
        assert columns[name].shape == (n,) and columns[name].dtype == np.float32
    assert_same_bits(columns, system.capture())
    assert np.all(columns["mass"] == 1.0)
    assert columns["age"].max() <= 1.5


def test_hit_attributes_in_every_format_as_capture_has_them(cli, samples, tmp_path):
    # The fountain's drops bounce on its ground: with output.hits they carry Houdini's hit
    # attributes, hitnum an int32 and the vectors (N, 3), in every format as in capture().
    run_cli(cli, "run", samples / "fountain.toml", "--frames", "36", "--format", "csv,ply,vdb",
            "--set", "output.hits=true", "--out", tmp_path, "--quiet")
    system = tickfx.load_effect(samples / "fountain.toml", {"output.hits": True})
    run_frames(system, 36)
    shown = system.capture()
    hits = ["hitnum", "hittime", "hitpos", "hitnml", "hitv"]
    assert list(shown) == STANDARD + hits
    n = system.count
    assert shown["hitnum"].dtype == np.int32 and shown["hitnum"].max() >= 1
    for name in ("hitpos", "hitnml", "hitv"):
        assert shown[name].shape == (n, 3) and shown[name].dtype == np.float32
    hit = shown["hitnum"] > 0
    assert np.all(shown["hitnml"][hit] == [0.0, 1.0, 0.0])  # the ground's normal
    assert np.all(shown["hitv"][hit][:, 1] < 0.0)  # falling onto it
    assert np.all((shown["hittime"][hit] > 0.0) & (shown["hittime"][hit] <= 1.5))
    for fmt in FORMATS:
        assert_same_bits(tickfx.read_cache(tmp_path / f"frame_0036.{fmt}"), shown)
        mine = tmp_path / f"mine.{fmt}"
        tickfx.write_cache(mine, shown, frame=36, time=system.time, system=system)
        assert mine.read_bytes() == (tmp_path / f"frame_0036.{fmt}").read_bytes(), fmt


def test_colour_opacity_and_size_over_life_in_every_format(cli, samples, tmp_path):
    # The fireworks' sparks at 3 s: Cd (N, 3), Alpha and pscale evaluated at the frame's own ages,
    # the same in capture(), in every cache the command line wrote and in the module's own.
    run_cli(cli, "run", samples / "fireworks.toml", "--frames", "72", "--format", "csv,ply,vdb",
            "--out", tmp_path, "--quiet")
    system = tickfx.load_effect(samples / "fireworks.toml")
    run_frames(system, 72)
    shown = system.capture()
    assert list(shown) == STANDARD + ["emitter", "Alpha", "Cd", "pscale"]
    sparks = shown["emitter"] == 1
    assert sparks.sum() % 150 == 0 and sparks.sum() >= 300  # whole bursts of 150
    assert shown["Cd"].shape == (system.count, 3) and shown["Cd"].dtype == np.float32
    nage = np.minimum(shown["age"][sparks] / shown["life"][sparks], 1.0)
    # pscale falls linearly from 6 cm to 1.5 cm over a spark's life (float arithmetic).
    expected = np.float32(0.06) + (np.float32(0.015) - np.float32(0.06)) * nage.astype(np.float32)
    assert np.allclose(shown["pscale"][sparks], expected, rtol=0, atol=1e-7)
    assert np.all(shown["Alpha"][sparks] <= 1.0) and np.all(shown["Alpha"][sparks] >= 0.0)
    assert np.all(shown["pscale"][~sparks] == np.float32(0.12))  # the shells' constant
    for fmt in FORMATS:
        assert_same_bits(tickfx.read_cache(tmp_path / f"frame_0072.{fmt}"), shown)
        mine = tmp_path / f"mine.{fmt}"
        tickfx.write_cache(mine, shown, frame=72, time=system.time, system=system)
        assert mine.read_bytes() == (tmp_path / f"frame_0072.{fmt}").read_bytes(), fmt


@pytest.mark.parametrize("fmt", FORMATS)
def test_write_cache_matches_the_cli(cli_frames, tmp_path, fmt):
    out, system = cli_frames
    cli_file = out / f"frame_0036.{fmt}"
    mine = tmp_path / f"mine.{fmt}"
    tickfx.write_cache(mine, system.capture(), frame=36, time=system.time, system=system)
    assert_same_bits(tickfx.read_cache(mine), tickfx.read_cache(cli_file))
    # The same frame, frame number, time and effect: the same file, byte for byte (a .vdb's
    # metadata included).
    assert mine.read_bytes() == cli_file.read_bytes()
    # Rewriting what was read gives the same frame again.
    again = tmp_path / f"again.{fmt}"
    tickfx.write_cache(again, tickfx.read_cache(cli_file), frame=36, time=system.time,
                       system=system)
    assert_same_bits(tickfx.read_cache(again), tickfx.read_cache(cli_file))


def awkward_frame(fmt):
    """Values that a careless reader or writer would change: signed zeros, infinities, NaN,
    subnormals, the extremes of float32, large ids; plus two custom attributes."""
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-45, -1e-40, 3.4028235e38,
                        -3.4028235e38, 0.1, 1.0 / 3.0, 2.0 ** -126, 1e30, -7.25], dtype=np.float32)
    n = len(special)
    rng = np.random.default_rng(11)
    noise = rng.standard_normal((n, 3)).astype(np.float32) * np.float32(1e3)
    big = 2**53 if fmt == "ply" else 2**62 + 12345  # PLY stores ids as doubles
    ids = np.array([0, 1, 2, 3, 5, 8, 13, 1000, 10**6, 10**9, 2**31, 2**32 + 1, 2**40, big],
                   dtype=np.int64)
    return {
        "P": np.stack([special, np.roll(special, 3), noise[:, 2]], axis=1),
        "v": np.stack([noise[:, 0], special[::-1].copy(), noise[:, 1]], axis=1),
        "id": ids,
        "age": np.abs(noise[:, 0]),
        "life": np.roll(special, 5),
        "mass": np.roll(special, 7),
        # A NaN with its sign bit set, too, except in CSV, which spells every NaN "nan" (a
        # "-nan" is text most CSV readers refuse): it reads back as the quiet NaN.
        "temperature": np.where(np.isnan(special), special, -special) if fmt == "csv" else -special,
        "Cd": rng.random(n, dtype=np.float32),
    }


@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_every_bit(tmp_path, fmt):
    columns = awkward_frame(fmt)
    path = tmp_path / f"awkward.{fmt}"
    tickfx.write_cache(path, columns, frame=7, time=0.25)
    back = tickfx.read_cache(path)
    assert_same_bits(back, columns)
    # And once more through a second write.
    path2 = tmp_path / f"awkward2.{fmt.upper()}"
    tickfx.write_cache(path2, back)
    assert_same_bits(tickfx.read_cache(path2), columns)


@pytest.mark.parametrize("fmt", ["csv", "vdb"])
def test_ids_past_2_63_keep_their_bits(tmp_path, fmt):
    ids = np.array([1, 2**63 - 1], dtype=np.int64)
    columns = {"P": np.zeros((2, 3), np.float32), "id": ids}
    tickfx.write_cache(tmp_path / f"ids.{fmt}", columns)
    assert tickfx.read_cache(tmp_path / f"ids.{fmt}")["id"].tobytes() == ids.tobytes()
    # As uint64: the id 2^64 - 1 reads back as int64 -1.
    tickfx.write_cache(tmp_path / f"u.{fmt}",
                       {"P": np.zeros((1, 3), np.float32),
                        "id": np.array([2**64 - 1], dtype=np.uint64)})
    assert tickfx.read_cache(tmp_path / f"u.{fmt}")["id"].tolist() == [-1]


@pytest.mark.parametrize("fmt", FORMATS)
def test_missing_columns_take_their_defaults(tmp_path, fmt):
    P = np.arange(12, dtype=np.float32).reshape(4, 3)
    tickfx.write_cache(tmp_path / f"min.{fmt}", {"P": P, "id": np.arange(4, dtype=np.uint32)})
    back = tickfx.read_cache(tmp_path / f"min.{fmt}")
    assert back["P"].tobytes() == P.tobytes()
    assert back["id"].tolist() == [0, 1, 2, 3]
    assert np.array_equal(back["v"], np.zeros((4, 3), np.float32))
    assert np.array_equal(back["age"], np.zeros(4, np.float32))
    assert np.array_equal(back["life"], np.full(4, np.inf, np.float32))
    assert np.array_equal(back["mass"], np.ones(4, np.float32))


def test_empty_frame(tmp_path):
    for fmt in FORMATS:
        tickfx.write_cache(tmp_path / f"empty.{fmt}",
                           {"P": np.zeros((0, 3), np.float32), "id": np.zeros(0, np.int64)})
        back = tickfx.read_cache(tmp_path / f"empty.{fmt}")
        assert back["P"].shape == (0, 3) and back["id"].shape == (0,)


def test_write_cache_validates(tmp_path):
    P = np.zeros((3, 3), np.float32)
    ids = np.arange(3)
    good = {"P": P, "id": ids}
    cases = [
        ({"P": P.astype(np.float64), "id": ids}, "float64, which does not convert to float32"),
        ({"P": P[:, :2], "id": ids}, r"'P' must have shape \(N, 3\)"),
        ({"P": P, "id": ids.astype(np.float32)}, "'id' must be an integer array"),
        ({"P": P, "id": ids[:2]}, r"'id' must have shape \(3,\)"),
        ({"P": P}, "columns need 'id'"),
        ({"id": ids}, "columns need 'P'"),
        ({**good, "v": np.zeros((3,), np.float32)}, r"'v' must have shape \(3, 3\)"),
        ({**good, "mass": np.ones(4, np.float32)}, r"'mass' must have shape \(3,\)"),
        ({**good, "heat": [1.0, 2.0, 3.0]}, "'heat' is float64"),
        ({**good, "heat": np.array([1, 2, 2**24 + 1], np.int32)}, "'heat' has integers past 2"),
        ({**good, "hitpos": np.zeros((3, 2), np.float32)}, r"'hitpos' must have shape \(3, 3\)"),
    ]
    for columns, message in cases:
        with pytest.raises(ValueError, match=message):
            tickfx.write_cache(tmp_path / "x.csv", columns)
    # Exact conversions are fine: float16 and small integers are float32 exactly.
    tickfx.write_cache(tmp_path / "ok.csv", {**good, "heat": np.ones(3, np.int16),
                                             "age": np.full(3, 0.5, np.float16)})
    assert tickfx.read_cache(tmp_path / "ok.csv")["heat"].dtype == np.float32
    with pytest.raises(ValueError, match="expected .csv, .ply, .vdb or .usda"):
        tickfx.write_cache(tmp_path / "x.bgeo", good)
    with pytest.raises(ValueError, match="no commas"):
        tickfx.write_cache(tmp_path / "x.csv", {**good, "a,b": np.zeros(3, np.float32)})
    with pytest.raises(ValueError, match="no spaces"):
        tickfx.write_cache(tmp_path / "x.ply", {**good, "a b": np.zeros(3, np.float32)})
    with pytest.raises(ValueError, match="not a valid OpenVDB attribute name"):
        tickfx.write_cache(tmp_path / "x.vdb", {**good, "a b": np.zeros(3, np.float32)})
    with pytest.raises(ValueError, match="past 2\\^53"):
        tickfx.write_cache(tmp_path / "x.ply", {"P": P, "id": np.array([0, 1, 2**53 + 2])})
    with pytest.raises(TypeError):
        tickfx.write_cache(tmp_path / "x.csv", [P, ids])
    assert not any(tmp_path.glob("x.*"))  # nothing half-written


def test_unreadable_caches_raise_cache_error(tmp_path, cli_frames):
    out, _ = cli_frames
    with pytest.raises(ValueError, match="expected .csv, .ply, .vdb or .usda"):
        tickfx.read_cache(tmp_path / "frame.bgeo")
    for fmt in FORMATS:
        missing = tmp_path / f"missing.{fmt}"
        with pytest.raises(tickfx.CacheError, match="missing"):
            tickfx.read_cache(missing)
        whole = (out / f"frame_0036.{fmt}").read_bytes()
        cut = tmp_path / f"cut.{fmt}"
        cut.write_bytes(whole[: len(whole) // 2])
        with pytest.raises(tickfx.CacheError, match="cut"):
            tickfx.read_cache(cut)
        junk = tmp_path / f"junk.{fmt}"
        junk.write_bytes(b"\x00\x01garbage\xff" * 100)
        with pytest.raises(tickfx.CacheError, match="junk"):
            tickfx.read_cache(junk)
    assert issubclass(tickfx.CacheError, OSError)
    with pytest.raises(tickfx.CacheError):
        tickfx.write_cache(tmp_path / "no" / "such" / "dir.csv",
                           {"P": np.zeros((1, 3), np.float32), "id": np.zeros(1, np.int64)})


def test_cache_info_gives_what_each_format_records(cli_frames, tmp_path):
    out, system = cli_frames
    vdb = tickfx.cache_info(out / "frame_0036.vdb")
    assert vdb["frame"] == 36 and vdb["time"] == 1.5 and vdb["points"] == system.count
    assert len(vdb["effect_hash"]) == 16 and vdb["seed"] == 7 and vdb["step_rate"] == 120
    assert vdb["integrator"] == "semi_implicit_euler" and vdb["version"] == tickfx.__version__
    ply = tickfx.cache_info(out / "frame_0036.ply")
    assert (ply["frame"], ply["time"], ply["points"]) == (36, 1.5, system.count)
    assert ply["effect_hash"] is None and ply["seed"] is None
    csv = tickfx.cache_info(out / "frame_0036.csv")
    assert csv["frame"] is None and csv["time"] is None and csv["points"] == system.count
    cut = tmp_path / "cut.vdb"
    cut.write_bytes((out / "frame_0036.vdb").read_bytes()[:300])
    with pytest.raises(tickfx.CacheError, match="cut.vdb"):
        tickfx.cache_info(cut)
    with pytest.raises(ValueError, match="usda_frames"):
        tickfx.cache_info(tmp_path / "run.usda")


def test_frames_between_ticks_are_the_cli_caches(cli, samples, tmp_path):
    """The fountain ticks at 120 Hz; at 50 fps four frames in five fall between two ticks and show
    interpolated positions, velocities and ages. Each frame Python captures equals the CLI's
    cache of it, bit for bit (the frames compared above all fall on ticks)."""
    out = tmp_path / "cli"
    run_cli(cli, "run", samples / "fountain.toml", "--fps", "50", "--frames", "25",
            "--format", "csv", "--out", out, "--quiet")
    system = tickfx.load_effect(samples / "fountain.toml")
    between = 0
    for number in range(1, 26):
        system.advance(Fraction(1, 50))
        if system.alpha < 1:
            between += 1
        assert_same_bits(tickfx.read_cache(out / f"frame_{number:04d}.csv"), system.capture())
    assert between == 20
    assert system.count > 100


def test_a_usda_layer_reads_frame_by_frame_as_the_vdb_caches(cli, samples, tmp_path):
    # `tickfx run --format usda` writes one layer a run; read_cache(path, frame=N) gives frame N
    # with the bits of the same run's VDB cache, and usda_frames() lists the time codes.
    run_cli(cli, "run", samples / "fireworks.toml", "--frames", "3", "--fps", "1",
            "--format", "vdb,usda", "--out", tmp_path, "--quiet")
    layer = tmp_path / "fireworks.usda"
    assert tickfx.usda_frames(layer) == [1, 2, 3]
    for f in (1, 2, 3):
        assert_same_bits(tickfx.read_cache(layer, frame=f),
                         tickfx.read_cache(tmp_path / f"frame_000{f}.vdb"))
    assert_same_bits(tickfx.read_cache(layer), tickfx.read_cache(tmp_path / "frame_0001.vdb"))
    with pytest.raises(ValueError, match="frame= picks a frame of a .usda layer"):
        tickfx.read_cache(tmp_path / "frame_0001.vdb", frame=1)
    with pytest.raises(tickfx.CacheError, match="has no ids at frame 9"):
        tickfx.read_cache(layer, frame=9)
