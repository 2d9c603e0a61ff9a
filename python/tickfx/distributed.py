"""tickfx on a Dask cluster: a run split into shards, one `tickfx run --shard I/N` a task, and
their caches merged into the unsharded run's files by `tickfx merge`.

    from distributed import Client, LocalCluster
    import tickfx.distributed

    with LocalCluster(n_workers=4, threads_per_worker=1) as cluster, Client(cluster) as client:
        result = tickfx.distributed.run("samples/fountain.toml", 4, client, "/shared/fx/fountain",
                                        args=("--format", "vdb", "--threads", "4"))
    print(result["state_hash"])                 # what the unsharded `tickfx run --hash` prints

Every task runs the command line as a subprocess on its worker and writes its caches straight
into `out` on a filesystem every worker reaches (NFS, a cluster filesystem): Dask carries the
task descriptions and small summary dicts only, never particle data. Workers need this package
importable (the tasks are its functions) and the CLI at the path `cli` names. Dask is imported
when run() is called: `import tickfx.distributed` works without it, and so does shard_commands().
"""

import ctypes
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import uuid

from . import _override_pairs, _path_text

__all__ = ["CommandError", "ShardError", "run", "shard_commands", "shard_folder"]

_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


class _Failure:
    # What CommandError and ShardError share: the command, its exit status and its stderr.
    def __init__(self, argv, returncode, stderr):
        self.argv = [str(a) for a in argv]
        self.returncode = returncode
        self.stderr = stderr
        message = stderr.strip()
        if not message:
            how = (f"was killed by signal {-returncode}" if returncode < 0
                   else f"exited {returncode}")
            message = f"{' '.join(self.argv)} {how} and printed nothing"
        super().__init__(message)

    def __reduce__(self):
        # Raised on a worker, unpickled on the client.
        return (type(self), (self.argv, self.returncode, self.stderr))


class CommandError(_Failure, RuntimeError):
    """A `tickfx run --shard` or `tickfx merge` that failed while running (exit 1: an effect
    that blew up, a cache that could not be written, ...) or was killed by a signal.

    str() is the command's stderr, stripped (when it wrote nothing: the command and how it
    ended). ``argv``: the command as run, a list of str; ``returncode``: its exit status
    (negative: the signal that killed it); ``stderr``: what it wrote to stderr, whole.
    """


class ShardError(_Failure, ValueError):
    """A command the CLI refused (exit 2): an effect that cannot be split exactly
    (``EFFECT: error: cannot shard: ...``), an effect with errors, a wrong option, or shard
    folders that do not belong together (`tickfx merge`, naming the folder). Nothing was
    simulated, and running it again gives the same refusal. ``argv``, ``returncode`` (2),
    ``stderr`` and str() as for CommandError.
    """


def shard_folder(out, index, shards):
    """The folder shard `index` (0-based) of `shards` writes into: OUT/shard_I_of_N."""
    return os.path.join(_path_text(out), f"shard_{index}_of_{shards}")


def _check_shards(shards):
    if isinstance(shards, bool) or not isinstance(shards, int):
        raise TypeError(f"shards must be an int, not {type(shards).__name__}")
    if shards < 1:
        raise ValueError(f"shards must be at least 1, not {shards}")


def shard_commands(effect, shards, out, *, args=(), overrides=None, cli="tickfx"):
    """The command lines of a sharded run, as argv lists: `shards` of them, shard I's
    ``[cli, "run", effect, "--shard", "I/N", "--out", "OUT/shard_I_of_N", "--quiet", "--hash",
    *args, "--set", "KEY=VALUE", ...]``, then the merge as the last element,
    ``[cli, "merge", "OUT/shard_0_of_N", ..., "--out", OUT, "--hash", "--quiet"]``.

    args: more `tickfx run` options, each shard gets them all (str; other values are str()'d):
        the frames (--frames, --seconds, --fps), --format, --threads, --checkpoint-every ...
        Paths are passed as given: relative ones are relative to where the commands run.
    overrides: None or a dict {key path: value}, written as `--set KEY=VALUE` in order, values
        as tickfx.load_effect() writes them (a str is TOML text as --set takes it).
    Pure: nothing is run or checked; effect and out are passed as given.
    """
    _check_shards(shards)
    effect, out, cli = _path_text(effect), _path_text(out), _path_text(cli)
    extra = [str(a) for a in args]
    for key, value in _override_pairs(overrides):
        extra += ["--set", f"{key}={value}"]
    commands = []
    for i in range(shards):
        commands.append([cli, "run", effect, "--shard", f"{i}/{shards}",
                         "--out", shard_folder(out, i, shards), "--quiet", "--hash", *extra])
    folders = [shard_folder(out, i, shards) for i in range(shards)]
    commands.append([cli, "merge", *folders, "--out", out, "--hash", "--quiet"])
    return commands


def _default_cli():
    cli = os.environ.get("TICKFX_CLI") or shutil.which("tickfx")
    if not cli:
        raise FileNotFoundError(
            "tickfx.distributed: no tickfx command line: pass cli=PATH, set TICKFX_CLI, or put "
            "tickfx on PATH"
        )
    return cli


_prctl = None  # libc's prctl(), looked up before the first fork


def _die_with_parent(parent):
    # Runs in the child between fork and exec, so it only calls what _spawn() looked up.
    # PR_SET_PDEATHSIG: the kernel sends SIGKILL when the thread that forked the child ends,
    # which it does when its worker process is killed. An orphaned CLI would otherwise go on
    # writing the folder that the task's retry writes.
    _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the worker died before prctl took effect
        os._exit(128 + signal.SIGKILL)


def _spawn(argv):
    """Runs argv to its end; (returncode, stdout, stderr, seconds, peak RSS in bytes)."""
    global _prctl
    preexec = None
    if sys.platform.startswith("linux"):
        if _prctl is None:
            prctl = ctypes.CDLL(None, use_errno=True).prctl
            prctl.argtypes = [ctypes.c_int] + [ctypes.c_ulong] * 4
            prctl.restype = ctypes.c_int
            _prctl = prctl
        parent = os.getpid()
        preexec = lambda: _die_with_parent(parent)  # noqa: E731
    # Files, not pipes: nothing to drain while waiting, so the child is waited for with wait4(),
    # which gives its own resource usage (RUSAGE_CHILDREN would be the most of every child the
    # worker has waited for). Its ru_maxrss includes the forked copy of this process (the kernel
    # carries the old image's high-water mark across exec), so it is an upper bound.
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.monotonic()
        child = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                 preexec_fn=preexec)
        try:
            _, status, usage = os.wait4(child.pid, 0)
        except BaseException:
            child.kill()
            child.wait()
            raise
        seconds = time.monotonic() - start
        child.returncode = os.waitstatus_to_exitcode(status)
        # ru_maxrss: kilobytes on Linux, bytes on macOS.
        peak = usage.ru_maxrss * (1 if sys.platform == "darwin" else 1024)
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode(errors="replace")
        stderr = err.read().decode(errors="replace")
    return child.returncode, stdout, stderr, seconds, peak


def _run_checked(argv):
    code, stdout, stderr, seconds, peak = _spawn(argv)
    if code == 2:
        raise ShardError(argv, code, stderr)
    if code != 0:
        raise CommandError(argv, code, stderr)
    return stdout, seconds, peak


def _hash_lines(argv, stdout):
    fields = dict(line.split(": ", 1) for line in stdout.splitlines() if ": " in line)
    try:
        return fields["state-hash"].strip(), int(fields["ticks"])
    except (KeyError, ValueError):
        raise CommandError(argv, 0, f"{' '.join(argv)}: expected 'state-hash:' and 'ticks:' "
                                    f"lines, got:\n{stdout}") from None


def _run_shard(index, argv, folder):
    """The task of one shard, on a worker: runs its CLI; its summary dict (see run()), or
    {"refused": ShardError} (returned, not raised: Dask would retry a refusal to no end)."""
    try:
        _, seconds, peak = _run_checked(argv)
    except ShardError as refused:
        return {"refused": refused}
    return {"shard": index, "seconds": seconds, "peak_rss": peak, "folder": folder,
            "host": socket.gethostname()}


def _run_merge(argv):
    """The merge task, on a worker: {"state_hash", "ticks", "seconds", "peak_rss"} (bytes), or
    {"refused": ShardError} as for _run_shard()."""
    try:
        stdout, seconds, peak = _run_checked(argv)
    except ShardError as refused:
        return {"refused": refused}
    state_hash, ticks = _hash_lines(argv, stdout)
    return {"state_hash": state_hash, "ticks": ticks, "seconds": seconds, "peak_rss": peak}


def run(effect, shards, client, out, *, args=(), overrides=None, cli=None, progress=None,
        retries=2):
    """Runs `effect` as `shards` shards on the Dask cluster of `client` (a distributed.Client),
    then merges them: OUT then holds the files the unsharded `tickfx run EFFECT --out OUT` with
    the same args and overrides writes, bit for bit, and OUT/shard_I_of_N each shard's own.

    out: a folder every worker reaches at this same path: a shared filesystem. effect and out are
        made absolute here (the workers' working folder need not be this one); paths inside
        `args` (--resume, --frame-times) are passed as given, so give them absolute. Give a new
        or empty folder: nothing an earlier run left in it is removed.
    args, overrides: as for shard_commands(); every shard gets them all. A shard's CLI takes its
        thread count from the effect (`simulation.threads`, 0: every core of its machine) unless
        args has --threads: give a worker's cores when workers share a machine.
    cli: the tickfx command line's path on the workers; default $TICKFX_CLI, else `tickfx` on
        this process's PATH (FileNotFoundError when neither names one).
    progress: None, or a callable progress(done, total, summary) called here, in this thread, as
        each shard ends (in the order they end; total is `shards`, the merge is not counted).
    retries: how many times Dask runs a failed shard or merge task again (exit 1 or a signal; a
        refusal, exit 2, is not run again: it would be refused again). A worker that dies
        mid-task (killed, out of memory) has its task run again on another worker as Dask does,
        up to the scheduler's `distributed.scheduler.allowed-failures` (3) times before
        distributed.KilledWorker is raised here; its CLI is killed with it (Linux:
        PR_SET_PDEATHSIG), so the two never write
        the same folder at once.

    Each shard is one task (key "tickfx-shard-I-of-N-<uuid>"), then one merge task on a worker.
    Returns a dict:
        "state_hash": 16 hex digits, and "ticks": the unsharded run's (`tickfx merge --hash`,
            exactly what `tickfx run --hash` of the whole run prints);
        "shards": one summary a shard, by index: {"shard": I, "seconds": the CLI's wall time,
            "peak_rss": the CLI's peak resident memory in bytes (wait4()'s ru_maxrss of that
                process alone, not of the worker's other children), "folder": OUT/shard_I_of_N,
            "host": the worker's host name}. peak_rss is an upper bound: Linux counts in it the
            copy of the worker made by fork() before the CLI starts (a Dask worker holds about
            100 MB), so a small shard reads high and a large one's own peak dominates;
        "merge_seconds": the merge's wall time in seconds;
        "out": out, absolute.
    Raises ShardError (a ValueError: exit 2, e.g. "EFFECT: error: cannot shard: ...") or
    CommandError (exit 1, or a signal) with the CLI's stderr as its message, from the first shard
    that fails after its retries; the other shards are then cancelled, their folders left as
    they are. The shard folders are kept after the merge.
    """
    from distributed import as_completed  # here, so `import tickfx.distributed` needs no Dask

    _check_shards(shards)
    if cli is None:
        cli = _default_cli()
    effect = os.path.abspath(_path_text(effect))
    out = os.path.abspath(_path_text(out))
    commands = shard_commands(effect, shards, out, args=args, overrides=overrides, cli=cli)
    token = uuid.uuid4().hex
    futures = []
    for i, argv in enumerate(commands[:-1]):
        futures.append(client.submit(
            _run_shard, i, argv, shard_folder(out, i, shards),
            key=f"tickfx-shard-{i}-of-{shards}-{token}", retries=retries, pure=False))
    summaries = []
    try:
        for future in as_completed(futures):
            summary = future.result()  # raises the task's CommandError
            if "refused" in summary:
                raise summary["refused"]
            summaries.append(summary)
            if progress is not None:
                progress(len(summaries), shards, summary)
    except BaseException:
        client.cancel(futures)
        raise
    merged = client.submit(_run_merge, commands[-1], key=f"tickfx-merge-{shards}-{token}",
                           retries=retries, pure=False).result()
    if "refused" in merged:
        raise merged["refused"]
    return {
        "state_hash": merged["state_hash"],
        "ticks": merged["ticks"],
        "shards": sorted(summaries, key=lambda s: s["shard"]),
        "merge_seconds": merged["seconds"],
        "out": out,
    }
