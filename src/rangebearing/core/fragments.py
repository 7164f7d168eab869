"""A landmark's columns made whole: runs split where the white body's height steps, fragments joined
across what hides the body, and structures whose "white body" is darker than their bands dropped
(see :mod:`.structure`).

Two things make a run of continuous edges not one landmark:

* **A nearer landmark beside or in front of a farther one** at nearly the same image height. After
  blur their edges differ by a pixel or two and change over a few columns, so no single column
  jumps. Their white bodies' heights (their ranges) differ: the run is split where the edges
  step, when it is too wide for the taller body and the taller piece is a whole silhouette (the
  landmark in front is seen whole).
* **Something thin in front of the white body** (a robot's own camera on its mast, a neighbour's
  mast): the columns behind it are not red→white→blue and the landmark falls apart into
  fragments too narrow to report, often in different region pairs (the mast cuts the blue band's
  region in two). Its bands run on behind the obstacle at the same rows: fragments whose edges
  agree are joined when the bands continue across the gap and the whole is at most one
  silhouette wide; fragments that overlap or touch with agreeing edges are one structure found
  in two windows and are joined whatever their width.

Coordinates are the downscaled masks' pixels.
"""

from __future__ import annotations

from typing import List, Sequence, Tuple

import numpy as np

from .stats import median

STEP_PX = 1.5  # an edge or white height that differs by this much between two pieces is another landmark
MIN_PIECE = 2  # columns of the narrowest piece a run is split into
MIN_SHARE = 0.15  # share of a silhouette each fragment joined across a gap must show
WHOLE_TOL = 0.3  # the taller piece of a split must be within this share of one silhouette
WIDE = 1.1  # a run wider than this many silhouettes of its taller part is examined for a step
JOIN_TOL = 0.3  # fragments joined across a gap make at most 1 + JOIN_TOL silhouettes
TRIM_WIDE, TRIM_KEEP = 1.1, 0.7  # a fragment this much too wide gives up a neighbour's columns if this much is left
BRIDGE = 2  # columns between two pieces that need no look at the bands (as the column scan bridges)
BAND_SHARE = 0.75  # share of the gap's columns where a band must continue (the obstacle may cross the other)

BODY_V_SHARE = 0.7  # the white body's V (upper quartile) over the bands' median (white paint is brighter, lit alike)
BODY_PCT = 0.75

# (c0, c1, y1, y2, gap, run_r, run_b): columns [c0, c1), median inner edges y1 (red bottom) and
# y2 (blue top), white height gap = y2 − y1 − 1, median band runs
Fragment = Tuple[float, float, float, float, float, float, float]


def height_steps(e1: np.ndarray, e2: np.ndarray, width_k: float, depth: int = 2) -> List[Tuple[int, int]]:
    """``[start, stop)`` pieces of one run (per-column edges ``e1``, ``e2``) with one landmark each."""
    n = len(e1)
    g = e2 - e1 - 1.0
    if depth == 0 or n < 2 * MIN_PIECE or n <= WIDE * width_k * float(np.max(g)):
        return [(0, n)]
    # the split that best explains both edges by two levels (CUSUM of the edges)
    c = np.arange(MIN_PIECE, n - MIN_PIECE + 1)
    score = np.zeros(len(c))
    for e in (e1, e2):
        cs = np.concatenate(([0.0], np.cumsum(e)))
        left, right = cs[c] / c, (cs[n] - cs[c]) / (n - c)
        score += c * (n - c) / n * (left - right) ** 2
    k = int(c[int(np.argmax(score))])
    gl, gr = float(median(g[:k])), float(median(g[k:]))
    steps = (abs(gl - gr), abs(median(e1[:k]) - median(e1[k:])),
             abs(median(e2[:k]) - median(e2[k:])))
    tall, (t0, t1) = (gl, (0, k)) if gl >= gr else (gr, (k, n))
    if n <= WIDE * width_k * tall or max(steps) < STEP_PX:
        return [(0, n)]
    if abs((t1 - t0) / (width_k * tall) - 1.0) > WHOLE_TOL:  # the one in front must be seen whole
        return [(0, n)]
    left = height_steps(e1[:k], e2[:k], width_k, depth - 1)
    right = height_steps(e1[k:], e2[k:], width_k, depth - 1)
    return left + [(a + k, b + k) for a, b in right]


def split_runs(
    found: Sequence[Tuple[int, int]], e1: np.ndarray, e2: np.ndarray, run_r: np.ndarray, run_b: np.ndarray,
    band_k: float, width_k: float, merged_k: float,
) -> List[Tuple[int, int]]:
    """The runs ``found`` (``[start, stop)`` over per-column edges and band runs) cut by :func:`height_steps`.

    A run whose band merged with a same-coloured background (runs on past ``merged_k`` band heights)
    is split as any other: the steps are in its inner edges, which stay sharp (two landmarks side by
    side before a red wall); the band runs ``run_r``/``run_b`` and ``band_k``/``merged_k`` are the
    column scan's call (:func:`.columns.window_runs`) and decide nothing here. Only runs wider than
    ``WIDE`` silhouettes of their tallest column are looked at (few are).
    """
    if not found:
        return []
    s0 = np.fromiter((f[0] for f in found), np.int64, len(found))
    s1 = np.fromiter((f[1] for f in found), np.int64, len(found))
    g = e2 - e1 - 1.0
    inside = np.zeros(len(g) + 1, np.int64)
    np.add.at(inside, s0, 1)
    np.add.at(inside, s1, -1)
    tallest = np.maximum.reduceat(np.where(np.cumsum(inside[:-1]) > 0, g, -np.inf), s0)
    wide = (s1 - s0 >= 2 * MIN_PIECE) & (s1 - s0 > WIDE * width_k * tallest)
    if not wide.any():
        return list(found)
    out: List[Tuple[int, int]] = []
    for (r0, r1), look in zip(found, wide.tolist()):
        if not look:
            out.append((r0, r1))
            continue
        out.extend((r0 + a, r0 + b) for a, b in height_steps(e1[r0:r1], e2[r0:r1], width_k))
    return out


def _band_share(mask: np.ndarray, rows: Tuple[int, int], c0: int, c1: int) -> float:
    """Share of columns ``[c0, c1)`` where ``mask`` is mostly set in ``rows``."""
    r0, r1 = max(0, rows[0]), max(0, min(mask.shape[0], rows[1]))
    if r1 <= r0 or c1 <= c0:
        return 0.0
    seg = mask[r0:r1, c0:c1] > 0
    return float(np.mean(seg.mean(axis=0) > 0.5))


def join_fragments(
    frags: Sequence[Fragment], red: np.ndarray, blue: np.ndarray, band_k: float, width_k: float
) -> List[Fragment]:
    """Fragments of one landmark joined (see the module notes), in the order of their first member."""
    if len(frags) < 2:
        return list(frags)
    f = np.asarray(frags, np.float64)
    c0, c1, y1, y2, g = f[:, 0], f[:, 1], f[:, 2], f[:, 3], f[:, 4]
    tol = 1.5 + 0.05 * np.maximum(g[:, None], g[None, :])
    agree = (np.abs(y1[:, None] - y1[None, :]) <= tol) & (np.abs(y2[:, None] - y2[None, :]) <= tol)
    np.fill_diagonal(agree, False)
    parent = list(range(len(f)))
    t0, t1 = c0.copy(), c1.copy()  # a fragment's columns after giving up those of a neighbour it overlaps

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in zip(*np.nonzero(np.triu(agree))):
        a, b = (i, j) if c0[i] <= c0[j] else (j, i)
        lo, hi = int(c1[a]), int(c0[b])
        shared = min(c1[a], c1[b]) - c0[b]
        if shared < 0.5 * min(c1[a] - c0[a], c1[b] - c0[b]):  # not one structure seen in two windows
            h = max(g[a], g[b])
            if max(c1[a], c1[b]) - c0[a] > (1 + JOIN_TOL) * width_k * h:
                continue
            if hi > lo + BRIDGE:  # a gap: the bands must run on behind whatever hides the body
                least = max(MIN_PIECE, MIN_SHARE * width_k * h)  # a column or two of edge noise counts for nothing
                if min(c1[a] - c0[a], c1[b] - c0[b]) < least:
                    continue
                inside = np.minimum(c1, hi) - np.maximum(c0, lo)
                if np.any(~agree[a] & (inside >= least) & (inside >= 0.5 * (c1 - c0))):
                    continue  # another structure's columns fill the gap: no obstacle hides this one there
                hb = max(1, round(0.5 * band_k * h))
                ye1, ye2 = round(0.5 * (y1[a] + y1[b])), round(0.5 * (y2[a] + y2[b]))
                if max(_band_share(red, (ye1 - hb + 1, ye1 + 1), lo, hi),
                       _band_share(blue, (ye2, ye2 + hb), lo, hi)) < BAND_SHARE:
                    continue
        else:  # overlapping: one structure in two windows, unless together they add up to too wide a one
            whole = max(c1[a], c1[b]) - c0[a]
            if whole > max(c1[a] - c0[a], c1[b] - c0[b]) + 1 and whole > (1 + JOIN_TOL) * width_k * max(g[a], g[b]):
                # two landmarks side by side whose edges agree within a pixel or two (e.g. 1.1 and 1.4 m): the
                # shared columns are the narrower one's when the wider is too wide for its own white body
                wide = a if c1[a] - c0[a] > c1[b] - c0[b] else b
                sil = width_k * g[wide]
                if (c1[wide] - c0[wide]) > TRIM_WIDE * sil and (c1[wide] - c0[wide] - shared) >= TRIM_KEEP * sil:
                    if wide == a:
                        t1[a] = min(t1[a], c0[b])
                    else:
                        t0[b] = max(t0[b], c1[a])
                continue
        parent[root(int(i))] = root(int(j))
    groups: dict = {}
    for i in range(len(f)):
        groups.setdefault(root(i), []).append(i)
    out = []
    for members in sorted(groups.values(), key=min):
        if len(members) == 1:
            k = members[0]
            out.append((float(t0[k]), float(t1[k]), *frags[k][2:]))
            continue
        m = f[members]
        lo, hi = t0[members], t1[members]
        widest = m[int(np.argmax(hi - lo))]
        out.append((float(lo.min()), float(hi.max()), *map(float, widest[2:])))
    return out  # type: ignore[return-value]


def lit_like_bands(hsv: np.ndarray, c0: int, c1: int, rrows: Tuple[int, int], brows: Tuple[int, int]) -> bool:
    """Whether the body between a structure's bands (columns ``[c0, c1)``) is as bright as a white
    body beside them: white paint is at least as bright as the bands' brightest channel in any
    light, so a dark robot chassis or shadow between a red box and a blue mat is no white body. The
    body's level is its upper quartile: something in front of it (its own camera) darkens only a part.

    ``hsv`` is indexed once, with two slices (it may convert only that window)."""
    top = max(0, rrows[0])
    v = hsv[top : max(top, brows[1]), c0:c1][..., 2]
    body = v[rrows[1] - top : brows[0] - top]
    bands = np.concatenate((v[: rrows[1] - top].ravel(), v[brows[0] - top :].ravel()))
    if body.size == 0 or bands.size == 0:
        return True
    # the body's upper quartile: a robot's own camera board in front of it darkens only a part
    flat = body.ravel()
    k = int(BODY_PCT * (flat.size - 1))
    return float(np.partition(flat, k)[k]) >= BODY_V_SHARE * median(bands)


EXTEND_MAX = 1.2  # an extended landmark spans at most this many silhouettes (an off-axis outline is wider)
EXTEND_BLUE = 0.5  # share of the extension's columns where the blue band must show (a bracket hides a sliver)
ABOVE_RED = 0.25  # share of red pixels in the two band heights above the band that makes it no band of its own
LIMB_PX = 1  # columns between the two bands' ends at a limb
HIDDEN_SHARE = 0.05  # a band seen in this much less of the columns than the other is partly hidden: no column cue


def _band_columns(mask: np.ndarray, rows: Tuple[int, int], c0: int, c1: int) -> np.ndarray:
    """Per column of ``[c0, c1)`` (clipped to the mask): whether ``mask`` is mostly set in ``rows``."""
    r0, r1 = max(0, rows[0]), max(0, min(mask.shape[0], rows[1]))
    c0, c1 = max(0, c0), min(mask.shape[1], c1)
    if r1 <= r0 or c1 <= c0:
        return np.zeros(0, bool)
    return (mask[r0:r1, c0:c1] > 0).mean(axis=0) > 0.5


def _reach(cols: np.ndarray) -> int:
    """How many leading columns of ``cols`` are set, gaps of up to ``BRIDGE`` bridged (-1: it never stops)."""
    last, miss = -1, 0
    for k, on in enumerate(cols.tolist()):
        if on:
            last, miss = k, 0
        else:
            miss += 1
            if miss > BRIDGE:
                return last + 1
    return -1


def extend_along_bands(
    frag: Fragment, red: np.ndarray, blue: np.ndarray, band_k: float, width_k: float
) -> Tuple[float, float, float, str, bool, bool]:
    """A fragment narrower than a silhouette, extended along its bands where something hides its white body.

    A robot's own camera board in front of a near landmark's white body (and its bracket over a
    sliver of the blue band) leaves only a piece of the body red→white→blue, but both bands run on
    at their rows, behind the board, to the cylinder's limb. On each side the red band is followed
    until it ends; the extension stands when it ends within ``EXTEND_MAX`` silhouettes (a red wall
    or a neighbour's band at the same rows runs on: no landmark's limb), the blue band shows in
    ``EXTEND_BLUE`` of the added columns and the red band has a top: little red in the two band
    heights above it (a red wall seen between two masts has none, a brick wall's courses come back
    above a mortar line; the column scan's window may have cut their runs short).

    Returns ``(c0, c1, seen, hidden, cut_left, cut_right)``: the extended columns, the share of the
    silhouette's area seen (both bands where they show, the white body over the fragment's columns
    only), the band seen in fewer columns (``"red"``/``"blue"``, else ``""``: its moments are pulled
    off the axis by what hides it) and, per side, whether the extension ends elsewhere than at a limb
    (the blue band ends more than ``LIMB_PX`` from the red one: the camera board hides the red band's
    end, or the mast the blue one's); the fragment's own columns, 1, ``""`` and no cut when nothing
    extends.
    """
    c0, c1, y1, y2, g = frag[0], frag[1], frag[2], frag[3], frag[4]
    a, z = int(c0), int(c1)
    hb = max(1, round(band_k * g))
    rrows = (round(y1 - hb + 1), int(y1) + 1)
    brows = (int(y2), round(y2 + hb))
    cap = int(EXTEND_MAX * width_k * g) - (z - a)
    if cap <= 0 or z - a < MIN_SHARE * width_k * g:  # a column or two of edge noise is extended to nothing
        return c0, c1, 1.0, "", False, False
    right = _band_columns(red, rrows, z, z + cap + BRIDGE + 1)
    left = _band_columns(red, rrows, a - cap - BRIDGE - 1, a)[::-1]
    out = [a, z]
    cut = [False, False]
    for side, cols in ((1, right), (0, left)):
        n = _reach(cols)
        if n <= 0 or n > cap:  # no band beyond, or no limb within reach (a wall, a neighbour, the frame's edge)
            continue
        lo, hi = (z, z + n) if side else (a - n, a)
        if _band_columns(blue, brows, lo, hi).mean() < EXTEND_BLUE:
            continue
        out[side] = hi if side else lo
        # a limb ends both bands at one column; where they end apart something hides the red band's end
        if side:
            on = np.flatnonzero(_band_columns(blue, brows, lo, hi + LIMB_PX + 1))
        else:
            on = np.flatnonzero(_band_columns(blue, brows, lo - LIMB_PX - 1, hi)[::-1])
        reach_b = int(on[-1]) + 1 if len(on) else 0
        cut[side] = abs(reach_b - n) > LIMB_PX
    e0, e1 = out
    if (e0, e1) == (a, z):
        return c0, c1, 1.0, "", False, False
    r0, r1 = max(0, round(y1 - 3 * hb)), max(0, round(y1 - 1.3 * hb))
    if r1 > r0 and (red[r0:r1, e0:e1] > 0).mean() >= ABOVE_RED:  # red above the band too: a red (brick) wall
        return c0, c1, 1.0, "", False, False
    seen_r = _band_columns(red, rrows, e0, e1)
    seen_b = _band_columns(blue, brows, e0, e1)
    seen_r[a - e0 : z - e0] = seen_b[a - e0 : z - e0] = True
    share_r, share_b = float(seen_r.mean()), float(seen_b.mean())
    # the silhouette's area seen: both bands where they show, the white body over the fragment only
    seen = (band_k * (share_r + share_b) + (z - a) / (e1 - e0)) / (2 * band_k + 1)
    hidden = "" if abs(share_r - share_b) <= HIDDEN_SHARE else "blue" if share_b < share_r else "red"
    return float(e0), float(e1), float(seen), hidden, cut[0], cut[1]
