"""The shape of the package: one-way layers, no import cycle, no private name across modules, small modules.

The import graph is read from the source (every ``import`` and ``from ... import``, at module
level and inside functions), so a cycle hidden by a function-local import is found too.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "screwkit"

LAYERS = {
    "screwkit.common": 0,  # tolerances, units, rotations, validation, the plumbing of compiled kernels
    "screwkit.screw": 1,  # the screw algebra and what it builds (numpy only)
    "screwkit.model": 1,  # what a file says
    "screwkit.indices": 2,  # the paper's indices (numpy, numba when they first run)
    "screwkit.closure": 2,  # closure solving
    "screwkit.io": 3,  # files of other tools and loading
    "screwkit.studies": 4,  # sweeps, maps, designs
    "screwkit.plots": 5, "screwkit.viewer": 5,
    "screwkit.cli": 6,
    "screwkit": 7,  # the top-level API, imported lazily
    "screwkit.__main__": 7,  # python -m screwkit
}
"""Layer of each module or package, bottom up: a module may import its own layer and those below."""


def module_name(path: Path) -> str:
    relative = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(relative.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer(module: str) -> int:
    assert module.count(".") != 1 or module in LAYERS, f"{module} has no layer: add it to LAYERS"
    while module not in LAYERS:
        module = module.rsplit(".", 1)[0]
    return LAYERS[module]


def imports(path: Path):
    """(line, imported module, imported names) of every import of a screwkit module in a file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "screwkit":
                    yield node.lineno, alias.name, ()
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "screwkit":
            yield node.lineno, node.module, tuple(alias.name for alias in node.names)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def graph() -> dict[str, set[str]]:
    edges: dict[str, set[str]] = {module: set() for module in MODULES}
    for module, path in MODULES.items():
        for _, target, names in imports(path):
            for name in names or ("",):
                candidate = f"{target}.{name}" if name else target
                resolved = candidate if candidate in MODULES else target
                if resolved in MODULES and resolved != module:
                    edges[module].add(resolved)
    return edges


def test_the_import_graph_has_no_cycle():
    edges = graph()
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(module: str) -> None:
        state[module] = 1
        path.append(module)
        for target in sorted(edges[module]):
            if state.get(target) == 1:
                cycle = path[path.index(target):] + [target]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if target not in state:
                visit(target)
        path.pop()
        state[module] = 2

    for module in sorted(edges):
        if module not in state:
            visit(module)


def test_layers_import_only_downwards():
    wrong = []
    for module, path in MODULES.items():
        for line, target, _ in imports(path):
            if target in MODULES or target.rsplit(".", 1)[0] in MODULES:
                if layer(target) > layer(module) and not target.startswith(module + "."):
                    wrong.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {module} (layer {layer(module)}) "
                                 f"imports {target} (layer {layer(target)})")
    assert not wrong, "\n".join(wrong)


def test_no_private_name_is_imported_from_another_module():
    wrong = []
    for module, path in MODULES.items():
        for line, target, names in imports(path):
            private = [name for name in names if name.startswith("_") and not name.startswith("__")]
            if private and target != module:
                wrong.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {', '.join(private)} from {target}")
    assert not wrong, "\n".join(wrong)


def test_function_local_imports_of_the_package_say_why():
    """Inside functions, screwkit modules are imported only to keep a heavy dependency off the import path."""
    wrong = []
    for path in MODULES.values():
        source = path.read_text(encoding="utf-8")
        lines = source.splitlines()
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for inner in ast.walk(node):
                    if isinstance(inner, ast.ImportFrom) and (inner.module or "").startswith("screwkit"):
                        if "#" not in lines[inner.lineno - 1]:
                            wrong.append(f"{path.relative_to(PACKAGE.parent)}:{inner.lineno}: "
                                         f"{lines[inner.lineno - 1].strip()}")
    assert not wrong, "function-local imports without a reason:\n" + "\n".join(wrong)


def test_modules_and_classes_stay_small():
    """No module above ~540 lines (the compiled kernels included; ~500 is the aim), no class above ~300 lines."""
    too_long = []
    for module, path in MODULES.items():
        source = path.read_text(encoding="utf-8")
        if source.count("\n") > 540:
            too_long.append(f"{module}: {source.count(chr(10))} lines")
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.ClassDef) and node.end_lineno - node.lineno > 300:
                too_long.append(f"{module}.{node.name}: {node.end_lineno - node.lineno} lines")
    assert not too_long, "\n".join(too_long)


def test_the_core_imports_numpy_only():
    """The math core loads no Pinocchio, numba, Dask, matplotlib, Meshcat, xarray or scipy when imported."""
    heavy = ("pinocchio", "numba", "dask", "distributed", "matplotlib", "meshcat", "xarray", "scipy", "pandas")
    code = ("import sys; import screwkit.screw.algebra, screwkit.indices.analysis, screwkit.indices.results, "
            "screwkit.indices.closed_forms, screwkit.screw.planar, screwkit.screw.chain_screws, "
            "screwkit.common.tolerances, screwkit.common.units, screwkit.common.rotations; "
            f"print(sorted(m for m in {heavy!r} if m in sys.modules))")
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert completed.returncode == 0, completed.stderr
    assert completed.stdout.strip() == "[]", completed.stdout


def test_the_command_line_starts_without_heavy_dependencies():
    """``screwkit --help`` and ``screwkit list`` import no numba, Pinocchio, Dask, matplotlib or Meshcat."""
    heavy = ("pinocchio", "numba", "dask", "distributed", "matplotlib", "meshcat", "xarray")
    code = f"import sys; import screwkit.cli; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert completed.returncode == 0, completed.stderr
    assert completed.stdout.strip() == "[]", completed.stdout


def test_every_subpackage_is_installed_by_a_plain_pip_install():
    """pyproject lists the packages by hand: a package missing there imports in an editable install only."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {module_name(path.parent) for path in PACKAGE.rglob("__init__.py")}
    assert found <= listed, f"not in pyproject.toml's packages: {sorted(found - listed)}"


def test_indices_are_built_by_one_constructor():
    """``Indices.from_arrays`` is the one constructor: no module but the result type's own calls ``Indices(...)``
    (where F_IOj is Eq. 14 of F_Oj and the ITI, the submechanisms every n-subset, shapes checked, derived indices
    computed), so no producer of results can skip one of those."""
    direct = []
    for module, path in MODULES.items():
        if module == "screwkit.indices.results":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "Indices":
                direct.append(f"{module}:{node.lineno}")
    assert not direct, "Indices(...) called directly (use Indices.from_arrays):\n" + "\n".join(direct)


MAX_PARAMETERS = 10
"""Parameters of a function at most (positional and keyword-only, ``self`` and ``cls`` not counted, nor
``*args`` and ``**kwargs``): options that travel together are one record (an ``AnalysisOptions``, an
``Execution``, a ``MapBlock``, a command's option group)."""
LONG_SIGNATURES = {
    # The top-level API (screwkit.analyze, screwkit.indices_at_poses): each keyword an independent setting with
    # its default, documented one by one and passed by name in users' code, the tests and the notebooks; a record
    # there would make every caller build one for the call most users make. The counts may not grow.
    "screwkit.indices.analysis.analyze": 14,
    "screwkit.studies.poses.indices_at_poses": 11,
    "screwkit.viewer.scene.animate_sweep": 11,  # (idem: screwkit.viewer.animate_sweep; limits= added for view)
}
"""Functions allowed more parameters, and how many."""
KERNELS = ("screwkit.indices.compiled", "screwkit.closure.compiled")
"""The numba kernels: plain arrays in, plain arrays out, by design (not counted)."""


def signatures():
    """(qualified name, parameter count) of every function and method outside the compiled kernels."""
    for module, path in MODULES.items():
        if module.startswith(KERNELS):
            continue

        def visit(node, prefix):
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    arguments = child.args
                    names = [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]
                    yield f"{prefix}.{child.name}", len([n for n in names if n not in ("self", "cls")])
                    yield from visit(child, f"{prefix}.{child.name}")
                elif isinstance(child, ast.ClassDef):
                    yield from visit(child, f"{prefix}.{child.name}")
                else:
                    yield from visit(child, prefix)

        yield from visit(ast.parse(path.read_text(encoding="utf-8")), module)


def test_no_function_takes_more_than_ten_parameters():
    counts = dict(signatures())
    long = {name: count for name, count in counts.items()
            if count > MAX_PARAMETERS and count > LONG_SIGNATURES.get(name, MAX_PARAMETERS)}
    assert not long, "group the options that travel together in a record: " + ", ".join(
        f"{name} ({count} parameters)" for name, count in sorted(long.items()))
    assert set(LONG_SIGNATURES) <= set(counts), "an allowed long signature is gone: take it off LONG_SIGNATURES"


MAX_KERNEL_FUNCTION_LINES = 80
"""Lines of a function of the compiled kernels at most (its decorators not counted, its docstring counted): a kernel
is a short driver over named stages (numba inlines them, ``inline="always"``), each readable on one screen."""


def test_no_kernel_function_is_longer_than_eighty_lines():
    """Every function of the compiled packages (``KERNELS``) fits in ``MAX_KERNEL_FUNCTION_LINES`` lines."""
    long = []
    for module, path in MODULES.items():
        if not module.startswith(KERNELS):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_KERNEL_FUNCTION_LINES:
                    long.append(f"{module}.{node.name} ({path.name}:{node.lineno}): {lines} lines")
    assert not long, (f"kernel functions above {MAX_KERNEL_FUNCTION_LINES} lines: cut them into named stages "
                      "(@njit(..., inline='always'), each a pass over a block) under a short driver:\n"
                      + "\n".join(long))
    assert any(module.startswith(KERNELS) for module in MODULES), f"no module of {KERNELS} found"
