"""MkDocs hook: typeset every formula of the site at build time, as MathML, with a bundled math font.

The site must read offline, so the browser fetches no math renderer and no font from the network.
``pymdownx.arithmatex`` (``generic: true``) still finds the formulas, in the Markdown pages
(``$...$``, ``\\(...\\)``, ``$$...$$``, ``\\[...\\]``) and in the docstrings of the API reference
(where ``griffe_sphinx.py`` has turned ``:math:`` and ``.. math::`` into those delimiters), and
leaves them as ``<span class="arithmatex">\\(...\\)</span>`` and
``<div class="arithmatex">\\[...\\]</div>``. This hook replaces the TeX inside by MathML from
``latex2mathml`` (pure Python, from PyPI), which current browsers draw natively: no JavaScript.
The TeX source stays in an ``<annotation encoding="application/x-tex">`` (not drawn).

MathML Core (what Chromium implements) ignores ``mathvariant`` other than ``normal``, so the
letters of ``\\mathbf``, ``\\boldsymbol``, ``\\mathsf``, ``\\mathcal``... are written as the Unicode
mathematical alphanumerics instead. Stretchy brackets, radicals and those letters need an
OpenType math font, which Linux desktops often lack: the build copies STIX Two Math (SIL Open Font
License) from the installed ``ziamath`` package into ``assets/fonts/``, and
``stylesheets/mathml.css`` uses it when the system has no STIX Two Math of its own.

A formula latex2mathml cannot parse, or a command it does not know (it would show as ``\\foo``),
is logged as a warning, so ``mkdocs build --strict`` fails on it. Loaded from mkdocs.yml
(``hooks: [docs/mathml_hook.py]``); not part of the site (``exclude_docs: *.py``).
"""

from __future__ import annotations

import html
import importlib.util
import re
from pathlib import Path

from latex2mathml.converter import convert
from mkdocs.plugins import get_plugin_logger
from mkdocs.structure.files import File

log = get_plugin_logger("mathml")

FONT_PACKAGE, FONT_FILE = "ziamath", "fonts/STIXTwoMath-Regular.ttf"
FONT_URI = "assets/fonts/STIXTwoMath-Regular.ttf"  # referenced by docs/stylesheets/mathml.css

ARITHMATEX = re.compile(r'<(?P<tag>span|div) class="arithmatex">(?P<tex>.*?)</(?P=tag)>', re.S)
DELIMITERS = (("\\(", "\\)"), ("\\[", "\\]"), ("$$", "$$"), ("$", "$"))
MATH = re.compile(r"^(?P<open><math\b[^>]*>)(?P<body>.*)</math>$", re.S)
VARIANT_TOKEN = re.compile(r'<(?P<tag>mi|mn|mo|mtext)(?P<before>[^>]*?) mathvariant="(?P<variant>[a-z-]+)"'
                           r"(?P<after>[^>]*)>(?P<text>[^<]*)</(?P=tag)>")
TEXT = re.compile(r">([^<]+)<")
# |x| and \|x\| without \left \right: ordinary symbols in TeX, no space around them (as an infix
# <mo> they would get the spacing of a relation)
BAR = re.compile(r'<mo(?P<attributes>(?![^>]*fence="true")[^>]*)>(?P<bar>&#x0007C;|&#x02016;|\||‖)</mo>')

# Unicode mathematical alphanumerics (U+1D400 ...): where capital A, small a, digit 0, capital
# Alpha and small alpha start for each variant; letters that were encoded earlier, in the
# Letterlike Symbols block, are the holes listed in HOLES.
_LATIN = {"bold": 0x1D400, "italic": 0x1D434, "bold-italic": 0x1D468, "script": 0x1D49C,
          "bold-script": 0x1D4D0, "fraktur": 0x1D504, "double-struck": 0x1D538, "bold-fraktur": 0x1D56C,
          "sans-serif": 0x1D5A0, "bold-sans-serif": 0x1D5D4, "sans-serif-italic": 0x1D608,
          "sans-serif-bold-italic": 0x1D63C, "monospace": 0x1D670}
_DIGITS = {"bold": 0x1D7CE, "double-struck": 0x1D7D8, "sans-serif": 0x1D7E2, "bold-sans-serif": 0x1D7EC,
           "monospace": 0x1D7F6}
_GREEK = {"bold": 0x1D6A8, "italic": 0x1D6E2, "bold-italic": 0x1D71C, "bold-sans-serif": 0x1D756,
          "sans-serif-bold-italic": 0x1D790}
_GREEK_EXTRA = "∂ϵϑϰϕϱϖ"  # after 25 capitals (Α..Ω with ϴ), ∇, and 25 small letters (α..ω with ς)
HOLES = {
    "italic": {"h": "ℎ"},
    "script": {"B": "ℬ", "E": "ℰ", "F": "ℱ", "H": "ℋ", "I": "ℐ", "L": "ℒ", "M": "ℳ", "R": "ℛ",
               "e": "ℯ", "g": "ℊ", "o": "ℴ"},
    "fraktur": {"C": "ℭ", "H": "ℌ", "I": "ℑ", "R": "ℜ", "Z": "ℨ"},
    "double-struck": {"C": "ℂ", "H": "ℍ", "N": "ℕ", "P": "ℙ", "Q": "ℚ", "R": "ℝ", "Z": "ℤ"},
}


def math_alphanumeric(char: str, variant: str) -> str:
    """``char`` in the mathematical alphabet ``variant`` (a MathML mathvariant); itself if none."""
    if char in HOLES.get(variant, {}):
        return HOLES[variant][char]
    code = ord(char)
    if variant in _LATIN and "A" <= char <= "Z":
        return chr(_LATIN[variant] + code - ord("A"))
    if variant in _LATIN and "a" <= char <= "z":
        return chr(_LATIN[variant] + 26 + code - ord("a"))
    if variant in _DIGITS and "0" <= char <= "9":
        return chr(_DIGITS[variant] + code - ord("0"))
    if variant in _GREEK:
        if 0x391 <= code <= 0x3A9:  # Α..Ω; U+03A2 is unassigned, its slot holds ϴ
            return chr(_GREEK[variant] + code - 0x391)
        if char == "ϴ":
            return chr(_GREEK[variant] + 0x3A2 - 0x391)
        if 0x3B1 <= code <= 0x3C9:  # α..ω (with ς)
            return chr(_GREEK[variant] + 26 + code - 0x3B1)
        if char in _GREEK_EXTRA:
            return chr(_GREEK[variant] + 51 + _GREEK_EXTRA.index(char))
        if char == "∇":
            return chr(_GREEK[variant] + 25)
    return char


def _unicode_variant(found: re.Match) -> str:
    variant = found["variant"]
    if variant == "normal":
        return found[0]
    text = "".join(math_alphanumeric(char, variant) for char in html.unescape(found["text"]))
    if any(ord(char) < 0x2100 and char.isalpha() for char in text):
        return found[0]  # a letter with no mathematical form: leave it to the browser
    # one letter of an <mi> would be made italic again by the browser: say it is final
    tag = found["tag"]
    normal = ' mathvariant="normal"' if tag == "mi" else ""
    return f'<{tag}{found["before"]}{normal}{found["after"]}>{html.escape(text, quote=False)}</{tag}>'


def tex_to_mathml(tex: str, display: bool) -> str:
    """MathML for one TeX formula (no delimiters); ValueError for TeX latex2mathml cannot render."""
    try:
        mathml = convert(tex, display="block" if display else "inline")
    except Exception as error:  # latex2mathml raises its own exception types
        raise ValueError(f"cannot convert {tex!r}: {type(error).__name__} {error}") from error
    unknown = [text for text in TEXT.findall(mathml) if "\\" in text]
    if unknown:
        raise ValueError(f"unknown TeX command {unknown[0]!r} in {tex!r}")
    mathml = VARIANT_TOKEN.sub(_unicode_variant, mathml)
    mathml = BAR.sub(r'<mo\g<attributes> lspace="0em" rspace="0em">\g<bar></mo>', mathml)
    parts = MATH.match(mathml)
    if parts is None:  # not the shape latex2mathml gives: leave it without the annotation
        return mathml
    return (f'{parts["open"]}<semantics><mrow>{parts["body"]}</mrow>'
            f'<annotation encoding="application/x-tex">{html.escape(tex, quote=False)}</annotation>'
            f"</semantics></math>")


def _strip_delimiters(source: str) -> str:
    for opening, closing in DELIMITERS:
        if source.startswith(opening) and source.endswith(closing) and len(source) >= 2 * len(opening):
            return source[len(opening):-len(closing)].strip()
    return source  # an environment (\begin{...} ... \end{...}) stands without delimiters


def render_math(page_html: str, where: str = "") -> str:
    """Replace the TeX in every arithmatex span and div of a page by MathML."""

    def replace(found: re.Match) -> str:
        tag = found["tag"]
        tex = _strip_delimiters(html.unescape(found["tex"]).strip())
        try:
            mathml = tex_to_mathml(tex, display=tag == "div")
        except ValueError as error:
            log.warning("%s: %s", where, error)
            return found[0]
        return f'<{tag} class="arithmatex">{mathml}</{tag}>'

    return ARITHMATEX.sub(replace, page_html)


def on_files(files, config, **kwargs):  # noqa: D103 - mkdocs hook
    spec = importlib.util.find_spec(FONT_PACKAGE)  # its folder, without importing it
    font = Path(spec.origin).parent / FONT_FILE if spec is not None and spec.origin else None
    if font is None or not font.is_file():
        log.warning("no math font at %s in the package %s: formulas may draw poorly", FONT_FILE, FONT_PACKAGE)
        return files
    files.append(File.generated(config, FONT_URI, abs_src_path=str(font)))
    return files


def on_page_content(html: str, page, **kwargs) -> str:  # noqa: D103 - mkdocs hook
    return render_math(html, page.file.src_uri)
