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
import math
import os
import socket
import sys
import time
from dataclasses import dataclass
from typing import Any, Callable

__all__ = ["run_tasks", "connect", "disconnect", "ClusterError", "CONNECT_TIMEOUT", "MAX_CONNECT_TIMEOUT", "Execution",
           "check_connect_timeout", "check_address", "SUPPORTED_ADDRESSES"]

CONNECT_TIMEOUT = 3.0
"""Seconds to wait for a Dask scheduler to answer (and to give its handshake) before giving up."""
MAX_CONNECT_TIMEOUT = 86_400.0
"""The longest ``connect_timeout`` taken: a day. A scheduler still starting (a job queue granting its node) is
waited for within hours at most; a longer wait is a mistyped value. Far larger ones cannot be waited at all: a
socket's timeout of 10^10 s overflows (``OverflowError: timestamp out of range``), and NaN would never be reached."""
SUPPORTED_ADDRESSES = "tcp://HOST:PORT or tls://HOST:PORT (a port from 1 to 65535)"
"""The scheduler addresses :func:`connect` takes: those of a scheduler in another process, reached over TCP."""


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


def check_connect_timeout(seconds, name: str = "`connect_timeout`") -> float:
    """``seconds`` as a float if it is a number of seconds to wait, 0 < seconds <= :data:`MAX_CONNECT_TIMEOUT`;
    else a ValueError naming ``name``."""
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and 0 < value <= MAX_CONNECT_TIMEOUT):
        given = f"{value:g}" if isinstance(seconds, (int, float)) else repr(seconds)
        raise ValueError(f"Expected {name} in seconds, more than 0 and at most {MAX_CONNECT_TIMEOUT:,.0f} (a day), "
                         f"got {given}.")
    return value


def check_address(scheduler) -> tuple[str, str, int]:
    """(scheme, host, port) of a scheduler address :func:`connect` can use (:data:`SUPPORTED_ADDRESSES`; without
    a scheme, tcp); else a ValueError saying what is wrong and what is supported."""
    from distributed.comm import parse_address, parse_host_port

    try:
        scheme, location = parse_address(scheduler)
        if scheme not in ("tcp", "tls"):
            raise ValueError(f"{scheme}:// is not supported")
        host, port = parse_host_port(location)
    except (TypeError, ValueError) as error:
        raise ValueError(f"Cannot use the Dask scheduler address {scheduler!r}: {error}; expected "
                         f"{SUPPORTED_ADDRESSES}.") from None
    if not 1 <= int(port) <= 65535:
        raise ValueError(f"Cannot use the Dask scheduler address {scheduler!r}: port {port} is not from 1 to 65535; "
                         f"expected {SUPPORTED_ADDRESSES}.")
    return scheme, host, int(port)


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
    import threading

    from distributed.comm import connect as open_comm

    async def exchange():
        comm = await asyncio.wait_for(open_comm(address, timeout=seconds, **connection_args), seconds)
        await comm.close()

    # A loop of its own, whatever runs in this thread, in a daemon thread: Ctrl+C (KeyboardInterrupt here) ends the
    # wait at once, where the exit of a ThreadPoolExecutor's block waited for its thread, up to the whole timeout.
    loop = asyncio.new_event_loop()
    task = loop.create_task(exchange())
    outcome: list[BaseException] = []

    def run() -> None:
        try:
            loop.run_until_complete(task)
        except BaseException as error:  # (re-raised in the calling thread)
            outcome.append(error)
        finally:
            loop.close()

    thread = threading.Thread(target=run, name="screwkit-handshake", daemon=True)
    thread.start()
    try:
        thread.join()
    except BaseException:
        with contextlib.suppress(RuntimeError):  # the loop closed meanwhile: nothing left to cancel
            loop.call_soon_threadsafe(task.cancel)
        raise
    if outcome:
        raise outcome[0]


def connect(scheduler: str, connect_timeout: float = CONNECT_TIMEOUT):
    """A ``distributed.Client`` of the scheduler at ``scheduler``, once it has answered as a Dask scheduler.

    Within ``connect_timeout`` seconds: something must listen at the address (tried again while
    nothing does, for a scheduler still starting), then answer Dask's handshake; a ``tls://``
    address needs TLS settings in Dask's configuration. Close the client with :func:`disconnect`.

    Raises
    ------
    ClusterError
        One line naming the address and what was found there (or what is wrong with it: only
        :data:`SUPPORTED_ADDRESSES` are taken).
    ValueError
        ``connect_timeout`` is not a number of seconds, 0 < connect_timeout <= :data:`MAX_CONNECT_TIMEOUT`.
    """
    from distributed import Client
    from distributed.security import Security

    connect_timeout = check_connect_timeout(connect_timeout)
    try:
        scheme, host, port = check_address(scheduler)
    except ValueError as error:
        raise ClusterError(str(error)) from None
    connection_args = Security().get_connection_args("client")
    if scheme == "tls" and connection_args.get("ssl_context") is None:
        raise ClusterError(f"Cannot connect to the Dask scheduler at {scheduler}: a tls:// address needs TLS "
                           "settings (distributed.comm.tls.ca-file, .client.cert and .client.key in Dask's "
                           "configuration, e.g. DASK_DISTRIBUTED__COMM__TLS__CA_FILE), and none are set.")
    deadline = time.monotonic() + connect_timeout
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
