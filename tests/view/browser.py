"""Headless Chromium (Debian's ``chromium`` package) driven by Playwright, or a stated reason to skip."""

from __future__ import annotations

import os
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
    required = os.environ.get("RANGEBEARING_REQUIRE_BROWSER") == "1"  # set by .ci/run when it has Chromium
    if path is None:
        if required:
            pytest.fail("RANGEBEARING_REQUIRE_BROWSER=1 but no Chromium found")
        pytest.skip("no Chromium on this machine (apt-get install chromium; .ci/run installs it)")
    try:
        from playwright import sync_api
    except ImportError:
        if required:
            raise
        pytest.skip("playwright is not installed (pip install -e '.[test]')")
    with tempfile.TemporaryDirectory(prefix="rangebearing-chromium-") as profile, sync_api.sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(
            profile, executable_path=path, headless=True, args=CHROMIUM_FLAGS, viewport={"width": 1180, "height": 900}
        )
        try:
            yield ctx
        finally:
            ctx.close()
