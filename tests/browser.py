"""Headless Chromium for the tests of `fivebar view` (and benchmarks/bench_view.py).

Chromium is driven through its command line, no extra package: `--dump-dom` prints the DOM once
the page has loaded (the page paints synchronously while loading, then sets data-ready, data-cells
and data-paint-ms on <body>), `--screenshot` writes a PNG. The flags keep it off the network
(no background requests, component updates or sync) and out of the user's profile.

Where Chromium is missing the browser tests skip with the reason, except when the environment
variable CI is set: then they fail (`make install` installs Debian's chromium where apt-get is
available).
"""

from __future__ import annotations

import html
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

NAMES = ("chromium", "chromium-browser", "google-chrome")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-extensions", "--disable-default-apps", "--mute-audio", "--hide-scrollbars")
TIMEOUT = 120
BODY = re.compile(r"<body([^>]*)>")
ATTRIBUTE = re.compile(r'([\w-]+)="([^"]*)"')


def find_chromium() -> str | None:
    """The Chromium executable: $FIVEBAR_CHROMIUM, else the first of NAMES on PATH."""
    chosen = os.environ.get("FIVEBAR_CHROMIUM")
    if chosen:
        return chosen
    for name in NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


def require_chromium() -> str:
    """The executable, or skip the test (fail it when CI is set)."""
    import pytest

    path = find_chromium()
    if path is None:
        reason = ("headless Chromium not found (install Debian's chromium: `make install` does it where "
                  "apt-get is available, or set FIVEBAR_CHROMIUM)")
        if os.environ.get("CI"):
            pytest.fail(reason + "; CI is set, so the browser tests fail instead of skipping")
        pytest.skip(reason)
    return path


def _run(chromium: str, args: list[str]) -> str:
    with tempfile.TemporaryDirectory(prefix="fivebar-chromium-") as profile:
        env = dict(os.environ, HOME=profile)
        result = subprocess.run([chromium, *FLAGS, f"--user-data-dir={profile}", *args], capture_output=True,
                                text=True, timeout=TIMEOUT, env=env, stdin=subprocess.DEVNULL)
    if result.returncode != 0:
        raise AssertionError(f"chromium exited with {result.returncode}: {result.stderr[-2000:]}")
    return result.stdout


def body_attributes(chromium: str, page: Path, fragment: str = "", budget_ms: int = 200,
                    size: tuple[int, int] = (1200, 800), png: Path | None = None) -> dict[str, str]:
    """The attributes of <body> once the page has loaded (and `budget_ms` of virtual time passed);
    with `png`, the same run also writes a screenshot of that state there (read it with `image`):
    one Chromium start instead of two."""
    url = page.resolve().as_uri() + (f"#{fragment}" if fragment else "")
    shot = [f"--screenshot={png}"] if png is not None else []
    dom = _run(chromium, [f"--virtual-time-budget={budget_ms}", f"--window-size={size[0]},{size[1]}",
                          "--dump-dom", *shot, url])
    match = BODY.search(dom)
    assert match, f"no <body> in the dumped DOM: {dom[:500]!r}"
    return {k: html.unescape(v) for k, v in ATTRIBUTE.findall(match.group(1))}


def image(png: Path) -> np.ndarray:
    """A screenshot Chromium wrote, as an RGB array of shape (height, width, 3), values 0..1."""
    from matplotlib.image import imread

    assert png.is_file(), "chromium wrote no screenshot"
    return imread(png)[..., :3]


def not_blank(image: np.ndarray) -> tuple[float, int]:
    """(share of pixels that are not white, number of distinct colours) of a screenshot."""
    pixels = np.round(image.reshape(-1, 3) * 255).astype(np.int32)
    coloured = float(np.mean(pixels.min(axis=1) < 245))
    distinct = len(np.unique(pixels[:, 0] << 16 | pixels[:, 1] << 8 | pixels[:, 2]))
    return coloured, distinct
