"""Running independent tasks: local threads (no Dask imported), or a ``dask.distributed`` cluster.

:func:`run_tasks` runs ``function(*arguments)`` for every tuple of arguments and returns the
results in order. Tasks are pure functions of their inputs, so a task lost with a worker is
recomputed on another (three retries); results come back only when every task is done, so a
caller writes nothing until then. Failures of the cluster itself are one-line
:class:`ClusterError` messages: an address that does not answer within ``connect_timeout``, one
that answers but is not a Dask scheduler (a web server, the dashboard's port) or is ``tls://``
without TLS settings, a scheduler lost mid-run, a task given up by the scheduler because the
workers running it died (more often than its ``distributed.scheduler.allowed-failures``).
:func:`connect` makes the connection (and so these checks) once, before any work; the client it
returns serves every later :func:`run_tasks`.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import socket
import sys
import time
from dataclasses import dataclass
from typing import Any, Callable

__all__ = ["run_tasks", "connect", "disconnect", "ClusterError", "CONNECT_TIMEOUT", "Execution"]

CONNECT_TIMEOUT = 3.0
"""Seconds to wait for a Dask scheduler to answer (and to give its handshake) before giving up."""


@dataclass(frozen=True)
class Execution:
    """Where and how a study's tasks run: the same record from the command line to :func:`run_tasks`.

    Attributes
    ----------
    scheduler : str or distributed.Client, optional
        Address of a running ``dask.distributed`` scheduler (``tcp://host:8786``) or a client of
        :func:`connect`; default: local threads, one per core.
    progress : bool, optional
        A progress bar on stderr; default: only when stderr is a terminal.
    connect_timeout : float
        Seconds to wait for the scheduler to answer.
    configurations_per_task : int, optional
        Configurations per task of a map (default: :func:`screwkit.studies.maps.task_size`).
    """

    scheduler: Any = None
    progress: bool | None = None
    connect_timeout: float = CONNECT_TIMEOUT
    configurations_per_task: int | None = None


class ClusterError(RuntimeError):
    """The Dask cluster could not be reached, or was lost mid-run."""


def _run_local(function: Callable, arguments: list[tuple], bar) -> list:
    """Local threads, one per core (the standard library's pool: Dask's threaded scheduler ran the same tasks the
    same way, after 0.1-0.2 s of importing Dask). The results in order; the first failure is raised as it was
    raised once the running tasks end, and the tasks not started are dropped."""
    from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

    if not arguments:
        return []
    pool = ThreadPoolExecutor(max_workers=min(len(arguments), os.cpu_count() or 1), thread_name_prefix="screwkit-task")
    try:
        futures = [pool.submit(function, *args) for args in arguments]
        for future in futures:
            future.add_done_callback(lambda _: bar.update(1))
        done, _ = wait(futures, return_when=FIRST_EXCEPTION)
        for future in futures:
            if future in done and future.exception() is not None:
                return future.result()  # (raises the task's exception)
        return [future.result() for future in futures]
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


class _NoBar:
    """The progress bar when none is shown (tqdm is then not imported)."""

    def update(self, count: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


@contextlib.contextmanager
def _distributed_logs_muted():
    """Drop the records of distributed's loggers meanwhile, such as the traceback it logs when a client
    whose scheduler is gone is closed: the failure is reported once, as a ClusterError."""

    def keep(record: logging.LogRecord) -> bool:
        return not record.name.startswith("distributed")

    loggers = [logging.root] + [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
                                if name == "distributed" or name.startswith("distributed.")]
    handlers = {handler for logger in loggers for handler in logger.handlers}
    for handler in handlers:
        handler.addFilter(keep)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(keep)


def _first_line(error: BaseException) -> str:
    text = str(error).strip()
    return f"{type(error).__name__}: {text.splitlines()[0]}" if text else type(error).__name__


def _reach(host: str, port: int, deadline: float) -> None:
    """Open (and close) a TCP connection to host:port, trying again until ``deadline`` while nothing listens."""
    pause = 0.01
    while True:
        try:
            socket.create_connection((host, port), timeout=max(0.01, deadline - time.monotonic())).close()
            return
        except OSError:
            if time.monotonic() + pause >= deadline:
                raise
            time.sleep(pause)
            pause = min(2 * pause, 0.5)


def _handshake(address: str, connection_args: dict, seconds: float) -> None:
    """Dask's handshake with ``address`` within ``seconds``, in an event loop of its own (distributed's
    ``connect`` waits for the handshake without a time limit once a connection is open)."""
    import asyncio
    import concurrent.futures

    from distributed.comm import connect as open_comm

    async def exchange():
        comm = await asyncio.wait_for(open_comm(address, timeout=seconds, **connection_args), seconds)
        await comm.close()

    with concurrent.futures.ThreadPoolExecutor(1) as thread:  # a loop of its own, whatever runs in this thread
        thread.submit(asyncio.run, exchange()).result()


def connect(scheduler: str, connect_timeout: float = CONNECT_TIMEOUT):
    """A ``distributed.Client`` of the scheduler at ``scheduler``, once it has answered as a Dask scheduler.

    Within ``connect_timeout`` seconds: something must listen at the address (tried again while
    nothing does, for a scheduler still starting), then answer Dask's handshake; a ``tls://``
    address needs TLS settings in Dask's configuration. Close the client with :func:`disconnect`.

    Raises
    ------
    ClusterError
        One line naming the address and what was found there.
    """
    from distributed import Client
    from distributed.comm import parse_address, parse_host_port
    from distributed.security import Security

    try:
        scheme, location = parse_address(scheduler)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (TypeError, ValueError) as error:
        raise ClusterError(f"Cannot use the Dask scheduler address {scheduler!r}: {error}") from None
    connection_args = Security().get_connection_args("client")
    if scheme == "tls" and connection_args.get("ssl_context") is None:
        raise ClusterError(f"Cannot connect to the Dask scheduler at {scheduler}: a tls:// address needs TLS "
                           "settings (distributed.comm.tls.ca-file, .client.cert and .client.key in Dask's "
                           "configuration, e.g. DASK_DISTRIBUTED__COMM__TLS__CA_FILE), and none are set.")
    deadline = time.monotonic() + connect_timeout
    if host is not None:
        try:
            _reach(host, port, deadline)
        except OSError as error:
            raise ClusterError(f"Cannot reach the Dask scheduler at {scheduler} within {connect_timeout:g} s "
                               f"({_first_line(error)}).") from None
        try:
            _handshake(scheduler, connection_args, max(0.01, deadline - time.monotonic()))
        except TimeoutError:
            raise ClusterError(f"The address {scheduler} answers but is not a Dask scheduler: no Dask handshake "
                               f"within {connect_timeout:g} s (a web server, or the dashboard's port?).") from None
        except Exception as error:  # what a server of another protocol says (read as Dask's frames), or its hang-up
            raise ClusterError(f"The address {scheduler} answers but is not a Dask scheduler: its answer is not "
                               f"Dask's handshake ({_first_line(error)[:160]}).") from None
    try:
        return Client(scheduler, set_as_default=False, timeout=connect_timeout)
    except (OSError, TimeoutError) as error:
        raise ClusterError(f"Cannot reach the Dask scheduler at {scheduler} within {connect_timeout:g} s "
                           f"({_first_line(error)}).") from None
    except (TypeError, ValueError) as error:
        raise ClusterError(f"Cannot use the Dask scheduler address {scheduler!r}: {error}") from None


def disconnect(client, connect_timeout: float = CONNECT_TIMEOUT) -> None:
    """Close a client of :func:`connect`, quietly (the client of a scheduler that is gone can only time out)."""
    with _distributed_logs_muted():
        try:
            client.close(timeout=connect_timeout)
        except Exception:
            pass


def _run_distributed(function: Callable, arguments: list[tuple], scheduler: Any, connect_timeout: float, bar) -> list:
    from concurrent.futures import CancelledError

    from distributed import Client, KilledWorker, as_completed

    client = scheduler if isinstance(scheduler, Client) else connect(scheduler, connect_timeout)
    address = getattr(client.scheduler, "address", scheduler)
    try:
        stamp = time.time_ns()
        keys = [f"screwkit-{function.__name__}-{hashlib.sha256(repr((i, stamp)).encode()).hexdigest()[:12]}"
                for i in range(len(arguments))]
        futures = client.map(function, *zip(*arguments), pure=False, retries=3, key=keys)
        try:
            for _ in as_completed(futures, loop=client.loop):  # the client's own loop: no default client needed
                bar.update(1)
            return client.gather(futures)
        except (CancelledError, OSError, TimeoutError) as error:
            raise ClusterError(f"Lost the Dask scheduler at {address} mid-run ({type(error).__name__}); "
                               "nothing was written.") from None
        except KilledWorker as error:  # the scheduler gave a task up: every worker that ran it died
            raise ClusterError(f"Dask workers of the scheduler at {address} died while running a task "
                               f"(KilledWorker: {str(error).split('. ')[0]}); nothing was written.") from None
    finally:
        if client is not scheduler:
            disconnect(client, connect_timeout)


def run_tasks(function: Callable, arguments: list[tuple], execution: Execution | None = None, *,
              label: str = "tasks") -> list:
    """Run ``function(*args)`` for every tuple of ``arguments`` and return the results in order.

    Parameters
    ----------
    function : callable
        A module-level function (workers import it by name).
    arguments : list of tuple
    execution : Execution, optional
        The scheduler (default: local threads, one per core), the progress bar (tqdm, on
        stderr; default: only when stderr is a terminal) and the seconds to wait for the scheduler.
    label : str
        The progress bar's label.

    Raises
    ------
    ClusterError
        The scheduler does not answer, or is lost before every task is done.
    """
    execution = Execution() if execution is None else execution
    progress = sys.stderr.isatty() if execution.progress is None else execution.progress
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(arguments), desc=label, file=sys.stderr, leave=False, delay=2.0)
    else:
        bar = _NoBar()
    try:
        if execution.scheduler is None:
            return _run_local(function, arguments, bar)
        return _run_distributed(function, arguments, execution.scheduler, execution.connect_timeout, bar)
    finally:
        bar.close()
