"""A big run in shards on a local Dask cluster against the same run in one process.

    /usr/bin/python3 bench/shards.py TICKFX_CLI WORK_DIR [--particles N] [--shards S]
        [--workers W] [--frames F]

The effect: N particles in one burst at t = 0, in a 100 m box, under gravity and drag, ticked
at 120 Hz, F frames at 24 fps cached as VDB points. First the whole run in one process (all
cores), then S shards on a LocalCluster of W single-threaded worker processes (each shard's CLI
on one thread: W at a time on W cores), then their merge. Prints the wall times, the peak
resident memory of the single run and of each shard (Linux's ru_maxrss of the process), the
merge's time and peak, and checks that the merged state hash and caches are the single run's.
Not a test: figures for docs/sharding.md and the README, run by hand (WORK_DIR needs about
90 bytes a particle a frame for the caches, and twice that again for the final states).
"""
import argparse
import filecmp
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

EFFECT = """format_version = 1
[simulation]
step_rate = 120
integrator = "semi_implicit_euler"
seed = 3
max_particles = {n}
threads = 0

[[emitters]]
name = "dust"
shape = "box"
size = [100.0, 100.0, 100.0]
bursts = [{{ time = 0.0, count = {n} }}]
speed = 1.0
spread = 180.0

[[forces]]
type = "gravity"

[[forces]]
type = "drag"
k = 0.5
"""


def timed(argv):
    """(wall seconds, peak RSS bytes, stdout) of a command run to completion."""
    start = time.monotonic()
    child = subprocess.Popen(argv, stdout=subprocess.PIPE, text=True)
    out = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        sys.exit(f"{' '.join(map(str, argv))} exited {child.returncode}")
    return time.monotonic() - start, usage.ru_maxrss * 1024, out


def hash_of(out):
    return next(line for line in out.splitlines() if line.startswith("state-hash: "))[12:]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("cli")
    parser.add_argument("work", type=Path)
    parser.add_argument("--particles", type=int, default=100_000_000)
    parser.add_argument("--shards", type=int, default=4)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--frames", type=int, default=1)
    a = parser.parse_args()
    shutil.rmtree(a.work, ignore_errors=True)
    a.work.mkdir(parents=True)
    effect = a.work / "dust.toml"
    effect.write_text(EFFECT.format(n=a.particles))
    run_args = ["--frames", str(a.frames), "--fps", "24", "--format", "vdb"]
    gib = 1 << 30

    seconds, peak, out = timed([a.cli, "run", effect, *run_args, "--out", a.work / "whole",
                                "--hash", "--quiet"])
    whole_hash = hash_of(out)
    print(f"one process: {seconds:.1f} s, peak {peak / gib:.2f} GiB, state-hash {whole_hash}")

    from distributed import Client, LocalCluster

    sys.path.insert(0, str(Path(a.cli).resolve().parent.parent / "python"))
    import tickfx.distributed

    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        start = time.monotonic()
        result = tickfx.distributed.run(effect, a.shards, client, a.work / "sharded",
                                        args=(*run_args, "--threads", "1"), cli=a.cli)
        seconds = time.monotonic() - start
    print(f"{a.shards} shards on {a.workers} workers: {seconds:.1f} s in all, merge "
          f"{result['merge_seconds']:.1f} s, state-hash {result['state_hash']}")
    for s in result["shards"]:
        print(f"  shard {s['shard']}: {s['seconds']:.1f} s, peak {s['peak_rss'] / gib:.2f} GiB")
    merge_seconds, merge_peak, _ = timed(
        [a.cli, "merge", *(s["folder"] for s in result["shards"]), "--out", a.work / "merged",
         "--quiet"])
    print(f"merge alone: {merge_seconds:.1f} s, peak {merge_peak / gib:.2f} GiB")
    assert result["state_hash"] == whole_hash, "the merged hash is not the single run's"
    for frame in range(1, a.frames + 1):
        name = f"frame_{frame:04d}.vdb"
        assert filecmp.cmp(a.work / "whole" / name, a.work / "sharded" / name, shallow=False), name
    print("merged caches and hash equal the single run's")


if __name__ == "__main__":
    main()
