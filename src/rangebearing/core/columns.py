"""The structure search's column scan: per column of a pair window, the red-bottom and blue-top edges
with white between them, gaps bridged, and runs of continuous edges (see :mod:`.structure`).

Columns are independent, so every pair window of a frame is scanned in one stacked array
(:func:`window_runs`): a frame's scan is a handful of array calls however many pairs it has.
"""

from __future__ import annotations

import itertools
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

WHITE_SHARE = 0.6  # share of the rows between the edges that must be white
EDGE_STEP = 1  # largest jump of an edge between neighbouring columns (plus 5 % of h)
BRIDGE = 2  # columns of a gap bridged between agreeing edges
WHITE_S_MAX, WHITE_V_MIN = 80, 40  # the white body: low saturation, not dark
TOP_TOL = 0.2  # a pair this much less white than a column's whitest still wins when it is above it


def _nonzero(a: np.ndarray) -> np.ndarray:
    """``np.flatnonzero(a)`` without its two Python wrappers (it runs a dozen times per window stack)."""
    return a.ravel().nonzero()[0]


def column_edges(red: np.ndarray, blue: np.ndarray, white: np.ndarray) -> Tuple[np.ndarray, ...]:
    """Per column of a window: ``(ok, y1, y2, run_r, run_b)``.

    ``y1`` is the last red row above the blue-top row ``y2``, with at least
    ``WHITE_SHARE`` of the rows between them white; of several such pairs in a
    column, the top-most of those within ``TOP_TOL`` of the whitest wins: a
    landmark stands above its robot, whose red top plate, pale bumper and blue
    floor (or mat) make a pair as white as the landmark's own. ``run_r``/``run_b`` are the
    lengths of the red run ending at ``y1`` and the blue run starting at ``y2``.
    Where no pair qualifies ``ok`` is False, ``y1`` −1 and ``y2`` 0.
    """
    return scan_columns(np.ascontiguousarray(red.T), np.ascontiguousarray(blue.T), np.ascontiguousarray(white.T))


def scan_columns(red: np.ndarray, blue: np.ndarray, white: np.ndarray) -> Tuple[np.ndarray, ...]:
    """:func:`column_edges` of (W, H) bool arrays, one row per image column (C order).

    The work is on the few colour changes of each column, not on its pixels:
    red bottoms, red tops, blue tops and blue bottoms are found once, flattened
    in column order, and each blue top is joined to the red bottom above it by
    a binary search, so a window costs some twenty array calls whatever its size.
    """
    w, h = red.shape
    base = np.arange(w, dtype=np.int64) * h  # flat index of each column's row 0
    # each edge is one comparison of neighbouring rows (True > False: set here, clear in the next row)
    edge = np.empty_like(red)
    np.greater(red[:, :-1], red[:, 1:], out=edge[:, :-1])
    edge[:, -1] = False
    red_bottoms = _nonzero(edge)
    np.greater(red[:, 1:], red[:, :-1], out=edge[:, 1:])
    edge[:, 0] = red[:, 0]
    red_tops = _nonzero(edge)
    np.greater(blue[:, 1:], blue[:, :-1], out=edge[:, 1:])
    edge[:, 0] = False
    tops = _nonzero(edge)
    np.greater(blue[:, :-1], blue[:, 1:], out=edge[:, :-1])
    edge[:, -1] = blue[:, -1]
    blue_bottoms = _nonzero(edge)
    col = tops // h
    # the last red bottom above each blue top, in its column (else none: -1)
    k = red_bottoms.searchsorted(tops) - 1
    above = red_bottoms[np.maximum(k, 0)] if len(red_bottoms) else np.zeros(len(tops), np.int64)
    has = (k >= 0) & (above >= base[col])
    row = tops - base[col]
    y1 = np.where(has, above - base[col], -1)
    gap = row - y1 - 1
    cum_w = white.reshape(-1).cumsum(dtype=np.int32)
    whites = cum_w[tops - 1] - cum_w[np.where(has, above, 0)]  # white rows strictly between y1 and the top
    valid = has & (gap >= 2) & (whites >= WHITE_SHARE * gap)
    share = whites / np.maximum(gap, 1)
    ok = np.zeros(w, bool)
    y2 = np.zeros(w, np.int64)
    b1 = np.full(w, -1, np.int64)
    v = _nonzero(valid)
    if len(v):
        best = np.full(w, -1.0)
        np.maximum.at(best, col[v], share[v])
        v = v[share[v] >= best[col[v]] - TOP_TOL]  # tops are in column, then row order: the first is the top-most
        cv = col[v]
        first = np.ones(len(v), bool)
        first[1:] = cv[1:] != cv[:-1]
        v, cv = v[first], cv[first]
        ok[cv], y2[cv], b1[cv] = True, row[v], y1[v]
    # red run ending at y1 (start: the last red top at or above it); without a pair, as at y1 = -1 → row 0
    run_r = np.where(red[:, 0], 0, -1)
    if ok.any():
        c = _nonzero(ok)
        q = base[c] + b1[c]
        run_r[c] = q - red_tops[red_tops.searchsorted(q, side="right") - 1] + 1
    # blue run starting at y2 (end: the first blue bottom at or below it); without a pair, from row 0
    start = base + y2
    run_b = np.zeros(w, np.int64)
    in_blue = blue.reshape(-1)[start]
    if in_blue.any():
        c = _nonzero(in_blue)
        run_b[c] = blue_bottoms[blue_bottoms.searchsorted(start[c])] - start[c] + 1
    return ok, b1, y2, run_r, run_b


def bridge(
    ok: np.ndarray, y1: np.ndarray, y2: np.ndarray, starts: Sequence[int] = ()
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fill gaps of up to ``BRIDGE`` columns between columns whose edges agree, and take the median
    of three neighbours, so sensor noise neither breaks one structure into pieces nor jitters its edges.

    ``starts``: where further windows begin when several are side by side in one array
    (:func:`window_runs`); nothing is bridged or smoothed across them.
    """
    ok, y1, y2 = ok.copy(), y1.astype(np.float64), y2.astype(np.float64)
    n = len(ok)
    seg = None  # each column's window, when there are several (one window: none to compare)
    if len(starts):
        seg = np.zeros(n, np.int64)
        seg[np.asarray(starts, np.int64)] = 1
        seg = seg.cumsum()
    idx = _nonzero(ok)
    d = idx[1:] - idx[:-1]
    near = (d > 1) & (d <= BRIDGE + 1)
    gaps = _nonzero(near if seg is None else near & (seg[idx[1:]] == seg[idx[:-1]]))  # usually none
    for g in gaps.tolist():
        a, b = idx[g], idx[g + 1]
        if abs(y1[a] - y1[b]) <= 1 and abs(y2[a] - y2[b]) <= 1:
            ok[a + 1 : b] = True
            y1[a + 1 : b], y2[a + 1 : b] = y1[a], y2[a]
    if n >= 3:
        inner = None if seg is None else (seg[:-2] == seg[1:-1]) & (seg[2:] == seg[1:-1])  # neighbours in its window
        for y in (y1, y2):
            a, b, c = y[:-2], y[1:-1], y[2:]
            med = np.maximum(np.minimum(a, b), np.minimum(np.maximum(a, b), c))
            y[1:-1] = med if inner is None else np.where(inner, med, b)
    return ok, y1, y2


def runs(ok: np.ndarray, y1: np.ndarray, y2: np.ndarray, starts: Sequence[int] = ()) -> List[Tuple[int, int]]:
    """``[start, stop)`` column ranges where the edges continue from column to column (none across
    the window ``starts`` of :func:`bridge`)."""
    step = EDGE_STEP + 0.05 * (y2 - y1)
    jump = np.zeros(len(ok), bool)
    jump[1:] = (np.abs(y1[1:] - y1[:-1]) > step[1:]) | (np.abs(y2[1:] - y2[:-1]) > step[1:])  # np.diff's values
    prev_ok = np.concatenate(([False], ok[:-1]))
    next_ok = np.concatenate((ok[1:], [False]))
    if len(starts):
        b = np.asarray(starts, np.int64)
        prev_ok[b] = False
        next_ok[b - 1] = False
    next_jump = np.concatenate((jump[1:], [True]))
    first = _nonzero(ok & (~prev_ok | jump))
    stops = _nonzero(ok & (~next_ok | next_jump)) + 1
    return list(zip(first.tolist(), stops.tolist()))


Window = Tuple[int, int, int, int]  # y0, y1, x0, x1 of a pair's window in the masks
RunStats = Tuple[int, int, float, float, float, float, float]  # s0, s1 and the run's medians (see window_runs)
Split = Callable[[List[Tuple[int, int]], np.ndarray, np.ndarray, np.ndarray, np.ndarray], List[Tuple[int, int]]]
STACK_WASTE = 4  # a window joins a stack of taller ones while it is at least 1/STACK_WASTE of their height


def window_runs(red: np.ndarray, blue: np.ndarray, hsv, wins: Sequence[Window],
                split: Optional[Split] = None, white_v_min: int = WHITE_V_MIN) -> List[List[RunStats]]:
    """The runs of every pair window, searched together.

    The windows are put side by side, top-aligned, into a few stacked arrays
    (columns are independent in :func:`column_edges`, and the empty rows padded
    below a window change none of its columns), so a frame's column search is a
    handful of array calls however many pairs it has. Windows of very different
    heights go into different stacks, so padding never costs much.

    Returns, per window, ``(s0, s1, gap, run_r, run_b, y1, y2)`` per run: its
    columns ``[s0, s1)`` in the window and the medians over them of the white gap
    ``y2 − y1 − 1``, the red and blue run lengths and the (bridged, smoothed)
    edges, window rows.

    ``split(runs, e1, e2, run_r, run_b)`` may cut the runs further on their
    per-column edges and band runs (:func:`.fragments.split_runs`). ``white_v_min``: the
    white body's least V (a second look at a dark frame takes less, see :mod:`.balance`).
    """
    out: List[List[RunStats]] = [[] for _ in wins]
    heights = [w[1] - w[0] for w in wins]
    order = sorted(range(len(wins)), key=lambda k: -heights[k])
    while order:
        top = heights[order[0]]
        batch = [k for k in order if heights[k] * STACK_WASTE >= top]
        order = [k for k in order if heights[k] * STACK_WASTE < top]
        widths = [wins[k][3] - wins[k][2] for k in batch]
        offs = np.array([0, *itertools.accumulate(widths)], np.int64)
        if len(batch) == 1:  # a window of its own: its masks transposed, nothing padded
            y0, y1, x0, x1 = wins[batch[0]]
            sv = hsv[slice(y0, y1), slice(x0, x1)]
            white = np.ascontiguousarray(((sv[..., 1] < WHITE_S_MAX) & (sv[..., 2] >= white_v_min)).T)
            r = np.ascontiguousarray(red[y0:y1, x0:x1].T)
            b = np.ascontiguousarray(blue[y0:y1, x0:x1].T)
        else:
            r = np.zeros((int(offs[-1]), top), np.uint8)  # one row per window column (see scan_columns)
            b = np.zeros_like(r)
            sv = np.zeros((*r.shape, 2), np.uint8)  # padding: no colour, V = 0 is not white
            for k, o, w in zip(batch, offs.tolist(), widths):
                y0, y1, x0, x1 = wins[k]
                h = y1 - y0
                r[o : o + w, :h] = red[y0:y1, x0:x1].T
                b[o : o + w, :h] = blue[y0:y1, x0:x1].T
                sv[o : o + w, :h] = hsv[slice(y0, y1), slice(x0, x1)][..., 1:].transpose(1, 0, 2)
            white = (sv[..., 0] < WHITE_S_MAX) & (sv[..., 1] >= white_v_min)
        ok, e1, e2, run_r, run_b = scan_columns(r > 0, b > 0, white)
        starts = offs[1:-1]
        ok, e1, e2 = bridge(ok, e1, e2, starts)
        found = runs(ok, e1, e2, starts)
        if split is not None:  # runs never cross a window start, so neither do their pieces
            found = split(found, e1, e2, run_r, run_b)
        if not found:
            continue
        s0 = np.array([f[0] for f in found], np.int64)
        s1 = np.array([f[1] for f in found], np.int64)
        med = _run_medians(np.stack((e2 - e1 - 1, run_r, run_b, e1, e2)), s0, s1)
        owner = offs.searchsorted(s0, side="right") - 1
        for q, (a, z, w_k) in enumerate(zip(s0.tolist(), s1.tolist(), owner.tolist())):
            o = int(offs[w_k])
            out[batch[w_k]].append((a - o, z - o, *(float(v) for v in med[:, q])))
    return out


def _run_medians(values: np.ndarray, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
    """(K, R) medians of each of K value rows over each run's columns ``[s0, s1)`` (``np.median``'s values)."""
    n = s1 - s0
    if len(n) == 1 and s1[0] > s0[0]:  # one run (the common case): its columns are one slice
        a, z = int(s0[0]), int(s1[0])
        v = np.sort(values[:, a:z].astype(np.float64), axis=1)
        lo, hi = (z - a - 1) // 2, (z - a) // 2
        return 0.5 * (v[:, lo : lo + 1] + v[:, hi : hi + 1])
    cols = s0[:, None] + np.arange(int(n.max()))[None, :]
    inside = cols < s1[:, None]
    v = np.where(inside[None], values[:, np.minimum(cols, values.shape[1] - 1)].astype(np.float64), np.inf)
    v.sort(axis=2)
    lo, hi = (n - 1) // 2, n // 2
    k = np.arange(len(n))
    return 0.5 * (v[:, k, lo] + v[:, k, hi])  # odd n: lo = hi, the middle value itself
