"""Shared fixtures of the tests, and the split between the fast default run and the full run.

``pytest`` alone runs the **fast set**: the tests of the library in this process. ``pytest --full`` (the
README's test command, and CI's) runs everything: besides the fast set, the docstring examples of the
package (``--doctest-modules``: importing every module compiles its kernels), and the tests of the classes
below, each marked so (``-m cli``, ``-m "not cluster"``, ... select among them):

* ``cli``: the command run as users run it, in a subprocess (found by the test's own code: it calls the
  ``screwkit`` helper or ``subprocess``; a new such test is classified without anyone marking it);
* ``cluster``: a real ``dask scheduler`` and workers (``tests/test_cluster.py``);
* ``browser``: headless Chromium (the viewer's exported page);
* ``docs``: the documentation site built in strict mode;
* ``notebooks``: the notebooks executed;
* ``slow``: anything else that takes long.

Helpers shared by several modules are in ``helpers.py``; fixtures shared by several modules are here.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np
import pytest

FULL_ONLY = ("cli", "cluster", "browser", "docs", "notebooks", "slow")
"""Markers of the tests that only ``pytest --full`` runs."""
BY_MODULE = {"test_cluster": "cluster", "test_docs": "docs", "test_notebooks": "notebooks", "test_json_schema": "cli"}
SUBPROCESS_CALLS = ("screwkit(", "screwkit_json(", "subprocess.", "run_command(", "Popen(")


def pytest_addoption(parser):
    parser.addoption("--full", action="store_true", help="Run every test: the CLI subprocesses, the cluster, the "
                                                         "browser, the docs, the notebooks and the doctests too.")


def pytest_configure(config):
    for marker in FULL_ONLY:
        config.addinivalue_line("markers", f"{marker}: run by pytest --full only (see tests/conftest.py)")
    if config.getoption("--full"):
        config.option.doctestmodules = True  # the package's docstring examples (they import every kernel)


def _source(item) -> str:
    """The test's own code and that of the fixtures it uses (a browser or a subprocess may start in one)."""
    functions = [getattr(item, "function", None)]
    info = getattr(item, "_fixtureinfo", None)
    for name in getattr(item, "fixturenames", ()):
        functions += [definition.func for definition in (info.name2fixturedefs.get(name, ()) if info else ())]
    return "\n".join(_function_source(function) for function in functions)


@functools.cache
def _function_source(function) -> str:
    """One function's code, looked up once (the items of a parametrised test share it); "" where it has none."""
    try:
        return inspect.getsource(function)
    except (OSError, TypeError):
        return ""


def _shares_fixtures(module) -> bool:
    """Whether a test module holds a fixture wider than a test (a Dask cluster, a browser, a site built): its tests
    then run in one worker process, which sets it up once (``--dist loadgroup``); the others go to whichever worker
    is free, test by test."""
    try:
        text = inspect.getsource(module)
    except (OSError, TypeError):
        return False
    return any(f'scope="{scope}"' in text or f"scope='{scope}'" in text for scope in ("module", "session", "package"))


@pytest.hookimpl(tryfirst=True)  # (before xdist's, which reads the xdist_group marks added here to group the tests)
def pytest_collection_modifyitems(config, items):
    grouped: dict[str, bool] = {}
    for item in items:
        module = item.module.__name__.rsplit(".", 1)[-1] if getattr(item, "module", None) else ""
        if module and grouped.setdefault(module, _shares_fixtures(item.module)):
            item.add_marker(pytest.mark.xdist_group(name=module))
        source = _source(item)
        if module in BY_MODULE:
            item.add_marker(getattr(pytest.mark, BY_MODULE[module]))
        elif "chromium" in source.lower():
            item.add_marker(pytest.mark.browser)
        elif any(call in source for call in SUBPROCESS_CALLS):
            item.add_marker(pytest.mark.cli)
    if config.getoption("--full"):
        return
    kept, skipped = [], []
    for item in items:
        (skipped if any(item.get_closest_marker(marker) for marker in FULL_ONLY) else kept).append(item)
    if skipped:
        config.hook.pytest_deselected(items=skipped)
        items[:] = kept


def pytest_report_header(config):
    if not config.getoption("--full"):
        return ("fast set: the CLI subprocesses, the cluster, the browser, the docs, the notebooks and the "
                "doctests run with --full (the README's test command)")
    return "full run"


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
