"""Which addresses count as loopback (anything else gets a warning when the view binds it)."""

from __future__ import annotations

import pytest

from rangebearing.view.app import is_loopback


@pytest.mark.parametrize("host", ["127.0.0.1", "127.0.0.2", "::1", "[::1]", "localhost"])
def test_loopback(host: str) -> None:
    assert is_loopback(host)


@pytest.mark.parametrize("host", ["0.0.0.0", "::", "192.168.1.10", "10.0.0.1"])
def test_not_loopback(host: str) -> None:
    assert not is_loopback(host)
