"""The batched column scatter against the band-by-band one (edges._column_sigma)."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing.core.column_scatter import ALONE, FEW_COLUMNS_SIGMA, column_sigmas
from rangebearing.core.edges import _column_sigma


def _band_tile(rng: np.random.Generator, n: int, m: int, down: bool) -> np.ndarray:
    """A band's excess tile: a step from the band level to the white body's, its row wobbling per column."""
    edge = n / 2 + 0.8 * np.sin(np.arange(m) / 3.0) + rng.normal(0, 0.3, m)
    rows = np.arange(n)[:, None]
    inside = rows < edge[None, :] if down else rows >= edge[None, :]
    tile = np.where(inside, 0.4, 0.02) + rng.normal(0, 0.01, (n, m))
    return (tile * rng.uniform(0.7, 1.0, m)[None, :]).astype(np.float32)  # shading across the cylinder


def _frame(rng: np.random.Generator, bands: int):
    """Two stacks (red, blue) of tiles one below the other and a spec per band, some at their tile's ends."""
    stacks, specs = [[], []], []
    offs = [0, 0]
    width = 40
    for b in range(bands):
        k = b % 2
        n, m = int(rng.integers(12, 40)), int(rng.integers(3, width + 1))
        down = k == 0
        tile = _band_tile(rng, n, m, down)
        mid = int(rng.integers(0, n // 2)) if down else int(rng.integers(n // 2, n))
        end = min(n - 1, mid + int(rng.integers(1, 12))) if down else max(0, mid - int(rng.integers(1, 12)))
        if b % 5 == 1:  # the middle row at the tile's first or last row, the end at the other
            mid, end = (0, n - 1) if down else (n - 1, 0)
        level, bg = float(rng.uniform(0.2, 0.45)), float(rng.uniform(0.0, 0.1))
        if b % 7 == 3:  # no column shows the step
            level, bg = 2.0, 0.0
        padded = np.zeros((n, width), np.float32)
        padded[:, :m] = tile
        stacks[k].append(padded)
        specs.append((k, offs[k], n, m, level, bg, mid, end, down))
        offs[k] += n
    full = [np.concatenate(s) if s else np.zeros((1, width), np.float32) for s in stacks]
    return full, specs


@pytest.mark.parametrize("seed", range(12))
def test_batch_matches_band_by_band(seed: int) -> None:
    rng = np.random.default_rng(seed)
    stacks, specs = _frame(rng, 3 + seed)
    batch = column_sigmas(stacks, specs)
    alone = [_column_sigma(stacks[k][o : o + n, :m], lv, bg, mid, end, down)
             for k, o, n, m, lv, bg, mid, end, down in specs]
    assert len(batch) == len(alone)
    for b, a in zip(batch, alone):
        if a == FEW_COLUMNS_SIGMA:  # the same columns take part (a float32 decision, bit for bit)
            assert b == FEW_COLUMNS_SIGMA
        else:
            assert b == pytest.approx(a, rel=1e-4, abs=1e-6)  # float64 sums against float32 ones
    assert any(a != FEW_COLUMNS_SIGMA for a in alone)


def test_one_landmark_is_measured_band_by_band_exactly() -> None:
    rng = np.random.default_rng(5)
    stacks, specs = _frame(rng, ALONE)
    alone = [_column_sigma(stacks[k][o : o + n, :m], lv, bg, mid, end, down)
             for k, o, n, m, lv, bg, mid, end, down in specs]
    assert column_sigmas(stacks, specs) == alone
    assert column_sigmas(stacks, []) == []


def test_scatter_grows_with_the_edges_noise() -> None:
    """A sanity check on the fit itself: noisier per-column edges give a larger sigma, a smooth arc none."""
    width, n = 30, 24
    x = np.arange(width)
    sig = []
    for noise in (0.0, 0.5, 1.5):
        rng = np.random.default_rng(1)
        edge = 10.0 + 0.01 * (x - 15.0) ** 2 + rng.normal(0, noise, width) * (noise > 0)
        rows = np.arange(n)[:, None]
        # a linear ramp one row wide at the edge: the two-level integral reads it exactly
        tile = np.clip(edge[None, :] - rows + 0.5, 0.0, 1.0).astype(np.float32)
        stacks = [np.tile(tile, (3, 1)), np.zeros((1, width), np.float32)]
        specs = [(0, q * n, n, width, 1.0, 0.0, 2, 20, True) for q in range(3)]
        sig.append(column_sigmas(stacks, specs)[0])
    assert sig[0] < 1e-3 < sig[1] < sig[2]
