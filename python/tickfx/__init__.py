"""tickfx: deterministic fixed-step particle effects, from Python.

    import tickfx

    system = tickfx.load_effect("samples/fountain.toml")
    frame = 1 / system.output_fps               # one frame, a fractions.Fraction of a second
    for f in range(1, system.output_frames + 1):
        system.advance(frame)
        P = system.interpolated_positions()     # (count, 3) float32, metres, at system.time
    print(system.state_hash())                  # what `tickfx run --hash` prints

Units everywhere: metres, seconds, kilograms; velocities in metres per second, rates per second
(Hz). A system driven through the same frames, or the same ticks, reaches the same state bits as
`tickfx run`, whatever the frame durations and the thread count.
"""

import numbers
import os
import re
from collections import namedtuple
from collections.abc import Mapping
from fractions import Fraction

import numpy as np

from . import _tickfx
from ._tickfx import FLICKS_PER_SECOND, CacheError, NonfiniteEvent, System, __version__

__all__ = [
    "AdvanceResult",
    "CacheError",
    "cache_info",
    "EffectError",
    "FLICKS_PER_SECOND",
    "NonfiniteEvent",
    "System",
    "check",
    "load_effect",
    "read_cache",
    "usda_frames",
    "write_cache",
]

CacheError.__doc__ = (
    "A cache file that could not be read or written (missing, truncated, malformed, or an "
    "unwritable folder); str() is tickfx's message, naming the file."
)


class EffectError(ValueError):
    """An effect file (or an override) with errors: nothing was built.

    str() is every diagnostic, one a line, exactly as `tickfx check` prints them:
    ``FILE:LINE:COL: error: key.path: what is wrong (what is expected)`` (an override's finding
    names ``--set key.path`` in place of FILE:LINE:COL). ``diagnostics`` is the list of those lines.
    """

    def __init__(self, diagnostics):
        self.diagnostics = [str(line) for line in diagnostics]
        super().__init__("\n".join(self.diagnostics) or "the effect could not be loaded")

    def __reduce__(self):
        return (type(self), (self.diagnostics,))


AdvanceResult = namedtuple("AdvanceResult", ["ticks", "dropped"])
AdvanceResult.__doc__ = """What one System.advance() did.

ticks: ticks run by this call (each 1/step_rate seconds).
dropped: whole ticks the real-time cap (simulation.max_ticks_per_frame, overrun = "drop")
    discarded in this call; always 0 for a system loaded with offline=True.
"""

_MAX_THREADS = 1024  # io::kMaxThreads, simulation.threads' range
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _toml_string(text):
    escaped = []
    for ch in text:
        if ch == '"':
            escaped.append('\\"')
        elif ch == "\\":
            escaped.append("\\\\")
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            escaped.append("\\u%04x" % ord(ch))
        else:
            escaped.append(ch)
    return '"' + "".join(escaped) + '"'


def _toml_value(value, nested):
    # bool before Integral: True is an int to Python, a boolean to TOML.
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        # repr() of a float reads back to the same double, and TOML reads 'inf' and 'nan' too.
        return repr(float(value))
    if isinstance(value, str):
        # At the top a str is TOML text as `--set` takes it ('rk4', '[0, 1, 0]'); inside a list
        # or table it can only be meant as a string.
        return _toml_string(value) if nested else value
    if isinstance(value, np.ndarray):
        return _toml_value(value.tolist(), nested)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v, True) for v in value) + "]"
    if isinstance(value, Mapping):
        items = []
        for key, v in value.items():
            if not isinstance(key, str):
                raise TypeError(f"override table keys must be str, not {type(key).__name__}")
            name = key if _BARE_KEY.fullmatch(key) else _toml_string(key)
            items.append(f"{name} = {_toml_value(v, True)}")
        return "{" + ", ".join(items) + "}"
    raise TypeError(f"cannot write a {type(value).__name__} as a TOML value: {value!r}")


def _override_pairs(overrides):
    if overrides is None:
        return []
    if not isinstance(overrides, Mapping):
        raise TypeError("overrides must be a dict {key path: value}")
    pairs = []
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise TypeError(f"override keys are key paths (str), not {type(key).__name__}")
        pairs.append((key, _toml_value(value, False)))
    return pairs


def _path_text(path):
    return os.fsdecode(os.fspath(path))


def load_effect(path, overrides=None, *, threads=None, offline=True):
    """Loads the effect file at `path` and builds its System, ready to advance from t = 0 s.

    overrides: None or a dict {key path: value}, applied in order before validation, as
        `tickfx run --set KEY=VALUE` applies them. Key paths join keys and entry numbers (from 0)
        with dots: "simulation.step_rate", "emitters.0.rate", "forces.1.k". Values: bool, int,
        float (written exactly), list or tuple (as a TOML array), dict (an inline table), or a
        str taken as TOML text exactly as --set takes it ("rk4" -- a single word needs no
        quotes --, "[0, 1, 0]", '"two words"'); strings inside lists and dicts are quoted for you.
    threads: worker threads in place of simulation.threads (0: all cores; None: the effect's).
    offline: True (the default; a cache bake, a farm job) lifts simulation.max_ticks_per_frame,
        so advance() runs every tick a frame covers and never drops one, as `tickfx run` does.
        A real-time host (a viewport, a game loop) passes offline=False: one advance() then runs
        at most max_ticks_per_frame ticks, and AdvanceResult.dropped reports what the cap dropped.

    Vector-field files and point files the effect names (relative to the effect file) are read
    now. Raises EffectError, listing every error at once, when the file, an override or a file it
    needs is wrong; the System's state then matches `tickfx run` of the same file and overrides
    tick for tick.
    """
    path = _path_text(path)
    pairs = _override_pairs(overrides)
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
            raise TypeError("threads must be an int or None")
        if not 0 <= threads <= _MAX_THREADS:
            raise ValueError(f"threads must be in [0, {_MAX_THREADS}] (0: all cores)")
        threads = int(threads)
    system, diagnostics = _tickfx._load_effect(path, pairs, threads, bool(offline))
    if system is None:
        raise EffectError(diagnostics)
    return system


def check(path, overrides=None):
    """`tickfx check` as a call: validates the effect at `path` (with `overrides`, as for
    load_effect()) and runs its lint. Returns the lint warnings, one line each as `tickfx check`
    prints them (``FILE:LINE:COL: warning: key.path: message``), an empty list for none. Raises
    EffectError when the effect has errors. Nothing is simulated.
    """
    lines = _tickfx._check(_path_text(path), _override_pairs(overrides))
    if any(is_error for is_error, _ in lines):
        raise EffectError([line for _, line in lines])
    return [line for _, line in lines]


def _duration_flicks(duration):
    if isinstance(duration, (bool, np.bool_)):
        raise TypeError("a duration is a number of seconds, not a bool")
    if isinstance(duration, numbers.Rational):
        # Exact input (Fraction, int): it must be a whole number of flicks, never rounded behind
        # the caller's back.
        seconds = Fraction(duration.numerator, duration.denominator)
        flicks = seconds * FLICKS_PER_SECOND
        if flicks.denominator != 1:
            nearest = round(flicks)
            raise ValueError(
                f"advance: {seconds} s is not a whole number of flicks (1/{FLICKS_PER_SECOND} s);"
                f" the nearest is {nearest} flicks = {Fraction(nearest, FLICKS_PER_SECOND)} s"
            )
        flicks = flicks.numerator
    elif isinstance(duration, numbers.Real):
        value = float(duration)
        if value != value or value in (float("inf"), float("-inf")):
            raise ValueError(f"advance: a duration must be finite, not {value}")
        # The float's exact value, rounded once to the nearest flick (ties to even).
        flicks = round(Fraction(value) * FLICKS_PER_SECOND)
    else:
        raise TypeError(
            f"advance: a duration is seconds as a Fraction, int or float, not {type(duration).__name__}"
        )
    if flicks < 0:
        raise ValueError(f"advance: a duration must be >= 0 s, not {duration}")
    if flicks > 2**63 - 1:
        raise ValueError(f"advance: {duration} s is too long for one frame")
    return flicks


def _advance(self, duration):
    """Advances the frame clock by `duration` seconds and runs the ticks that brings due; the
    copies (interpolated_positions(), capture()) then show the state at the new `time`.

    duration: seconds, as a fractions.Fraction (exact: it must be a whole number of flicks,
        1/705600000 s -- 1/24, 1/25, 1/30, 1/60, 1001/30000 s all are -- else ValueError naming
        the nearest), an int, or a float (its exact value rounded to the nearest flick). Pass
        1 / system.output_fps for one output frame.

    Returns AdvanceResult(ticks, dropped): the ticks run, and the ticks the real-time cap
    discarded. A system loaded with offline=True (the default) never drops a tick; with
    offline=False at most simulation.max_ticks_per_frame ticks run per call and `dropped` says
    what was lost (overrun = "drop"), or later calls catch up (overrun = "fall_behind").
    """
    ticks, dropped = self._advance_flicks(_duration_flicks(duration))
    return AdvanceResult(ticks, dropped)


_advance.__name__ = "advance"
_advance.__qualname__ = "System.advance"
System.advance = _advance


def read_cache(path, frame=None):
    """Reads one frame cache written by `tickfx run` or write_cache(): .csv, .ply or .vdb (by the
    file name's extension; ValueError for any other), or frame `frame` of a run's .usda layer
    (`tickfx run --format usda`; its first frame when `frame` is None; usda_frames() lists them).

    Returns a dict of new numpy arrays keyed by Houdini's attribute names, rows in id order:
        "P": positions, metres, (N, 3) float32
        "v": velocities, metres per second, (N, 3) float32
        "id": particle ids, int64 (the ids' 64 bits: ids of 2^63 and more read as negative)
        "age", "life": seconds, float32 (life is inf for particles that never die)
        "mass": kilograms, float32 (inf: pinned)
    and one float32 array per custom attribute, by its name. A .vdb without some of these reads
    v and age as 0, life as inf, mass as 1, and ids as the row numbers. Raises CacheError (an
    OSError) with tickfx's message, naming the file, when it is missing, truncated or malformed.
    """
    return _tickfx._read_cache(_path_text(path), frame)


def cache_info(path):
    """What one frame cache (.csv, .ply or .vdb) records besides its rows, as a dict:
        "frame": the frame number, "time": its time in seconds (None for CSV, which records
            neither; a .vdb of another tool without them reads 0),
        "points": the row count,
        "effect_hash", "seed", "step_rate" (ticks per second), "integrator", "version": the run
            that wrote a .vdb (None for PLY and CSV, and for a .vdb tickfx did not write).
    The file is read whole, so a truncated or malformed file raises CacheError as read_cache does.
    """
    return _tickfx._cache_info(_path_text(path))


def usda_frames(path):
    """The frames (time codes) of a .usda layer written by `tickfx run --format usda`, rising."""
    return _tickfx._usda_frames(_path_text(path))


_STANDARD_COLUMNS = ("P", "v", "id", "age", "life", "mass")


def _float32_column(name, value, rows):
    array = np.asarray(value)
    if array.dtype != np.float32:
        if not np.can_cast(array.dtype, np.float32, casting="safe"):
            raise ValueError(
                f"write_cache: '{name}' is {array.dtype}, which does not convert to float32 "
                f"exactly (caches store float32): pass {name}.astype(numpy.float32) if rounding "
                f"is meant"
            )
        array = array.astype(np.float32)
    expected = (rows, 3) if name in ("P", "v") or array.ndim == 2 else (rows,)
    if rows is None:
        if array.ndim != 2 or array.shape[1] != 3:
            raise ValueError(f"write_cache: 'P' must have shape (N, 3), not {array.shape}")
    elif array.shape != expected:
        raise ValueError(f"write_cache: '{name}' must have shape {expected}, not {array.shape}")
    return np.ascontiguousarray(array)


def write_cache(path, columns, *, frame=0, time=0.0, system=None):
    """Writes one frame cache at `path`, as .csv, .ply or .vdb by its extension (ValueError for
    any other), atomically: a failure leaves no file and an existing one untouched.

    columns: a dict as read_cache() returns it (or System.capture()). Required: "P", positions in
        metres, (N, 3), and "id", any integer dtype (stored modulo 2^64, so the int64 ids of
        read_cache() come back as they were). Optional, with what a missing one is written as:
        "v" metres per second, (N, 3) (0); "age" seconds (0); "life" seconds (inf: never dies);
        "mass" kilograms (1). Every other key is a custom attribute: float of shape (N,), a
        vector of shape (N, 3) (stored as three columns, a vec3 in .vdb), or whole numbers of an
        integer dtype up to 2^24 (hitnum: an int in .ply and .vdb, read back as int32). Float
        columns must be float32 or convert to it exactly (float64 is refused: call
        .astype(numpy.float32) to round on purpose).
    frame, time: the frame number and its time in seconds, recorded in the file's metadata
        (PLY comments, VDB grid metadata), not in the rows.
    system: the System the frame came from, or None; a .vdb then records its effect hash, seed,
        step rate and integrator, as `tickfx run` does.

    Reading the file back with read_cache() gives every value's bits back when rows are in
    increasing id order (a .vdb reads back sorted by id), except: a .ply stores ids as doubles,
    so ids past 2^53 are refused; a .csv keeps a NaN's sign but not its payload. Custom attribute
    names must suit the format (.csv: no commas or line breaks; .ply: no spaces; .vdb: letters,
    digits, '_', '|', ':'). Raises CacheError when the file cannot be written.
    """
    path = _path_text(path)
    if not isinstance(columns, Mapping):
        raise TypeError("write_cache: columns must be a dict {attribute name: array}")
    for key in columns:
        if not isinstance(key, str):
            raise TypeError(f"write_cache: column names are str, not {type(key).__name__}")
    missing = [key for key in ("P", "id") if key not in columns]
    if missing:
        raise ValueError(f"write_cache: columns need {' and '.join(repr(k) for k in missing)}")
    positions = _float32_column("P", columns["P"], None)
    rows = positions.shape[0]
    ids = np.asarray(columns["id"])
    if ids.dtype.kind not in "iu":
        raise ValueError(f"write_cache: 'id' must be an integer array, not {ids.dtype}")
    if ids.shape != (rows,):
        raise ValueError(f"write_cache: 'id' must have shape {(rows,)}, not {ids.shape}")
    ids = np.ascontiguousarray(ids.astype(np.uint64))

    def optional(name, default):
        if name in columns:
            return _float32_column(name, columns[name], rows)
        shape = (rows, 3) if name == "v" else (rows,)
        return np.full(shape, default, dtype=np.float32)

    velocities = optional("v", 0.0)
    age = optional("age", 0.0)
    life = optional("life", np.inf)
    mass = optional("mass", 1.0)
    names, attributes = [], []
    for key in columns:
        if key in _STANDARD_COLUMNS:
            continue
        value = np.asarray(columns[key])
        if value.dtype.kind in "iu":
            # An integer attribute (Houdini's hitnum): whole numbers a float32 holds exactly.
            if value.size and np.abs(value.astype(np.int64)).max() > 2**24:
                raise ValueError(f"write_cache: '{key}' has integers past 2^24, which a cache "
                                 f"column (float32) does not hold exactly")
            value = value.astype(np.float32)
        array = _float32_column(key, value, rows)
        if array.ndim == 2:
            # A vector attribute (Houdini's hitpos, Cd): three columns of the frame.
            for c, column in enumerate(_tickfx._vector_columns(key)):
                names.append(column)
                attributes.append(np.ascontiguousarray(array[:, c]))
        else:
            names.append(key)
            attributes.append(array)
    if isinstance(frame, bool) or not isinstance(frame, numbers.Integral):
        raise TypeError("write_cache: frame must be an int")
    metadata = _tickfx._vdb_metadata(system) if system is not None else None
    _tickfx._write_cache(
        path, ids, positions, velocities, age, life, mass, names, attributes, int(frame),
        float(time), metadata,
    )
