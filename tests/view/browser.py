"""Headless Chromium (Debian's ``chromium`` package) driven by Playwright, or a stated reason to skip."""

from __future__ import annotations

import shutil
import tempfile
from typing import Iterator, Optional

import pytest

CHROMIUM_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]


def chromium_path() -> Optional[str]:
    for name in ("/usr/bin/chromium", "chromium", "chromium-browser"):
        found = shutil.which(name)
        if found:
            return found
    return None


def browser_context() -> Iterator[object]:
    """A fresh persistent context (its own --user-data-dir) of the system's Chromium; skips without one."""
    path = chromium_path()
    if path is None:
        pytest.skip("no Chromium on this machine (apt-get install chromium; .ci/run installs it)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install '.[test]')")
    with tempfile.TemporaryDirectory(prefix="rangebearing-chromium-") as profile, sync_api.sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(
            profile, executable_path=path, headless=True, args=CHROMIUM_FLAGS, viewport={"width": 1180, "height": 900}
        )
        try:
            yield ctx
        finally:
            ctx.close()
