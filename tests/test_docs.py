"""The documentation site builds in strict mode, and what it shows stays true.

``mkdocs build --strict`` fails on any warning: a broken link or image, an unknown cross
reference, a docstring mkdocstrings cannot render, a CLI command that no longer imports, a formula
the MathML hook cannot typeset. Neither the build nor the built site needs the network: formulas
are MathML written at build time (docs/mathml_hook.py), with a math font copied into the site.
"""

from __future__ import annotations

import html
import importlib.util
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
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
                 "cli/index.html", "paper/index.html", "performance/index.html", "api/indices/index.html"):
        assert (site / page).is_file(), page


def test_api_reference_renders_docstring_math(site):
    page = (site / "api" / "screw" / "index.html").read_text(encoding="utf-8")
    assert "Reciprocal product of two screws" in page
    assert ".. math::" not in page and ":math:" not in page and ":func:" not in page
    # docstring math typeset as MathML at build time, no TeX left for a script to find
    assert '<span class="arithmatex"><math ' in page or '<div class="arithmatex"><math ' in page
    assert not re.search(r'class="arithmatex">\\[(\[]', page)


def _load_docs_module(name: str):
    spec = importlib.util.spec_from_file_location(name, DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_theory_formula_is_rendered_as_mathml(site):
    """The reciprocal product of docs/theory.md (Eq. 1) comes out as display MathML."""
    tex = r"A \circ T = \mathbf f \cdot \mathbf v + \mathbf m \cdot \boldsymbol\omega ."
    assert tex in (DOCS / "theory.md").read_text(encoding="utf-8")
    page = (site / "theory" / "index.html").read_text(encoding="utf-8")
    displays = re.findall(r'<div class="arithmatex">(<math\b.*?</math>)</div>', page, re.S)
    assert displays, "no display formula typeset as MathML"
    equation = next(math for math in displays if r"\circ T = \mathbf f" in math)
    assert 'display="block"' in equation
    assert "<semantics>" in equation and '<annotation encoding="application/x-tex">' in equation
    symbols = html.unescape(re.sub(r"<annotation\b.*?</annotation>", "", equation, flags=re.S))
    assert "\u2218" in symbols  # the circle operator
    assert "\U0001D41F" in symbols and "\U0001D74E" in symbols  # bold f, bold italic omega
    assert "<merror" not in page


class _Fetched(HTMLParser):
    """Addresses a browser loads by itself from a page: scripts, stylesheets, icons, images, styles."""

    NOT_LOADED = {"canonical", "alternate", "prev", "next"}  # <link rel=...> that only name a page

    def __init__(self):
        super().__init__()
        self.addresses: list[str] = []
        self.styles: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        if tag in ("script", "img", "iframe", "source", "audio", "video", "embed") and attributes.get("src"):
            self.addresses.append(attributes["src"])
        relations = set((attributes.get("rel") or "").split())
        if tag == "link" and attributes.get("href") and not relations & self.NOT_LOADED:
            self.addresses.append(attributes["href"])
        if attributes.get("style"):
            self.styles.append(attributes["style"])
        self._in_style = tag == "style"

    def handle_endtag(self, tag):
        self._in_style = False

    def handle_data(self, data):
        if self._in_style:
            self.styles.append(data)


CSS_URL = re.compile(r"""(?:url\(\s*['"]?|@import\s+['"])([^'")\s]+)""", re.I)


def _external(address: str) -> bool:
    return bool(re.match(r"^\s*(https?:)?//", address, re.I))


def test_site_loads_nothing_from_the_network(site):
    """No page pulls a script, stylesheet, font or image from elsewhere (links <a href> may point out)."""
    external = []
    for page in site.rglob("*.html"):
        parser = _Fetched()
        parser.feed(page.read_text(encoding="utf-8"))
        urls = parser.addresses + [url for style in parser.styles for url in CSS_URL.findall(style)]
        external += [f"{page.relative_to(site)}: {url}" for url in urls if _external(url)]
    stylesheets = sorted(site.rglob("*.css"))
    assert stylesheets
    for stylesheet in stylesheets:
        for url in CSS_URL.findall(stylesheet.read_text(encoding="utf-8")):
            if _external(url):
                external.append(f"{stylesheet.relative_to(site)}: {url}")
            elif not url.startswith(("data:", "#")):  # a local asset (the math font): shipped
                assert (stylesheet.parent / url.split("#")[0].split("?")[0]).is_file(), (stylesheet, url)
    assert not external, "fetched from the network:\n" + "\n".join(external)
    assert (site / "assets" / "fonts" / "STIXTwoMath-Regular.ttf").is_file()


def test_mathml_hook_conversion():
    hook = _load_docs_module("mathml_hook")
    page = hook.render_math('<p>a <span class="arithmatex">\\(x &lt; y_1\\)</span> b</p>'
                            '<div class="arithmatex">\\[\n\\mathcal M = \\mathbb R^6\n\\]</div>')
    assert page.startswith('<p>a <span class="arithmatex"><math ') and "display=\"inline\"" in page
    assert "&#x0003C;" in page and "<msub>" in page and 'display="block"' in page
    assert "\u2133" in page and "\u211d" in page  # script M, double-struck R
    assert '<annotation encoding="application/x-tex">x &lt; y_1</annotation>' in page
    assert hook.math_alphanumeric("d", "bold") == "\U0001D41D"
    assert hook.math_alphanumeric("h", "italic") == "\u210e"
    assert hook.math_alphanumeric("\u03c9", "bold-italic") == "\U0001D74E"
    assert hook.math_alphanumeric("\u03a9", "bold") == "\U0001D6C0"
    assert hook.math_alphanumeric("+", "bold") == "+"
    bars = hook.tex_to_mathml(r"|\mathbf m|\,\|x\|", display=False)
    assert bars.count('lspace="0em" rspace="0em"') == 4  # |, || are ordinary symbols, as in TeX
    with pytest.raises(ValueError, match="unknown TeX command"):
        hook.tex_to_mathml(r"\notacommand x", display=False)
    with pytest.raises(ValueError, match="cannot convert"):
        hook.tex_to_mathml(r"\frac{a}{", display=False)
    assert hook.render_math("<p>no math</p>") == "<p>no math</p>"


def _commands(group: click.Group, context: click.Context | None = None, prefix: str = ""):
    """(name, command, context) of every command, a group's subcommands as ``group subcommand``."""
    context = context or click.Context(group, info_name="screwkit")
    for name in group.list_commands(context):
        command = group.get_command(context, name)
        inner = click.Context(command, info_name=name, parent=context)
        yield f"{prefix}{name}", command, inner
        if isinstance(command, click.Group):
            yield from _commands(command, inner, f"{prefix}{name} ")


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
    module = _load_docs_module("griffe_sphinx")
    convert = module.sphinx_math_to_arithmatex
    assert convert("the pitch :math:`h` and :math:`\\rho_{max}`") == "the pitch \\(h\\) and \\(\\rho_{max}\\)"
    text = "Before:\n\n.. math:: a = b\n          + c\n\nafter."
    assert convert(text) == "Before:\n\n\\[\na = b + c\n\\]\n\nafter."
    text = "Before:\n\n.. math::\n\n    x = y\n\nafter."
    assert convert(text) == "Before:\n\n\\[\nx = y\n\\]\n\nafter."
    assert convert("no math here") == "no math here"
    roles = module.sphinx_roles_to_code
    assert roles("see :func:`analyze` and :class:`~screwkit.screw.chain_screws.ChainScrews`") == \
        "see `analyze` and `ChainScrews`"
    assert roles(":mod:`screwkit.indices.compiled.algebra`, :meth:`TransmissionResult.lmti_of`") == (
        "`screwkit.indices.compiled.algebra`, `TransmissionResult.lmti_of`")
