"""The Dask scheduler: the same photo tasks on an existing ``distributed`` cluster.

Nothing is shared but the scheduler's address: the batch process reads each photo and sends
its *bytes* with the task, the worker makes the photo's folder in a temporary folder of its
own and returns the files as bytes, and the batch process writes them into the library as a
whole (the same atomic folder write as the local pool). So the workers need neither the
inputs' paths nor the library (no shared file system), only ``quilt-studio`` installed at the
same version. The function that makes the folder is the local pool's (:mod:`engine.batch.task`)
and each photo's seed comes from its content, so the files are byte-identical to a local run.

At most two photos per worker thread are in flight (read, sent or being returned), so the
batch process holds a bounded number of photos in memory whatever the library's size.

Dask is imported only here, and only when a batch is given ``--scheduler``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

from engine.batch.settings import BatchSettings
from engine.batch.task import PhotoRecord, error_text, photo_files, store_failed, store_files

CONNECT_TIMEOUT = "20s"


class ClusterError(RuntimeError):
    """The scheduler cannot be reached or used; the message says why."""


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address`` (``tcp://HOST:PORT``)."""
    try:
        from distributed import Client
    except ImportError:
        raise ClusterError(
            "--scheduler needs Dask distributed: pip install 'quilt-studio[distributed]'"
        ) from None
    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ClusterError(f"cannot reach the Dask scheduler at {address}: {exc}") from None


def local_cluster(workers: int = 2):
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes on the
    loopback address: what the tests and the benchmark run the batch on."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=":0",  # a free port: several clusters may run at once
    )


def _threads(client) -> int:
    workers = client.scheduler_info().get("workers", {})
    return max(1, sum(int(w.get("nthreads", 1)) for w in workers.values()))


def iter_cluster(
    photos, settings: BatchSettings, library, *, address: str
) -> Iterator[PhotoRecord]:
    """Make every photo's folder in ``library`` on the Dask cluster at ``address``; yields each
    :class:`PhotoRecord` as its photo finishes. Closing the generator cancels what is left."""
    from distributed import as_completed

    todo = list(reversed(list(photos)))
    if not todo:
        return
    client = connect(address)
    pending: dict = {}
    tag = settings.digest()
    try:
        window = 2 * _threads(client)
        done = as_completed(loop=client.loop)

        def submit() -> None:
            photo = todo.pop()
            try:
                with open(photo.path, "rb") as f:
                    data = f.read()
            except OSError as exc:  # the task reports the reason
                data, photo = b"", replace(photo, error=f"cannot be read ({error_text(exc)})")
            fut = client.submit(
                photo_files, photo, settings, data, key=f"quilt-photo-{photo.key}-{tag}"
            )
            pending[fut] = photo
            done.add(fut)

        while todo and len(pending) < window:
            submit()
        for fut in done:
            photo = pending.pop(fut)
            try:
                record, files = fut.result()
            except Exception as exc:  # the worker died (KilledWorker) or the task broke
                record = PhotoRecord(photo.key, photo.path, "failed", error_text(exc))
                store_failed(library, photo, settings, record)
            else:
                try:
                    store_files(library, photo.key, files)
                except OSError as exc:
                    record = PhotoRecord(photo.key, photo.path, "failed", error_text(exc))
                del files
            fut.release()
            if todo:
                submit()
            yield record
    finally:
        if pending:
            client.cancel(list(pending), force=True)
        client.close()
