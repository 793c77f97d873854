"""numba's cache never serves a kernel compiled from older sources (``screwkit.common.jit``).

numba checks the stamp of a kernel's own file; the kernels inline helpers from other modules, so screwkit's
cache locators add a digest of every kernel source. Here: that the digest covers every module the compiled code
imports, and, end to end on a copy of the package, that a change to a helper module alone compiles the kernel anew
where numba alone would load the old machine code.
"""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import screwkit
from screwkit.common.compiling import PACKAGE, kernel_sources, kernel_sources_digest

# imported by compiled modules for Python-side plumbing only (which kernels to prepare), never compiled in
PLUMBING = {"screwkit.common.compiling"}


def _file(module: str) -> Path:
    return PACKAGE.parent.joinpath(*module.split(".")).with_suffix(".py")


def _imported_modules(path: Path) -> set[str]:
    modules = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("screwkit"):
            submodules = {f"{node.module}.{alias.name}" for alias in node.names}  # from a package import a module
            found = {name for name in submodules if _file(name).is_file()}
            modules.update(found or {node.module})
        elif isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names if alias.name.startswith("screwkit"))
    return modules


def test_the_stamp_covers_every_module_the_kernels_import():
    sources = set(kernel_sources())
    compiled = [path for path in sources if "compiled" in path.parts]
    assert len(compiled) >= 10  # both compiled folders were found
    for path in compiled:
        for module in _imported_modules(path) - PLUMBING:
            assert _file(module) in sources, \
                f"{path.relative_to(PACKAGE)} imports {module}, which the kernels' cache stamp does not cover"


def test_the_digest_follows_the_contents(tmp_path):
    copy = tmp_path / "screwkit"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = kernel_sources_digest(copy)
    assert before == kernel_sources_digest(PACKAGE)  # names and contents, not where the package lies
    helper = copy / "indices" / "compiled" / "jacobi.py"
    helper.write_text(helper.read_text() + "\n# edited\n")
    kernel_sources_digest.cache_clear()
    assert kernel_sources_digest(copy) != before


PROBE = """
import json, numpy as np
import screwkit
from screwkit.common.compiling import kernel_is_cached
cached = kernel_is_cached("screwkit.indices.compiled.planar")  # before numba sees the index
from screwkit.indices.compiled.planar import planar_closed_form_kernel as kernel
from screwkit.studies import indices_at_poses
mechanism = screwkit.load("planar_5rrr")
result = indices_at_poses(mechanism, np.array([[-0.2, 0.0, 0.785], [0.1, 0.05, 0.3]]), closed_forms=True)
print(json.dumps({"file": screwkit.__file__, "cached": cached, "hits": sum(kernel.stats.cache_hits.values()),
                  "misses": sum(kernel.stats.cache_misses.values()), "lmti": result.lmti.tolist()}))
"""


def test_a_helper_changed_alone_compiles_the_kernel_anew(tmp_path):
    """On a copy of the package with a cache of its own: cached, then a helper module the kernel compiles in
    (``common/fastmath.py``, not the kernel's file) edited alone: compiled again, then cached again; and
    ``kernel_is_cached`` (what decides the notice and the compiling ahead) says so before each run."""
    copy = tmp_path / "code"
    shutil.copytree(PACKAGE, copy / "screwkit", ignore=shutil.ignore_patterns("__pycache__"))
    environment = {**os.environ, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
                   "SCREWKIT_CACHE_DIR": str(tmp_path / "screwkit-cache")}

    def probe() -> dict:
        done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=environment,
                              cwd=tmp_path, timeout=600)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout.strip().splitlines()[-1])

    first = probe()
    assert Path(first["file"]).resolve().is_relative_to(copy.resolve())  # the copy runs, not the checkout
    assert Path(screwkit.__file__).resolve().is_relative_to(PACKAGE.parent)
    assert first["misses"] == 1 and first["hits"] == 0 and not first["cached"]
    again = probe()
    assert again["hits"] == 1 and again["misses"] == 0 and again["lmti"] == first["lmti"] and again["cached"]
    helper = copy / "screwkit" / "common" / "fastmath.py"
    helper.write_text(helper.read_text() + "\n# a helper edited alone\n")
    edited = probe()
    assert edited["misses"] == 1 and edited["hits"] == 0, "the old machine code was served after a helper changed"
    assert not edited["cached"]  # the index of the old sources is not taken for a cached kernel
    last = probe()
    assert last["hits"] == 1 and last["cached"]
