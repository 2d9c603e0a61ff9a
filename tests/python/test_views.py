# Zero-copy views of the pool: they alias its memory, refuse writes, keep their System alive, and
# stay valid however the pool grows (the first view reserves max_particles rows).
#
# Under the sanitizer build (TICKFX_SANITIZE=1, ASan preloaded) every read of an old view goes
# through memcpy (tobytes(), np.array(copy)), which ASan intercepts: a view left pointing at freed
# storage would be a heap-use-after-free report, not a silently wrong number.
import gc
import os
import weakref

import numpy as np
import pytest
import tickfx

INITIAL_STORAGE_ROWS = 1024  # ParticlePool's first growth; the fountain passes it after 0.5 s


def address(array):
    return array.__array_interface__["data"][0]


@pytest.fixture
def fountain(samples):
    system = tickfx.load_effect(samples / "fountain.toml")
    system.step(30)  # 0.25 s at 2000 particles/s
    assert 400 < system.count < INITIAL_STORAGE_ROWS
    return system


def test_sanitizer_is_active_when_asked():
    if os.environ.get("TICKFX_SANITIZE") != "1":
        pytest.skip("not the sanitizer build")
    with open("/proc/self/maps") as maps:
        mapped = maps.read()
    # g++'s runtime or clang's (scripts/test builds the sanitizer pass with clang).
    assert "libasan" in mapped or "libclang_rt.asan" in mapped


def test_views_alias_the_pool(fountain):
    x1, y1, z1 = fountain.positions
    x2, _, _ = fountain.positions
    n = fountain.count
    for view in (x1, y1, z1, fountain.ids, fountain.lifetimes, fountain.masses,
                 *fountain.velocities):
        assert view.shape == (n,)
        assert not view.flags.writeable
        assert view.base is fountain
    assert address(x1) == address(x2)
    assert x1.dtype == np.float32 and fountain.ids.dtype == np.uint64
    assert fountain.ages.dtype == fountain.lifetimes.dtype == fountain.masses.dtype == np.float32
    # Ages are worked out from birth ticks where they are read: a new array each time.
    ages = fountain.ages
    assert ages.shape == (n,) and ages.flags.owndata and ages is not fountain.ages
    # The same bits as the copies of the newest tick.
    newest = fountain.interpolated_positions(1.0)
    for c, view in enumerate((x1, y1, z1)):
        assert newest[:, c].tobytes() == view.tobytes()
    shown = fountain.capture()
    assert shown["id"].view(np.uint64).tobytes() == fountain.ids.tobytes()
    assert shown["mass"].tobytes() == fountain.masses.tobytes()
    assert shown["life"].tobytes() == fountain.lifetimes.tobytes()
    assert shown["age"].tobytes() == fountain.ages.tobytes()
    for c, view in enumerate(fountain.velocities):
        assert shown["v"][:, c].tobytes() == view.tobytes()
    # Real values: ids in birth order, the effect's masses, ages on the tick grid.
    ids = fountain.ids
    assert ids[0] == 0 and np.all(np.diff(ids.astype(np.int64)) > 0)
    assert np.all(fountain.masses == 1.0)
    assert np.all((fountain.lifetimes > 2.0) & (fountain.lifetimes < 3.0))  # 2.5 s ± 20 %
    assert fountain.ages.max() == np.float32(30 * (1.0 / 120))  # born in tick 0
    assert np.all(fountain.velocities[1] > 0)  # still rising after 0.25 s at 8 m/s
    # A view is a window: stepping moves the particles under it.
    height_before = y1.copy()
    fountain.step()
    assert address(fountain.positions[1]) == address(y1)
    assert not np.array_equal(height_before, y1)
    assert y1.tobytes() == fountain.positions[1][:n].tobytes()


def test_views_refuse_writes(fountain):
    x, _, _ = fountain.positions
    ids = fountain.ids
    with pytest.raises(ValueError, match="read-only"):
        x[0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        ids[:] = 0
    with pytest.raises(ValueError, match="read-only"):
        np.add(fountain.masses, 1.0, out=fountain.masses)
    with pytest.raises(ValueError):
        x.setflags(write=True)
    # Copies are the caller's.
    mine = fountain.interpolated_positions()
    mine[0, 0] = 42.0
    assert fountain.interpolated_positions()[0, 0] != 42.0


def test_unknown_attribute_is_a_key_error(fountain):
    assert fountain.attribute_names == []
    with pytest.raises(KeyError, match="temperature"):
        fountain.attribute("temperature")


def test_view_outlives_its_system(samples):
    system = tickfx.load_effect(samples / "fountain.toml")
    system.step(60)
    x, y, z = system.positions
    ids = system.ids
    expected = (x.copy(), y.copy(), z.copy(), ids.copy())
    alive = weakref.ref(system)
    del system
    gc.collect()
    assert alive() is not None  # the views hold it
    for view, copy in zip((x, y, z, ids), expected):
        assert view.tobytes() == copy.tobytes()
        assert np.array_equal(np.array(view, copy=True), copy)
    assert float(y.max()) > 1.0
    del x, y, z, ids, view
    gc.collect()
    assert alive() is None  # and nothing else does


def test_old_view_survives_pool_growth(samples):
    system = tickfx.load_effect(samples / "fountain.toml")
    system.step(10)
    old_x, old_y, old_z = system.positions
    old_ids = system.ids
    old_age = system.ages
    old_age_then = old_age.tobytes()
    rows = system.count
    assert 0 < rows < INITIAL_STORAGE_ROWS
    # Two seconds of emission: the pool passes its first storage many times over.
    system.step(240)
    assert system.count > 3 * INITIAL_STORAGE_ROWS
    x, y, z = system.positions
    assert address(x) == address(old_x)  # the storage did not move
    # The old window reads the first rows of the same memory: the state after tick 250.
    assert old_x.tobytes() == x[:rows].tobytes()
    assert old_y.tobytes() == y[:rows].tobytes()
    assert old_z.tobytes() == z[:rows].tobytes()
    assert old_ids.tobytes() == system.ids[:rows].tobytes()
    # Ages are a snapshot of their tick (worked out from birth ticks), not a window.
    assert old_age.tobytes() == old_age_then
    assert old_age.max() == np.float32(10 / 120)  # the oldest, born in tick 0
    # Reserving changed nothing of the simulation.
    unviewed = tickfx.load_effect(samples / "fountain.toml")
    unviewed.step(250)
    assert unviewed.state_hash() == system.state_hash()
    # The old views still hold the system after it is dropped.
    del system, x, y, z
    gc.collect()
    assert np.isfinite(np.array(old_x, copy=True)).all()


def test_views_at_max_particles(samples):
    system = tickfx.load_effect(samples / "fountain.toml", {"simulation.max_particles": 300})
    system.step(2)
    old = system.positions[0]
    system.step(120)  # 2000 particles/s for a second: most spawns are refused
    assert system.count == 300
    assert address(system.positions[0]) == address(old)
    assert old.tobytes() == system.positions[0][: len(old)].tobytes()


def test_reservation_past_the_machine_memory_is_refused(samples):
    rows = 10**9  # the largest max_particles an effect may ask for: 69 GB of columns
    physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    if physical >= 69 * rows:
        pytest.skip("this machine could hold the reservation")
    system = tickfx.load_effect(samples / "fountain.toml", {"simulation.max_particles": rows})
    system.step(12)
    with pytest.raises(MemoryError, match=r"max_particles = 1000000000 rows \(69\.0 GB\)"):
        system.positions
    # Nothing was reserved and the system runs on.
    system.step(12)
    assert system.count == 400
