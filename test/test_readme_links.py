"""Every relative link of the README resolves: to a file or folder of the repository
and, with ``#anchor``, to a heading of that Markdown file, under the anchor GitHub gives it.

The documentation pages' own links are checked by the docs build (``make docs``: Sphinx with
``-W -n``), not here.
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
#: ``[text](target)`` and ``![alt](target)``, the target up to the closing parenthesis.
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _without_code(text: str) -> str:
    """The text without fenced code blocks and inline code (links inside are not links)."""
    text = re.sub(r"```.*?```", "", text, flags=re.DOTALL)
    return re.sub(r"`[^`\n]*`", "", text)


def _relative_links() -> list[str]:
    return [
        target
        for target in LINK.findall(_without_code(README))
        if not re.match(r"^[a-z][a-z0-9+.-]*:", target)  # https:, mailto:
    ]


def github_anchor(heading: str) -> str:
    """The anchor GitHub gives a Markdown heading: lower case, inline markup and punctuation
    other than ``-`` and ``_`` removed, spaces as ``-``."""
    text = re.sub(r"[`*]", "", heading.strip()).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def _anchors(path: Path) -> set[str]:
    headings = re.findall(r"^#{1,6} (.+)$", _fenced_removed(path), re.MULTILINE)
    return {github_anchor(heading) for heading in headings}


def _fenced_removed(path: Path) -> str:
    return re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.DOTALL)


LINKS = _relative_links()


def test_the_readme_links_into_the_docs():
    pages = {target.split("#")[0] for target in LINKS if target.startswith("docs/")}
    assert len(pages) >= 10, pages
    assert any(target.endswith(".png") for target in LINKS)  # the picture


@pytest.mark.parametrize("target", LINKS)
def test_a_relative_link_resolves(target):
    path_text, _, anchor = target.partition("#")
    path = ROOT / unquote(path_text) if path_text else ROOT / "README.md"
    assert path.exists(), f"{target}: no such file or folder"
    if anchor:
        assert path.suffix == ".md", f"{target}: an anchor into a file that is not Markdown"
        assert anchor in _anchors(path), f"{target}: no heading with that anchor"


def test_github_anchors():
    assert github_anchor("The demo") == "the-demo"
    assert github_anchor("Action `~/compute_workspace`") == "action-compute_workspace"
    assert github_anchor("Cost and scaling (`python benchmarks/atlas.py`)") == (
        "cost-and-scaling-python-benchmarksatlaspy"
    )
