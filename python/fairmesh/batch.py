"""Fairing many files: one function per file, run by a process pool on one machine, or by Dask or
Ray past it.

``fair_file(source, destination, **options)`` loads one file, fairs it and writes it back beside
(as ``fairmesh fair SOURCE -o DESTINATION`` does: the file comes back with only the positions,
and what follows them, changed) and returns the report, a plain dict that pickles. It is a
module-level function, so any pool can send it to another process.

On one machine, ``fair_files`` runs it over a list of (source, destination) pairs in a process
pool, one thread a process (``threads=1``: the processes are the parallelism), and yields each
file's (source, report or exception) as it finishes, so that one bad file does not stop the
batch::

    import fairmesh.batch
    jobs = [(path, path.with_name(path.stem + "_faired" + path.suffix))
            for path in sorted(Path("scans").glob("*.ply"))]
    for source, outcome in fairmesh.batch.fair_files(jobs, rounds=None):
        if isinstance(outcome, Exception):
            print(source, "failed:", outcome)
        else:
            print(source, outcome["rounds_run"], outcome["volume_change_percent"])

Any start method works, ``fork`` included, before or after this process used fairmesh (each
process runs its own thread pool; the ``DeprecationWarning`` Python 3.12 and newer give when a
process with threads forks is about other threads: fairmesh's own are not copied and not
needed in the child). Ctrl+C in the terminal stops the batch: every worker gets the
signal and its call stops at the next round, and ``fair_files`` cancels what has not started and
raises ``KeyboardInterrupt``.

Past one machine, the same function over the files, with the files where every worker reads
them (a shared file system or object store mounted alike)::

    import dask.bag
    reports = dask.bag.from_sequence(jobs).starmap(fairmesh.batch.fair_file,
                                                   threads=1).compute()

    import ray
    fair_remote = ray.remote(fairmesh.batch.fair_file)
    reports = ray.get([fair_remote.remote(s, d, threads=1) for s, d in jobs])

Threads instead of processes: the calls release the GIL, so a ``ThreadPoolExecutor`` of
``fair_file(..., threads=1)`` calls runs them side by side too, in one process. Python gives
Ctrl+C to the main thread only, so a call in a worker thread does not stop on it: give each call
``progress=lambda fraction: not stop.is_set()`` with a ``threading.Event`` that the main thread
sets when it catches ``KeyboardInterrupt`` (the call then raises ``fairmesh.Cancelled`` at its
next round).
"""

import multiprocessing
import os
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any, Dict, Iterable, Iterator, Optional, Tuple, Union

import fairmesh

PathLike = Union[str, "os.PathLike[str]"]


def fair_file(source: PathLike, destination: PathLike, **options: Any) -> Dict[str, Any]:
    """Load ``source``, fair it with ``options`` (those of ``fairmesh.fair``) and save it into
    ``destination`` (format by extension; the file's own format keeps all it held). Returns the
    report, with ``output`` set to ``destination``."""
    mesh = fairmesh.load(source)
    vertices, report = fairmesh.fair(mesh, **options)
    mesh.save(destination, vertices)
    report["output"] = os.fspath(destination)
    return report


def fair_files(
    jobs: Iterable[Tuple[PathLike, PathLike]],
    *,
    processes: Optional[int] = None,
    start_method: Optional[str] = None,
    **options: Any,
) -> Iterator[Tuple[str, Union[Dict[str, Any], BaseException]]]:
    """Run ``fair_file(source, destination, **options)`` for every pair of ``jobs`` in a pool of
    ``processes`` processes (None: one a core) made by ``start_method`` (None: Python's default;
    "fork", "forkserver" or "spawn"). Yields (source, report) for each file as it finishes, or
    (source, exception) for one that failed. ``threads`` defaults to 1 (one thread a process).
    Ctrl+C cancels the files not started and raises ``KeyboardInterrupt``."""
    options.setdefault("threads", 1)
    context = multiprocessing.get_context(start_method)
    executor = ProcessPoolExecutor(max_workers=processes, mp_context=context)
    try:
        running: Dict[Future, str] = {
            executor.submit(fair_file, source, destination, **options): os.fspath(source)
            for source, destination in jobs
        }
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in done:
                source = running.pop(future)
                error = future.exception()
                yield source, (future.result() if error is None else error)
    except BaseException:
        executor.shutdown(wait=True, cancel_futures=True)
        raise
    executor.shutdown(wait=True)
