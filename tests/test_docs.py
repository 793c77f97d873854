"""The documentation site builds in strict mode, and what it shows stays true.

``mkdocs build --strict`` fails on any warning: a broken link or image, an unknown cross
reference, a docstring mkdocstrings cannot render, a CLI command that no longer imports. The
build needs no network (MathJax is only referenced by the pages).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import click
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """Build the site once into a temporary folder (strict mode)."""
    folder = tmp_path_factory.mktemp("site")
    environment = dict(os.environ, NO_MKDOCS_2_WARNING="1", PYTHONWARNINGS="ignore")
    completed = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file", str(ROOT / "mkdocs.yml"),
         "--site-dir", str(folder)],
        cwd=ROOT, env=environment, capture_output=True, text=True, timeout=600,
    )
    assert completed.returncode == 0, f"mkdocs build --strict failed:\n{completed.stdout}\n{completed.stderr}"
    return folder


def test_site_builds_strict(site):
    for page in ("index.html", "theory/index.html", "urdf-convention/index.html", "tutorial/index.html",
                 "cli/index.html", "paper/index.html", "performance/index.html", "api/transmission/index.html"):
        assert (site / page).is_file(), page


def test_api_reference_renders_docstring_math(site):
    page = (site / "api" / "screws" / "index.html").read_text(encoding="utf-8")
    assert "Reciprocal product of two screws" in page
    assert ".. math::" not in page and ":math:" not in page and ":func:" not in page
    assert 'class="arithmatex"' in page


def _commands(group: click.Group):
    context = click.Context(group, info_name="screwkit")
    for name in group.list_commands(context):
        command = group.get_command(context, name)
        yield name, command, click.Context(command, info_name=name, parent=context)


def test_cli_page_names_every_command_and_option(site):
    """Part of the CLI reference is written by hand: it must not miss a command or an option."""
    from screwkit.cli import app

    page = (site / "cli" / "index.html").read_text(encoding="utf-8")
    for name, command, context in _commands(app):
        assert f"screwkit {name}" in page, f"command {name!r} missing from docs/cli.md"
        for parameter in command.get_params(context):
            if isinstance(parameter, click.Option):
                for option in parameter.opts:
                    assert option in page, f"option {option} of `screwkit {name}` missing from docs/cli.md"


def test_figures_are_small():
    figures = sorted((DOCS / "figures").glob("*.png"))
    assert figures
    for figure in figures:
        assert figure.stat().st_size < 300_000, f"{figure.name} is {figure.stat().st_size} bytes"


def test_sphinx_markup_conversion():
    spec = importlib.util.spec_from_file_location("griffe_sphinx", DOCS / "griffe_sphinx.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    convert = module.sphinx_math_to_arithmatex
    assert convert("the pitch :math:`h` and :math:`\\rho_{max}`") == "the pitch \\(h\\) and \\(\\rho_{max}\\)"
    text = "Before:\n\n.. math:: a = b\n          + c\n\nafter."
    assert convert(text) == "Before:\n\n\\[\na = b + c\n\\]\n\nafter."
    text = "Before:\n\n.. math::\n\n    x = y\n\nafter."
    assert convert(text) == "Before:\n\n\\[\nx = y\n\\]\n\nafter."
    assert convert("no math here") == "no math here"
    roles = module.sphinx_roles_to_code
    assert roles("see :func:`analyze` and :class:`~screwkit.chains.ChainScrews`") == "see `analyze` and `ChainScrews`"
    assert roles(":mod:`screwkit._kernels`, :meth:`TransmissionResult.lmti_of`") == (
        "`screwkit._kernels`, `TransmissionResult.lmti_of`")
