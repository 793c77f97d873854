"""Griffe extension for the API reference: Sphinx markup in docstrings -> Markdown.

screwkit's docstrings follow numpydoc and write the Sphinx way: formulas as ``:math:`...```
inline and ``.. math:: ...`` displays, references as ``:func:`name```, ``:class:`~a.b.C```.
mkdocstrings renders docstrings as Markdown, where those would come out as literal text. This
extension rewrites every docstring before it is parsed: formulas into the delimiters of
``pymdownx.arithmatex`` (``\\( ... \\)`` and ``\\[ ... \\]``, typeset as MathML by docs/mathml_hook.py), references into
inline code (``~a.b.C`` shows as ``C``). Loaded from mkdocs.yml
(``extensions: [docs/griffe_sphinx.py:SphinxMarkup]``); not part of the site.
"""

from __future__ import annotations

import re
import textwrap

import griffe

INLINE = re.compile(r":math:`([^`]+)`")
ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const|ref):`(~?)([^`]+)`")
DISPLAY = re.compile(r"^(?P<indent>[ \t]*)\.\. math::[ \t]*(?P<first>.*)$")


def sphinx_math_to_arithmatex(text: str) -> str:
    """Rewrite ``:math:`x``` as ``\\(x\\)`` and ``.. math::`` blocks as ``\\[ ... \\]`` displays."""
    lines = text.splitlines()
    out: list[str] = []
    index = 0
    while index < len(lines):
        match = DISPLAY.match(lines[index])
        if not match:
            out.append(lines[index])
            index += 1
            continue
        indent = match["indent"]
        body = [match["first"]] if match["first"].strip() else []
        index += 1
        block: list[str] = []
        while index < len(lines) and (not lines[index].strip() or
                                      len(lines[index]) - len(lines[index].lstrip()) > len(indent)):
            block.append(lines[index])
            index += 1
        while block and not block[-1].strip():  # the blank line after the display stays outside
            block.pop()
            index -= 1
        body += textwrap.dedent("\n".join(block)).splitlines()
        formula = " ".join(part.strip() for part in body if part.strip())
        if out and out[-1].strip():
            out.append("")
        out += [f"{indent}\\[", f"{indent}{formula}", f"{indent}\\]"]
        if index < len(lines) and lines[index].strip():
            out.append("")
    return INLINE.sub(lambda found: f"\\({found[1]}\\)", "\n".join(out))


def sphinx_roles_to_code(text: str) -> str:
    """Rewrite ``:func:`a.b``` as ``a.b`` in backticks, ``:class:`~a.b.C``` as ``C``."""
    return ROLE.sub(lambda found: f"`{found[2].rsplit('.', 1)[-1] if found[1] else found[2]}`", text)


class SphinxMarkup(griffe.Extension):
    """Rewrite Sphinx math and reference roles in every docstring."""

    def on_instance(self, *, obj: griffe.Object, **kwargs) -> None:  # noqa: D102 - griffe hook
        if obj.docstring is not None and ":" in obj.docstring.value:
            obj.docstring.value = sphinx_roles_to_code(sphinx_math_to_arithmatex(obj.docstring.value))
