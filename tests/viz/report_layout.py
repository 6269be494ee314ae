"""Layout measurements of the HTML report in a real browser (playwright + Debian's Chromium).

:func:`measure` returns what issue 19 asks of the report as a decision tool: the page height, the
widest table as shown (a table inside a horizontal scroll container counts as wide as the
container) against the width of the text column, the page's bytes and the share of them that are
inline animation frames, and where the regime map sits.  The browser test asserts on it; run this
module as a script to measure a real report:
``python tests/viz/report_layout.py REPORT/index.html`` (``OPEN_DETAILS=1``: with every
``<details>`` unfolded).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
from pathlib import Path
from typing import Any

CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: the viewport of every measurement [CSS px]
VIEWPORT = {"width": 1280, "height": 900}

_JS = """() => {
  const body = document.body, cs = getComputedStyle(body);
  const column = body.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight);
  const shown = t => {
    let w = t.getBoundingClientRect().width;
    for (let e = t.parentElement; e && e !== body; e = e.parentElement) {
      const o = getComputedStyle(e).overflowX;
      if (o === 'auto' || o === 'scroll' || o === 'hidden') {
        w = Math.min(w, e.getBoundingClientRect().width); break; }
    }
    return w;
  };
  const tables = Array.from(document.querySelectorAll('table'));
  const map = document.getElementById('regime-map');
  return {
    page_height: document.documentElement.scrollHeight,
    column_width: column,
    widest_table_shown: Math.max(0, ...tables.map(shown)),
    widest_table_natural: Math.max(0, ...tables.map(t => t.scrollWidth)),
    tables: tables.length,
    tallest_visible_table: Math.max(0, ...tables.filter(t => t.checkVisibility())
      .map(t => t.getBoundingClientRect().height)),
    page_overflow_x: document.documentElement.scrollWidth - document.documentElement.clientWidth,
    plotly_divs_at_load: document.querySelectorAll('.js-plotly-plot').length,
    regime_map_top: map ? map.getBoundingClientRect().top + window.scrollY : null,
  };
}"""


def chromium() -> str | None:
    """Debian's Chromium on the PATH (``None`` when absent)."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


def inline_animation_bytes(index: Path) -> int:
    """Bytes of the page source inside its inline animation sections (``<section
    class="animation">`` ... ``</section>``, the frames carried by the page itself; a ``lazy``
    section holds only the button that loads its side file)."""
    text = Path(index).read_bytes()
    pattern = rb'<section class="animation">.*?</section>'
    return sum(len(m) for m in re.findall(pattern, text, re.S))


def measure(page: Any, index: Path) -> dict[str, Any]:
    """The layout figures of ``index`` (already loaded in ``page``); bytes from the file."""
    out: dict[str, Any] = page.evaluate(_JS)
    size = Path(index).stat().st_size
    out["page_bytes"] = size
    out["inline_animation_bytes"] = inline_animation_bytes(index)
    out["animation_share"] = out["inline_animation_bytes"] / size if size else 0.0
    return out


def main(argv: list[str]) -> int:
    from playwright.sync_api import sync_playwright

    index = Path(argv[0]).resolve()
    exe = chromium()
    if exe is None:
        print("no chromium on PATH", file=sys.stderr)
        return 2
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport=VIEWPORT)
            page.goto(index.as_uri(), wait_until="load")
            page.wait_for_timeout(int(os.environ.get("SETTLE_MS", "1500")))
            if os.environ.get("OPEN_DETAILS"):  # every folded table unfolded
                page.evaluate("() => document.querySelectorAll('details').forEach(d => d.open = 1)")
            print(json.dumps(measure(page, index), indent=1))
        finally:
            browser.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
