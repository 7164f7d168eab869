"""The edges' column scatter (:func:`.edges._column_sigma`) of every band of a frame in one batch.

A full scan measures each band's inner edge column by column and takes the
scatter of those edges about a parabola as the edge's noise (``sigma_l_px``).
Band by band that is some twenty numpy calls on a tile a few dozen columns
wide; here the rows every band needs are gathered from the frame's stacked
tiles at once and the fits run on (bands, columns) arrays, so a frame pays
about forty calls however many bands it has.

The columns that take part and the levels that choose them are those of
:func:`.edges._column_sigma` bit for bit (the same float32 sums); the integrals
and the fit are summed in float64, so a sigma differs from the band-by-band
one only in its last bits (about 1e-7 relative). The residuals' lag-1 correlation
is taken over the columns taking part, packed side by side as the band-by-band
residuals are.
"""

from __future__ import annotations

from typing import List, Sequence, Tuple

import numpy as np

from . import edges
from .edges import BG_ROWS

#: one band: (which stack, its tile's first row in that stack, tile rows, tile columns,
#: band level, background level, middle row, end row of the integral, inner edge below the band)
Scatter = Tuple[int, int, int, int, float, float, int, int, bool]
FEW_COLUMNS_SIGMA = 0.5  # what _column_sigma gives when fewer than 5 columns show the step
_EYE = np.eye(3)
ALONE = 6  # up to this many bands one by one: cold, a batch costs about what seven bands do


def column_sigmas(stacks: Sequence[np.ndarray], specs: Sequence[Scatter]) -> List[float]:
    """:func:`.edges._column_sigma` of every band in ``specs`` (see :data:`Scatter`), the bands' tiles
    lying in ``stacks`` (float32 arrays of one width, tiles one below the other from column 0).

    Up to ``ALONE`` bands (three landmarks) are measured one by one, exactly as :func:`.edges._column_sigma`.
    """
    if len(specs) <= ALONE:
        return [edges._column_sigma(stacks[k][o : o + n, :m], level, bg, mid, end, down)
                for k, o, n, m, level, bg, mid, end, down in specs]
    order = sorted(range(len(specs)), key=lambda j: specs[j][0])  # the bands of each stack together
    t = np.asarray([specs[j] for j in order], np.float64)
    which, o, n, m, mid, end = (t[:, k].astype(np.intp)[:, None] for k in (0, 1, 2, 3, 6, 7))
    down = t[:, 8:9] > 0
    reach = int((np.abs(end - mid) + 1).max())
    # each band's rows: 3 around the middle, BG_ROWS beyond the end, the integral's; those outside it count zero
    lev = mid + np.arange(-1, 2)
    beyond = np.where(down, end, end - BG_ROWS + 1) + np.arange(BG_ROWS)
    lo = np.where(down, mid, end)
    integral = lo + np.arange(reach)
    rows = np.concatenate((lev, beyond, integral), axis=1)
    real = (rows >= 0) & (rows < n)
    real[:, 3 + BG_ROWS :] &= integral <= np.where(down, end, mid)
    idx = o + np.minimum(np.maximum(rows, 0), n - 1)
    g = np.concatenate([stacks[k][idx[which[:, 0] == k]] for k in sorted({s[0] for s in specs})])
    g *= real[:, :, None]  # the rows counting zero add nothing to the sums (x + 0 = x)
    # the means as mean_along takes them: float32 sums in row order, divided by the count
    lev = np.add.reduce(g[:, :3], axis=1)
    lev = np.true_divide(lev, np.add.reduce(real[:, :3], axis=1)[:, None], out=lev, casting="unsafe")
    bgc = np.add.reduce(g[:, 3 : 3 + BG_ROWS], axis=1)
    bgc = np.true_divide(bgc, np.add.reduce(real[:, 3 : 3 + BG_ROWS], axis=1)[:, None], out=bgc, casting="unsafe")
    step = lev - bgc
    width = g.shape[2]
    ok = (step > (0.5 * (t[:, 4:5] - t[:, 5:6])).astype(np.float32)) & (np.arange(width)[None, :] < m)
    cols = np.add.reduce(ok, axis=1)
    w = ok.astype(np.float64)
    s = np.add.reduce(g[:, 3 + BG_ROWS :] - bgc[:, None, :] * real[:, 3 + BG_ROWS :, None], axis=1, dtype=np.float64)
    s = s / np.where(ok, step, np.float32(1.0)) * w  # each column's edge, zero where it takes no part
    # the scatter about a parabola: least squares on (1, x, x²) over the columns taking part, x centred
    count = np.maximum(cols, 1).astype(np.float64)
    x = np.arange(width, dtype=np.float64)[None, :] - (w @ np.arange(width, dtype=np.float64) / count)[:, None]
    wx = w * x
    basis = np.stack((w, wx, wx * x), axis=1)  # (bands, 3, columns)
    gram = basis @ basis.transpose(0, 2, 1)
    gram[cols < 5] = _EYE  # too few columns: no fit (FEW_COLUMNS_SIGMA)
    proj = basis @ s[:, :, None]
    coef = np.linalg.solve(gram, proj)
    rss = np.add.reduce(s * s, axis=1) - np.add.reduce(proj * coef, axis=(1, 2))
    rss = np.maximum(rss, 0.0)
    # the residuals' lag-1 correlation over the columns taking part, next to each other as edges takes them
    res = s - np.add.reduce(basis * coef, axis=1)
    packed = np.zeros_like(res)
    b, c = np.nonzero(ok)
    packed[b, (np.cumsum(ok, axis=1) - 1)[b, c]] = res[b, c]
    lag = np.add.reduce(packed[:, :-1] * packed[:, 1:], axis=1) / np.maximum(np.add.reduce(packed * packed, axis=1),
                                                                             1e-30)
    rho = np.clip(lag, -edges.RHO_MAX, edges.RHO_MAX)
    sigma = np.sqrt(rss / np.maximum(cols - 3, 1) * (1.0 + rho) / (1.0 - rho)) / np.sqrt(count)
    out = [0.0] * len(specs)
    for j, v, c in zip(order, sigma.tolist(), cols.tolist()):
        out[j] = v if c >= 5 else FEW_COLUMNS_SIGMA
    return out
