"""Check the built documentation site for what a strict build lets through.

``mkdocs build --strict`` catches broken links and unparsable docstrings, not pages that
build but read wrong. This script reads the built HTML (``python docs/check_site.py site/``,
run by ``.ci/run`` after the build) and fails if:

- an API page has a quote block, or a ``>>>`` line outside a code block: a doctest in a
  docstring section griffe does not parse as examples (``Example:``, a bare ``>>>``
  paragraph) renders its prompts as three nested quote blocks with the lines run together;
  write ``Examples:`` (Google style) instead;
- the theory page has no math element for KaTeX to render, or a page loads a script or
  stylesheet from another host (the site must render without the internet).
"""

from __future__ import annotations

import re
import sys
from html.parser import HTMLParser
from pathlib import Path

#: Pages that must carry math, relative to the site's root.
MATH_PAGES = ("physics/index.html", "dp/index.html")
#: The KaTeX files the pages load, relative to the site's root.
KATEX_FILES = ("assets/katex/katex.min.js", "assets/katex/katex.min.css", "assets/katex/auto-render.min.js")


class _Page(HTMLParser):
    """Counts what the checks need in one HTML page."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.open_tags: list[str] = []
        self.quote_depth = 0
        self.quotes = 0
        self.nested_quotes = 0
        self.prompts_outside_code = 0
        self.math_elements = 0
        self.remote_assets: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attributes = dict(attrs)
        if tag == "blockquote":
            self.quote_depth += 1
            self.quotes += 1
            if self.quote_depth > 1:
                self.nested_quotes += 1
        if "arithmatex" in (attributes.get("class") or "").split():
            self.math_elements += 1
        source = attributes.get("src") if tag == "script" else None
        if tag == "link" and attributes.get("rel") == "stylesheet":
            source = attributes.get("href")
        if source and re.match(r"^(https?:)?//", source):
            self.remote_assets.append(source)
        if tag not in {"br", "img", "hr", "meta", "link", "input", "source", "wbr"}:
            self.open_tags.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if tag == "blockquote":
            self.quote_depth -= 1
        if tag in self.open_tags:
            while self.open_tags.pop() != tag:
                pass

    def handle_data(self, data: str) -> None:
        if ">>>" in data and not {"pre", "code"} & set(self.open_tags):
            self.prompts_outside_code += 1


def read(path: Path) -> _Page:
    """Parse one built page."""
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def problems(site: Path) -> list[str]:
    """Every problem found in the built site at ``site``, as one line each."""
    found = []
    api_pages = sorted((site / "api").rglob("*.html"))
    if not api_pages:
        found.append(f"{site / 'api'}: no API pages; is {site} a built site?")
    for path in api_pages:
        page = read(path)
        name = path.relative_to(site)
        if page.prompts_outside_code:
            found.append(f"{name}: {page.prompts_outside_code} '>>>' example line(s) outside a code block")
        if page.quotes:
            found.append(
                f"{name}: {page.quotes} quote block(s), {page.nested_quotes} of them nested"
                " (a docstring's '>>>' outside an 'Examples:' section?)"
            )
    for relative in MATH_PAGES:
        path = site / relative
        if not path.exists():
            found.append(f"{relative}: missing")
        elif read(path).math_elements == 0:
            found.append(f"{relative}: no math element (class 'arithmatex') to render")
    for relative in KATEX_FILES:
        if not (site / relative).exists():
            found.append(f"{relative}: missing (KaTeX is served from the site itself)")
    for path in sorted(site.rglob("*.html")):
        for source in read(path).remote_assets:
            found.append(f"{path.relative_to(site)}: loads {source} from another host")
    return found


def main(argv: list[str]) -> int:
    """Check the site directory given as the only argument; print problems, return 1 if any."""
    if len(argv) != 1:
        print("usage: python docs/check_site.py SITE_DIR", file=sys.stderr)
        return 2
    found = problems(Path(argv[0]))
    for line in found:
        print(line, file=sys.stderr)
    print(f"check_site: {len(found)} problem(s)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
