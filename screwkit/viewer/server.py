"""The Meshcat server of a scene: a child process listening on the loopback address only.

``meshcat.Visualizer()`` would start ``meshcat.servers.zmqserver``, whose tornado web server
listens on every interface (``Application.listen(port)`` without an address); the server here
is started with ``listen`` bound to :data:`LOOPBACK_HOST`. Stop it with
:meth:`ViewerServer.stop`; it is also stopped when the Python process exits, and it stops itself
when its parent process is gone however that ended (a watchdog in the server, see :data:`_SERVER_CODE`).
"""

from __future__ import annotations

import contextlib
import io
import select
import subprocess
import sys
import tempfile
import time
import weakref

__all__ = ["LOOPBACK_HOST", "ViewerServer", "start_viewer", "servers_to_stop", "import_meshcat"]


LOOPBACK_HOST = "127.0.0.1"
"""The only address the Meshcat servers started here listen on."""


BACKGROUND_COLORS = ((0.98, 0.98, 0.98), (0.80, 0.82, 0.85))
"""Top and bottom colours of the viewer background (light grey, so coloured chains stand out)."""


_SERVER_CODE = r"""
import os, select, sys, threading, time
host = sys.argv[1]
parent = os.getppid()
def _watch_parent():
    # Ends the server when its parent is gone, however it ended (even SIGKILL): the parent holds the only write
    # end of this process's stdin, so its end reads as end-of-file; and the parent id changes on re-parenting.
    while True:
        readable = select.select([0], [], [], 0.5)[0]
        if (readable and not os.read(0, 4096)) or os.getppid() != parent:
            os._exit(0)
threading.Thread(target=_watch_parent, daemon=True).start()
import tornado.web
_listen = tornado.web.Application.listen
def _listen_on_host(self, port, address=None, **kwargs):
    return _listen(self, port, host, **kwargs)
tornado.web.Application.listen = _listen_on_host
from meshcat.servers.zmqserver import ZMQWebSocketBridge
bridge = ZMQWebSocketBridge(host=host)
sys.stdout.write("zmq_url=%s\nweb_url=%s\n" % (bridge.zmq_url, bridge.web_url))
sys.stdout.flush()
quiet = os.open(os.devnull, os.O_WRONLY)
os.dup2(quiet, 1)
os.dup2(quiet, 2)
bridge.run()
"""
"""Started as ``python -c``: meshcat's ZeroMQ/websocket bridge with tornado's ``listen``
forced onto ``host`` (meshcat passes no address, which means every interface), and a watchdog thread that
ends the server as soon as its parent is gone (its stdin, a pipe only the parent holds, reaches end-of-file, or
its parent process id changes): a parent killed by any signal, even SIGKILL, leaves no server behind."""


class ViewerServer:
    """A Meshcat server child process listening on :data:`LOOPBACK_HOST` only.

    Start it with :meth:`start`; stop it with :meth:`stop` (also called when the object is
    garbage collected or Python exits).

    Attributes
    ----------
    process : subprocess.Popen
        The server process (meshcat's ``ZMQWebSocketBridge``).
    zmq_url : str
        ``tcp://127.0.0.1:PORT`` the Python client sends commands to.
    web_url : str
        ``http://127.0.0.1:PORT/static/``, the page of the viewer.
    """

    def __init__(self, process: subprocess.Popen, zmq_url: str, web_url: str):
        self.process = process
        self.zmq_url = zmq_url
        self.web_url = web_url
        self._finalizer = weakref.finalize(self, stop_process, process)
        SERVERS.add(self)

    @classmethod
    def start(cls, host: str = LOOPBACK_HOST, timeout: float = 30.0) -> ViewerServer:
        """Start a server bound to ``host`` and wait until it reports its URLs.

        Parameters
        ----------
        host : str
            Listening address of both the web and the ZeroMQ socket. Keep the default
            ``"127.0.0.1"`` unless the viewer must be reachable from other machines.
        timeout : float
            Seconds to wait for the server to start.

        Raises
        ------
        RuntimeError
            The server exited or did not report its URLs in time (the message quotes its output).
        """
        with tempfile.TemporaryFile() as errors:
            process = subprocess.Popen([sys.executable, "-c", _SERVER_CODE, host], stdin=subprocess.PIPE,
                                       stdout=subprocess.PIPE, stderr=errors, start_new_session=True)
            urls: dict[str, str] = {}
            problem = None
            deadline = time.monotonic() + timeout
            try:
                while len(urls) < 2:
                    remaining = deadline - time.monotonic()
                    if remaining <= 0 or not select.select([process.stdout], [], [], remaining)[0]:
                        problem = f"did not report its URLs within {timeout:g} s"
                        break
                    line = process.stdout.readline()
                    if not line:  # end of its output: the server exited
                        process.wait(timeout=5)
                        problem = "exited"
                        break
                    key, separator, value = line.decode("utf-8", "replace").strip().partition("=")
                    if separator:
                        urls[key] = value
            except BaseException:
                stop_process(process)
                raise
            if problem is not None:
                stop_process(process)
                errors.seek(0)
                output = errors.read().decode("utf-8", "replace").strip()
                raise RuntimeError(f"The Meshcat server on {host} {problem} (exit code {process.returncode}): "
                                   f"{output[-2000:] or 'no output'}")
        process.stdout.close()
        return cls(process, urls["zmq_url"], urls["web_url"])

    @property
    def running(self) -> bool:
        """Whether the server process is alive."""
        return self.process.poll() is None

    def stop(self) -> None:
        """Terminate the server process (kill it if it does not exit within 5 s); idempotent."""
        self._finalizer()

    def __repr__(self) -> str:
        state = "running" if self.running else f"stopped ({self.process.returncode})"
        return f"ViewerServer(web_url={self.web_url!r}, pid={self.process.pid}, {state})"


SERVERS: weakref.WeakSet = weakref.WeakSet()


def servers_to_stop() -> bool:
    """Whether some server process started here is still to be stopped (at the latest at exit)."""
    return any(server._finalizer.alive for server in SERVERS)


def stop_process(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    for stream in (process.stdout, process.stdin):
        if stream is not None and not stream.closed:
            with contextlib.suppress(OSError):
                stream.close()


def start_viewer(server: ViewerServer | None = None, *, timeout: float = 30.0):
    """A ``meshcat.Visualizer`` connected to a server on 127.0.0.1, with screwkit's background.

    Parameters
    ----------
    server : ViewerServer, optional
        Connect to this server; default: start a new one (``viewer.window.server_proc`` is
        its process, as with ``meshcat.Visualizer()``).
    timeout : float
        Seconds to wait for the server to start, and for each reply of the server.

    Returns
    -------
    meshcat.Visualizer
        ``viewer.window.screwkit_server`` holds the :class:`ViewerServer`.
    """
    import zmq

    meshcat = import_meshcat()
    server = ViewerServer.start(timeout=timeout) if server is None else server
    class Window(meshcat.visualizer.ViewerWindow):
        """meshcat's window, closing its ZeroMQ socket before it opens another (it reconnects once)."""

        def connect_zmq(self):
            previous = getattr(self, "zmq_socket", None)
            if previous is not None:
                previous.close(linger=0)
            super().connect_zmq()

    with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints the URL
        window = Window(zmq_url=server.zmq_url, start_server=False, server_args=[])
        viewer = meshcat.Visualizer(window=window)
    viewer.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(max(timeout, 60.0) * 1000))
    viewer.window.server_proc = server.process
    viewer.window.screwkit_server = server
    style_viewer(viewer)
    return viewer


def import_meshcat():
    """``import meshcat`` without its DeprecationWarning (its server module imports zmq.eventloop.ioloop)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import meshcat
        import meshcat.servers.zmqserver
    return meshcat


def style_viewer(viewer) -> None:
    top, bottom = BACKGROUND_COLORS
    viewer["/Background"].set_property("top_color", list(top))
    viewer["/Background"].set_property("bottom_color", list(bottom))

