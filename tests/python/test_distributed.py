# tickfx.distributed on a local Dask cluster of two worker processes: the merged shards give the
# unsharded run's state hash and cache bytes, a worker killed mid-shard changes nothing, and an
# effect that cannot be sharded is refused with the CLI's message.
import os
import pickle
import signal
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

if os.environ.get("TICKFX_SANITIZE") == "1":
    # Worker processes are started afresh by the cluster's nannies without the ASan preload
    # that the interpreter needs to import the sanitized module.
    pytest.skip("tickfx.distributed's workers do not carry the ASan preload",
                allow_module_level=True)

import tickfx.distributed  # noqa: E402
from conftest import cli_hash, run_cli  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      local_directory=str(tmp_path_factory.mktemp("dask"))) as cluster, \
            Client(cluster) as client:
        yield client


def test_shard_commands_are_the_cli_lines():
    commands = tickfx.distributed.shard_commands(
        "fx/fountain.toml", 3, "out/f", args=("--frames", 24, "--format", "vdb"),
        overrides={"emitters.0.rate": 500, "simulation.integrator": "rk4"}, cli="/opt/tickfx")
    tail = ["--quiet", "--hash", "--frames", "24", "--format", "vdb",
            "--set", "emitters.0.rate=500", "--set", "simulation.integrator=rk4"]
    assert commands == [
        ["/opt/tickfx", "run", "fx/fountain.toml", "--shard", "0/3", "--out", "out/f/shard_0_of_3",
         *tail],
        ["/opt/tickfx", "run", "fx/fountain.toml", "--shard", "1/3", "--out", "out/f/shard_1_of_3",
         *tail],
        ["/opt/tickfx", "run", "fx/fountain.toml", "--shard", "2/3", "--out", "out/f/shard_2_of_3",
         *tail],
        ["/opt/tickfx", "merge", "out/f/shard_0_of_3", "out/f/shard_1_of_3", "out/f/shard_2_of_3",
         "--out", "out/f", "--hash", "--quiet"],
    ]
    assert tickfx.distributed.shard_commands("e.toml", 1, "o", cli="tickfx") == [
        ["tickfx", "run", "e.toml", "--shard", "0/1", "--out", "o/shard_0_of_1", "--quiet",
         "--hash"],
        ["tickfx", "merge", "o/shard_0_of_1", "--out", "o", "--hash", "--quiet"],
    ]
    with pytest.raises(ValueError):
        tickfx.distributed.shard_commands("e.toml", 0, "o")


def test_errors_carry_the_cli_message_across_processes():
    refused = tickfx.distributed.ShardError(["tickfx", "run", "e.toml"], 2,
                                            "e.toml: error: cannot shard: x\n")
    failed = tickfx.distributed.CommandError(["tickfx", "merge"], -9, "")
    assert isinstance(refused, ValueError) and not isinstance(failed, ValueError)
    assert str(refused) == "e.toml: error: cannot shard: x"
    assert str(failed) == "tickfx merge was killed by signal 9 and printed nothing"
    for error in (refused, failed):
        copy = pickle.loads(pickle.dumps(error))
        assert type(copy) is type(error) and str(copy) == str(error)
        assert (copy.argv, copy.returncode, copy.stderr) == (error.argv, error.returncode,
                                                             error.stderr)


def test_merged_shards_are_the_unsharded_run(cli, samples, client, tmp_path):
    effect = samples / "fountain.toml"
    seen = []
    result = tickfx.distributed.run(
        effect, 3, client, tmp_path / "sharded", args=("--frames", "24", "--format", "vdb"),
        cli=cli, progress=lambda done, total, summary: seen.append((done, total, summary)))
    assert (result["state_hash"], result["ticks"]) == cli_hash(cli, effect, "--frames", "24")
    assert result["out"] == str(tmp_path / "sharded")
    assert [s["shard"] for s in result["shards"]] == [0, 1, 2]
    for s in result["shards"]:
        assert s["folder"] == str(tmp_path / "sharded" / f"shard_{s['shard']}_of_3")
        assert s["seconds"] > 0 and s["peak_rss"] > 1 << 20
    assert result["merge_seconds"] > 0
    assert [(done, total) for done, total, _ in seen] == [(1, 3), (2, 3), (3, 3)]
    assert sorted(s["shard"] for _, _, s in seen) == [0, 1, 2]

    whole = tmp_path / "whole"
    run_cli(cli, "run", effect, "--frames", "24", "--format", "vdb", "--out", whole, "--quiet")
    expected = sorted(p.name for p in whole.iterdir())
    assert expected == [f"frame_{f:04d}.vdb" for f in range(1, 25)]
    merged = tmp_path / "sharded"
    assert sorted(p.name for p in merged.glob("frame_*")) == expected
    for name in expected:
        assert (merged / name).read_bytes() == (whole / name).read_bytes(), name


def test_an_effect_that_cannot_be_sharded_is_refused(cli, samples, client, tmp_path):
    with pytest.raises(tickfx.distributed.ShardError) as refused:
        tickfx.distributed.run(samples / "fireworks.toml", 2, client, tmp_path,
                               args=("--frames", "4"), cli=cli)
    assert isinstance(refused.value, ValueError)
    assert refused.value.returncode == 2
    assert "cannot shard" in str(refused.value)
    assert not (tmp_path / "frame_0001.vdb").exists()  # no merge


def _children(pid):
    """{pid: (state, argv)} of the processes whose parent is `pid` (Linux /proc)."""
    found = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
            with open(f"/proc/{entry}/cmdline", "rb") as cmdline:
                argv = [a.decode() for a in cmdline.read().split(b"\0") if a]
        except OSError:
            continue
        if int(fields[1]) == pid:
            found[int(entry)] = (fields[0], argv)
    return found


def _state(pid):
    """The process's state letter (R, S, T: stopped, Z: ended, not yet reaped), None when gone."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return None


def _gone(pid):
    return _state(pid) in (None, "Z", "X")


def _wait_for(condition, seconds):
    deadline = time.monotonic() + seconds
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.01)
    return condition()


def _running_shard(client, out, shards):
    """(worker pid, shard index, CLI pid) of a shard whose CLI is running and has written its first
    frame, or None."""
    pids = client.run(os.getpid)
    for worker, keys in client.processing().items():
        for key in keys:
            key = str(key)
            if not key.startswith("tickfx-shard-"):
                continue
            index = int(key.split("-")[2])
            folder = out / f"shard_{index}_of_{shards}"
            if not (folder / "frame_0001.vdb").exists():
                continue
            for child, (state, argv) in _children(pids[worker]).items():
                if state not in ("Z", "X") and "--shard" in argv \
                        and argv[argv.index("--shard") + 1] == f"{index}/{shards}":
                    return pids[worker], index, child
    return None


def test_a_worker_killed_mid_shard_changes_nothing(cli, samples, client, tmp_path):
    effect = samples / "fountain.toml"
    # Long enough to be caught running (20 s of frames), small enough to write little (200
    # drops a second: about 20 MB of VDB caches).
    args = ("--frames", "480", "--format", "vdb", "--set", "emitters.0.rate=200")
    out = tmp_path / "sharded"
    done = threading.Event()
    with ThreadPoolExecutor(1) as pool:
        running = pool.submit(tickfx.distributed.run, effect, 2, client, out, args=args, cli=cli)
        running.add_done_callback(lambda _: done.set())
        victim = None
        deadline = time.monotonic() + 30
        while victim is None and not done.is_set() and time.monotonic() < deadline:
            victim = _running_shard(client, out, 2)
            if victim is None:
                time.sleep(0.01)
                continue
            # Stopped, the CLI cannot finish before its worker dies, and only the worker's death
            # (PR_SET_PDEATHSIG: SIGKILL, which ends a stopped process too) can end it.
            try:
                os.kill(victim[2], signal.SIGSTOP)
            except ProcessLookupError:
                pass
            if not _wait_for(lambda: _state(victim[2]) in ("T", "Z", "X", None), 5) \
                    or _gone(victim[2]):
                victim = None  # it ended first: find another
        if victim is None and done.is_set():
            running.result()  # the run's own error, if it failed
        assert victim is not None, "no shard was seen running (too short a run?)"
        worker, index, child = victim
        os.kill(worker, signal.SIGKILL)
        died = _wait_for(lambda: _gone(child), 10)
        if not died:
            os.kill(child, signal.SIGKILL)  # not to leave it stopped
        assert died, f"the CLI of shard {index} outlived its worker"
        result = running.result(timeout=120)
    assert (result["state_hash"], result["ticks"]) == cli_hash(cli, effect, *args[:2], *args[4:])
    assert [s["shard"] for s in result["shards"]] == [0, 1]
    assert worker not in client.run(os.getpid).values()
