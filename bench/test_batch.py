"""``pftrack batch`` on Dask: speed-up over serial, per-task overhead, worker memory.

nice pytest bench/test_batch.py --benchmark-enable --benchmark-only --benchmark-group-by=group

- ``batch 4 sequences``: four PETS09-S2L1 videos (the one video under four names; a synthetic
  480x360 scene of 795 frames when the data is absent, another workload: the group's name then
  ends in ``[synthetic scene]`` and ``extra_info["video"]`` says why) tracked with
  ``pftrack track``'s defaults, one after the other in this process (``n_workers=0``, OpenCV
  at one thread as ``pftrack track`` and ``pftrack batch --workers 0`` set it) and on a warm
  two-worker ``LocalCluster``; on that cluster again with each worker's read-ahead, detector
  and kernel threads switched on (``PFTRACK_TRACKING_THREADS=1``: the plugin switches them off;
  quiet, stop 69 found them costing each worker CPU and the run wall: docs/batch.md); and
  once more including the cluster's start and close, as ``pftrack batch`` does it. Goal:
  serial / two workers >= 1.7 on two cores. Untimed
  (``--benchmark-disable``, as CI runs the benchmarks as tests) the four cases take the smallest
  input that still runs the same path, four links to a synthetic 160x120 video of 8 frames (they
  took 27 % of CI's bench step on PETS09's 795 frames); ``extra_info["video"]`` says so.
- ``batch overhead``: 40 tiny sequences (3 frames of 64x64): the scheduler's cost per sequence,
  ``2 * t_dask / n - t_serial / n`` (worker-seconds per sequence beyond the work), goal <= 0.5 s.
- ``batch memory``: 100 tiny sequences on the two workers; each worker's resident memory after
  the first 10 and after all 100 (goal: flat).

Figures go to ``extra_info`` and are printed (``-s``). Beside each four-sequence case's wall and
each task's ``cpu_seconds`` (its ``process_time``), the CPU of whole processes over the run
(``getrusage``, every thread): this process (the serial run's read-ahead and detector threads;
a cluster's scheduler, nannies and client), and the workers' processes (``client.run`` on a
warm cluster; the reaped children of a cluster started and closed inside the run, their start
included), with the cores they kept busy (CPU / wall): the serial run's is the bound of the
speed-up on two cores (stop 68, docs/batch.md). On the warm cluster, the workers' CPU is split
into their task threads' (the tracking) and their other threads' (Dask's event loop,
heartbeats: what a worker spends beyond a plain process tracking on one thread; stop 69; and
the pipeline's read-ahead and detector threads in the case that switches them on).
"""

from __future__ import annotations

import os
import resource
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from pftrack.batch import dask_client, track_many
from pftrack.synthetic import make_scene

pytest.importorskip("distributed")

N_WORKERS = 2


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    with dask_client(n_workers=N_WORKERS) as c:
        yield c


#: ``extra_info["video"]`` of the four-sequence cases on the data's video.
PETS_VIDEO = "PETS09-S2L1 video.avi"
VIDEO: dict[Path, str] = {}  # a four-sequence folder -> what its sequences are


def _four_links(folder: Path, video: Path, what: str) -> Path:
    for k in range(1, 5):
        (folder / f"seq{k}.avi").symlink_to(video)  # a link, not a copy of the data
    VIDEO[folder] = what
    return folder


@pytest.fixture(scope="module")
def four_timed(data_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("four")
    video = data_dir / "pets09-s2l1" / "video.avi"
    if video.is_file():
        return _four_links(folder, video, PETS_VIDEO)
    what = f"synthetic 480x360 scene, 795 frames (no PETS09-S2L1 video at {video})"
    video = make_scene(n_frames=795, rng=0).write_video(folder.parent / "synthetic.avi")
    return _four_links(folder, video, what)


@pytest.fixture(scope="module")
def four_untimed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Four links to an 8-frame 160x120 video: its walkers are born and tracked on the timed
    cases' path (video files, ``pftrack track``'s defaults) in a fraction of a second."""
    folder = tmp_path_factory.mktemp("four_untimed")
    scene = make_scene(n_frames=8, width=160, height=120, n_walkers=2, rng=0)
    video = scene.write_video(folder.parent / "untimed.avi")
    return _four_links(folder, video, "synthetic 160x120 scene, 8 frames (--benchmark-disable)")


@pytest.fixture
def four_sequences(benchmark: BenchmarkFixture, request: pytest.FixtureRequest) -> Path:
    """:func:`four_timed` when timed, :func:`four_untimed` under ``--benchmark-disable``; only
    the one used is built (without the data, the 795-frame scene is written only to be timed)."""
    folder: Path = request.getfixturevalue("four_untimed" if benchmark.disabled else "four_timed")
    return folder


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("tiny")
    scene = make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0)
    for k in range(100):
        scene.write_images(folder / f"t{k:03d}")
    return folder


def _process_cpu(who: int = resource.RUSAGE_SELF) -> float:
    """User and system CPU seconds of this process (all its threads), or of its reaped children."""
    used = resource.getrusage(who)
    return used.ru_utime + used.ru_stime


def _workers_cpu(client: Any) -> float:
    """The CPU seconds the client's workers' processes have used so far, summed."""
    return float(sum(client.run(_process_cpu).values()))


def _task_threads_cpu() -> dict[int, float]:
    """CPU seconds of each of this Dask worker's task threads (its default executor's), by id.

    The rest of a worker's process is Dask's (its event loop, heartbeats, the offload thread):
    what a worker spends that a plain process tracking on one thread does not (stop 69).
    """
    import threading

    used: dict[int, float] = {}
    for thread in threading.enumerate():
        if "Dask-Default-Threads" in thread.name and thread.ident is not None:
            try:
                clock = time.pthread_getcpuclockid(thread.ident)
                used[thread.ident] = time.clock_gettime(clock)
            except OSError:  # ended meanwhile
                continue
    return used


def _workers_task_cpu(client: Any) -> dict[str, dict[int, float]]:
    """:func:`_task_threads_cpu` of each of the client's workers, by address."""
    return dict(client.run(_task_threads_cpu))


def _task_cpu_spent(
    before: dict[str, dict[int, float]], after: dict[str, dict[int, float]]
) -> float:
    """CPU seconds the workers' task threads spent between two :func:`_workers_task_cpu`.

    A thread started meanwhile counts from 0; one that ended meanwhile (Dask ends a task thread
    idle for a while) is not counted here, so its CPU falls to the rest of its process.
    """
    return sum(
        used - before.get(worker, {}).get(ident, 0.0)
        for worker, threads in after.items()
        for ident, used in threads.items()
    )


def _run(inputs: Any, out: Path, client: Any = None, **kwargs: Any) -> float:
    workers = _workers_cpu(client) if client is not None else 0.0
    tasks = _workers_task_cpu(client) if client is not None else {}
    here, children = _process_cpu(), _process_cpu(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    summary = track_many(inputs, out, client, force=True, show_progress=False, **kwargs)
    seconds = time.perf_counter() - start
    assert not summary.failed, summary.table()
    CPU[str(out)] = [e["cpu_seconds"] for e in summary.entries]
    # the processes' CPU, all threads: a serial run's read-ahead and detector threads, a
    # worker's Dask threads, a started cluster's imports (its workers are this process's
    # children, reaped when it closes); `cpu_seconds` above is each task's process_time
    used = {"this process": _process_cpu() - here}
    if client is not None:
        used["workers"] = _workers_cpu(client) - workers
        TASK_THREADS_CPU[str(out)] = _task_cpu_spent(tasks, _workers_task_cpu(client))
    elif kwargs.get("n_workers", 1) != 0:
        used["workers"] = _process_cpu(resource.RUSAGE_CHILDREN) - children
    PROCESS_CPU[str(out)] = used
    return seconds


CPU: dict[str, list[float]] = {}  # CPU seconds of each sequence's task, by output folder
#: CPU seconds of this process and of the workers' processes over a run, by output folder
PROCESS_CPU: dict[str, dict[str, float]] = {}
#: CPU seconds of the warm workers' task threads over a run (the rest of `PROCESS_CPU`'s
#: "workers" is Dask's own threads), by output folder
TASK_THREADS_CPU: dict[str, float] = {}


TIMES: dict[str, float] = {}  # the serial time, for the speed-up printed by the next case


def _timed(benchmark: BenchmarkFixture, key: str, *args: Any, **kwargs: Any) -> float:
    video = VIDEO[args[0]]
    if video != PETS_VIDEO:  # another workload under another name, as bench/conftest.py's frames
        benchmark.group = f"{benchmark.group} [synthetic scene]"
    seconds = float(benchmark.pedantic(_run, args, kwargs, rounds=1))
    TIMES[key] = seconds
    cpu = CPU[str(args[1])]
    used = PROCESS_CPU[str(args[1])]
    load = os.getloadavg()[0]  # the other users of the cores, for reading the figures
    total = sum(used.values())
    benchmark.extra_info.update(
        seconds=seconds,
        cpu_seconds_per_sequence=cpu,
        process_cpu_seconds=used,
        cores_busy=total / seconds,
        loadavg=load,
        video=video,
    )
    line = f"\n{key} ({video}): {seconds:.1f} s (load {load:.1f}); CPU s per sequence " + " ".join(
        f"{c:.2f}" for c in cpu
    )
    line += (
        "; processes' CPU "
        + ", ".join(f"{who} {c:.2f} s" for who, c in used.items())
        + f" = {total / len(cpu):.2f} s per sequence, {total / seconds:.2f} cores busy"
    )
    if str(args[1]) in TASK_THREADS_CPU:  # a warm cluster: the workers' CPU, task threads or not
        threads = TASK_THREADS_CPU[str(args[1])]
        benchmark.extra_info["workers_task_threads_cpu_seconds"] = threads
        line += (
            f"; workers' task threads {threads:.2f} s, their other threads "
            f"{used['workers'] - threads:.2f} s"
        )
    if key != "serial" and "serial" in TIMES:
        benchmark.extra_info["speedup"] = TIMES["serial"] / seconds
        line += f"; {TIMES['serial'] / seconds:.2f}x serial"
    print(line)
    return seconds


@pytest.mark.benchmark(group="batch 4 sequences")
def test_four_serial(benchmark: BenchmarkFixture, four_sequences: Path, tmp_path: Path) -> None:
    import cv2

    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)  # as `pftrack batch --workers 0` and `pftrack track` run
    try:
        _timed(benchmark, "serial", four_sequences, tmp_path, n_workers=0)
    finally:
        cv2.setNumThreads(threads)


@pytest.mark.benchmark(group="batch 4 sequences")
def test_four_two_workers(
    benchmark: BenchmarkFixture, four_sequences: Path, client: Any, tmp_path: Path
) -> None:
    _run([four_sequences / "seq1.avi"], tmp_path, client)  # workers import pftrack: not timed
    _timed(benchmark, "two workers (warm cluster)", four_sequences, tmp_path, client)


def _set_worker_threads(value: str) -> None:
    """Set this worker's ``PFTRACK_TRACKING_THREADS`` (read by each task as it starts)."""
    from pftrack._threads import WORKER_THREADS_VARIABLE

    os.environ[WORKER_THREADS_VARIABLE] = value


@pytest.mark.benchmark(group="batch 4 sequences")
def test_four_two_workers_pipeline_threads(
    benchmark: BenchmarkFixture, four_sequences: Path, client: Any, tmp_path: Path
) -> None:
    """The warm case with each worker's read-ahead, detector and kernel threads switched on (a
    worker's plugin switches them off): on and off in one run (off won quietly at stop 69)."""
    _run([four_sequences / "seq1.avi"], tmp_path, client)  # workers import pftrack: not timed
    client.run(_set_worker_threads, "1")
    try:
        _timed(benchmark, "two workers, their threads on (warm)", four_sequences, tmp_path, client)
    finally:
        client.run(_set_worker_threads, "0")  # as the plugin leaves them, for the later cases


@pytest.mark.benchmark(group="batch 4 sequences")
def test_four_two_workers_with_cluster_start(
    benchmark: BenchmarkFixture, four_sequences: Path, tmp_path: Path
) -> None:
    _timed(benchmark, "two workers (cluster started)", four_sequences, tmp_path, n_workers=2)


@pytest.mark.benchmark(group="batch overhead")
def test_overhead_per_sequence(
    benchmark: BenchmarkFixture, client: Any, tiny: Path, tmp_path: Path
) -> None:
    inputs = sorted(tiny.iterdir())[:40]
    _run(inputs[:4], tmp_path / "warm", client)
    serial = _run(inputs, tmp_path / "serial", n_workers=0)
    dask = float(benchmark.pedantic(_run, (inputs, tmp_path / "dask", client), rounds=1))
    overhead = N_WORKERS * dask / len(inputs) - serial / len(inputs)
    benchmark.extra_info.update(serial_s=serial, dask_s=dask, overhead_s=overhead)
    print(
        f"\n{len(inputs)} tiny sequences: serial {serial:.2f} s, {N_WORKERS} workers "
        f"{dask:.2f} s; overhead {1e3 * overhead:.0f} ms per sequence (goal <= 500 ms)"
    )
    assert overhead < 0.5


def _rss() -> int:
    import psutil

    return int(psutil.Process().memory_info().rss)


@pytest.mark.benchmark(group="batch memory")
def test_worker_memory_is_flat(
    benchmark: BenchmarkFixture, client: Any, tiny: Path, tmp_path: Path
) -> None:
    inputs = sorted(tiny.iterdir())
    _run(inputs[:10], tmp_path / "a", client)
    after_10 = client.run(_rss)
    benchmark.pedantic(_run, (inputs[10:], tmp_path / "b", client), rounds=1)
    after_100 = client.run(_rss)
    growth = {w: (after_100[w] - after_10[w]) / 2**20 for w in after_10}
    benchmark.extra_info["rss_mib_after_10"] = [after_10[w] / 2**20 for w in after_10]
    benchmark.extra_info["rss_mib_after_100"] = [after_100[w] / 2**20 for w in after_10]
    print(
        "\nworker RSS after 10 / 100 tiny sequences (MiB): "
        + ", ".join(f"{after_10[w] / 2**20:.0f} / {after_100[w] / 2**20:.0f}" for w in after_10)
    )
    assert max(growth.values()) < 20, growth
