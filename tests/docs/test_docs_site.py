"""The documentation site: it builds with no warning, its links lead somewhere, its pages
render in headless Chromium without console errors, and a new pair type documents itself."""

from __future__ import annotations

import html as entities
import json
import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

pytestmark = pytest.mark.slow  # one Sphinx build, about half a minute


def test_builds_without_warnings(site) -> None:
    status, warnings, html = site
    assert status == 0 and warnings == "", warnings
    pages = sorted(p.relative_to(html).as_posix() for p in html.rglob("*.html"))
    for page in ("getting-started.html", "guides/embedded.html", "auto/types/planar-cam.html",
                 "auto/types/spatial-universal.html", "auto/cli.html", "auto/gallery.html",
                 "reference/api.html", "method/equations.html", "topics/index.html"):
        assert page in pages, pages


class _Links(HTMLParser):
    """The href and src of a page, and the ids it defines."""

    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        if found.get("id"):
            self.ids.add(found["id"] or "")
        for key in ("href", "src"):
            if found.get(key):
                self.links.append(found[key] or "")


def _parsed(page: Path) -> _Links:
    parser = _Links()
    parser.feed(page.read_text(encoding="utf-8"))
    return parser


def broken_links(html: Path) -> list[str]:
    """Every internal link or picture whose file, or whose #anchor in it, does not exist."""
    parsed = {page: _parsed(page) for page in html.rglob("*.html")}
    broken = []
    for page, links in parsed.items():
        for link in links.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:")):
                continue
            target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
            if not target.exists():
                broken.append(f"{page.relative_to(html)}: {link}")
            elif parts.fragment and target.suffix == ".html":
                ids = parsed[target].ids if target in parsed else _parsed(target).ids
                if parts.fragment not in ids:
                    broken.append(f"{page.relative_to(html)}: {link} (no such anchor)")
    return broken


def test_internal_links_lead_somewhere(site) -> None:
    _, _, html = site
    assert broken_links(html) == []


def test_a_broken_link_is_seen(site, tmp_path: Path) -> None:
    """The link check can fail: a missing page and a missing anchor are both reported."""
    page = tmp_path / "a.html"
    page.write_text('<a href="b.html#x">b</a><a href="gone.html">c</a><p id="y"></p>')
    (tmp_path / "b.html").write_text('<h1 id="z">b</h1>')
    assert sorted(broken_links(tmp_path)) == ["a.html: b.html#x (no such anchor)",
                                              "a.html: gone.html"]


PAGES = ["index.html", "getting-started.html", "guides/design.html",
         "auto/types/planar-revolute.html", "auto/types/spatial-spherical.html",
         "auto/cli.html", "auto/gallery.html", "reference/api.html", "method/equations.html",
         "search.html"]


PLANTED = "<html><body><script>console.error('planted');undefinedCall();</script></body></html>"
HARNESS = """<html><body>{frames}<script>
window.addEventListener("load", () => {{
  const seen = {{}};
  for (const frame of document.querySelectorAll("iframe")) {{
    const page = frame.contentDocument;
    seen[frame.src] = page !== null && page.readyState === "complete"
                      && page.querySelector(".body") !== null;
  }}
  const out = document.createElement("pre");
  out.id = "laid-out";
  out.textContent = JSON.stringify(seen);
  document.body.appendChild(out);
}});
</script></body></html>"""


@pytest.fixture(scope="module")
def browsed(site, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, bool], list[str]]:
    """Every page of PAGES loaded in one headless Chromium (a launch costs a CPU-second): a
    page of frames holds each at the window's size, and a page that logs an error beside them
    (PLANTED), so that an error in a frame is seen to reach the console lines. Chromium lets
    file pages read each other only with --allow-file-access-from-files: the frames' DOM is
    then read by the holding page, which writes whether the theme laid each out. Returns
    {page URL: laid out} and the console lines."""
    from tests.present.test_present import _browse, _console_lines

    _, _, html = site
    folder = tmp_path_factory.mktemp("browsed")
    (folder / "planted.html").write_text(PLANTED, encoding="utf-8")
    urls = [(html / name).as_uri() for name in PAGES] + [(folder / "planted.html").as_uri()]
    frames = "".join(f'<iframe src="{url}" width="1400" height="900"></iframe>' for url in urls)
    holder = folder / "pages.html"
    holder.write_text(HARNESS.format(frames=frames), encoding="utf-8")
    loaded = _browse(holder, "--allow-file-access-from-files", "--dump-dom")
    assert loaded.returncode == 0, loaded.stderr
    found = re.search(r'<pre id="laid-out">(.*?)</pre>', loaded.stdout, re.S)
    assert found is not None, loaded.stdout[-2000:]
    return json.loads(entities.unescape(found.group(1))), _console_lines(loaded.stderr)


def test_an_error_in_a_browsed_page_is_seen(browsed) -> None:
    """The checks below can fail: the planted page's error reaches the console lines, and the
    planted page, which the theme did not lay out, is not taken for laid out."""
    laid_out, lines = browsed
    assert any("planted" in line and "planted.html" in line for line in lines), lines
    assert [done for url, done in laid_out.items() if url.endswith("/planted.html")] == [False]


@pytest.mark.parametrize("name", PAGES)
def test_page_renders_without_console_errors(site, browsed, name: str) -> None:
    _, _, html = site
    laid_out, lines = browsed
    url = (html / name).as_uri()
    assert laid_out[url]  # the theme laid the page out
    # a line from this page, or from none of the pages (a shared script, the browser), fails
    pages = [(html / other).as_uri() for other in PAGES if other != name]
    own = [line for line in lines if "planted.html" not in line
           and not any(f"source: {other}" in line for other in pages)]
    assert own == [], lines


def test_gallery_shows_each_example_with_its_command(site) -> None:
    _, _, html = site
    text = (html / "auto" / "gallery.html").read_text(encoding="utf-8")
    pictures = re.findall(r'<img alt="([a-z_]+): [^"]*" src="([^"]+)"', text)
    assert [name for name, _ in pictures] == ["crank_slider", "four_bar"], pictures
    words = entities.unescape(re.sub(r"<[^>]+>", "", text))  # the console block is highlighted
    for name, src in pictures:
        assert f"symkin run examples/{name}.yaml --plot {name}.png" in words
        assert (html / "auto" / src).stat().st_size > 10_000  # a figure, not an empty file


def test_a_new_pair_type_documents_itself(site) -> None:
    """A type registered (by the site's fixture, as a module of its own: planted_pair) gets its
    page, with its keys, their roles and defaults, its meaning and equation, and a line in
    the index."""
    status, warnings, html = site
    assert status == 0 and warnings == "", warnings
    page = (html / "auto" / "types" / "planar-tether.html").read_text(encoding="utf-8")
    text = entities.unescape(re.sub(r"<[^>]+>", "", page))
    for key in ("reach", "slack_factor", "sA", "sB"):
        assert key in text, key
    assert "within reach of point B" in text and "|r_B - r_A|^2 - reach^2 = 0" in text
    assert "a constant: an expression of the parameters" in text  # reach's role, registered
    assert "0.5" in text  # slack_factor's default
    index = (html / "auto" / "types" / "index.html").read_text(encoding="utf-8")
    assert 'href="planar-tether.html"' in index
