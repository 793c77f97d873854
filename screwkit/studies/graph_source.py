"""Closed-loop graphs in the tasks of a map: what a task needs to rebuild one where it runs."""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path

from screwkit.io import GraphMechanism, graph_mechanism, read_closed_tree

__all__ = ["GraphSource", "graph_source", "cached_graph"]


@dataclass(frozen=True)
class GraphSource:
    """What a task needs to rebuild a closed-loop graph (:class:`~screwkit.io.GraphMechanism`): its file, read where
    the task runs (a Dask worker on another machine needs it at the same path), the reading's output choice, its
    locked and actuated joints, its length unit, and the file's digest (a task refuses a file changed since the map
    began)."""

    path: str
    output: str | None
    output_type: str | None
    digest: str
    lock: tuple[str, ...] = ()
    actuate: tuple[str, ...] = ()
    length_unit: str | None = None
    initial: tuple[tuple[str, float], ...] = ()


@functools.lru_cache(maxsize=4)
def cached_graph(source: GraphSource) -> GraphMechanism:
    """The graph of ``source``, assembled at the file's configuration (remembered per process)."""
    try:
        data = Path(source.path).read_bytes()
    except OSError as error:
        raise ValueError(f"{source.path}: cannot be read where the map's task runs ({error.strerror}).") from None
    if hashlib.sha256(data).hexdigest() != source.digest:
        raise ValueError(f"{source.path}: the file changed while the map was computed.")
    return graph_mechanism(read_closed_tree(Path(source.path), output=source.output, output_type=source.output_type,
                                            lock=source.lock, actuate=source.actuate, length_unit=source.length_unit,
                                            initial=source.initial))


def graph_source(graph: GraphMechanism) -> GraphSource:
    """What a task elsewhere needs to rebuild ``graph`` as read (:func:`cached_graph`)."""
    digest = hashlib.sha256(Path(graph.tree.source).read_bytes()).hexdigest()
    return GraphSource(str(graph.tree.source), graph.tree.output, graph.tree.output_type, digest, graph.tree.locked,
                       graph.tree.actuated, graph.tree.length_unit, graph.tree.initial)
