"""White balance from the landmarks themselves: their white bodies are the one surface known to be neutral.

Grey-world (:func:`.color.grey_world_gains`) assumes the frame's near-neutral
surfaces average to grey. A muted red wall or a brown floor filling most of
the view breaks that: the gains neutralise the wall (R × 0.6, B × 1.45) and
turn the white body blue, so the structure search sees no white between the
bands. A partly corrected tungsten or LED light breaks the camera's own
balance the other way. Neither can be told from the other by frame
statistics, but both leave a landmark findable under one of the two. So:

1. search under the grey-world gains and, when they are not near one, also
   under the camera's own balance (unit gains); keep every landmark either
   search finds (:func:`merge_candidates`). Under a strong cast search
   :func:`halfway` between them as well: in a room of one colour (a blue wall
   over a navy carpet) the camera leaves the wall blue, so every blue band
   merges with it, and grey-world makes it grey, which turns the white bodies
   orange; half the correction takes the wall out of the blue class and
   leaves the bodies white (and a camera that corrected half of a tungsten
   cast is right there);
2. measure with the gains that make the found landmarks' white bodies
   neutral (:func:`white_body_gains`): it is the light *on the landmarks*
   that decides their band colours, not the frame's average.
"""

from __future__ import annotations

from typing import Callable, List, Optional, Sequence, Tuple, Union

import numpy as np

from .color import CLIPPED, DARK, UNIT_GAINS, Gains
from .denoise import Box
from .limbs import at_frame_edges, cut_sides
from .stats import median_rows
from .structure import Candidate, Found, one_run

NEAR_UNIT = 0.05  # gains within 5 % of one: the two searches would find the same landmarks
TALLER = 1.15  # of one landmark found twice, a white body this much taller is the landmark's whole
STRONG_CAST = 0.15  # a gain more than 15 % from one: the halfway balance is searched too
MIN_WHITE_PX = 12  # unclipped, not dark pixels of white body needed for a landmark to vote
SAMPLES = 16  # rows and columns sampled per white body (the median needs no more)
WHOLE = 0.9  # a second-look candidate cut on both sides shows both limbs of a band: as wide as a silhouette


def near_unit(gains: Gains, tol: float = NEAR_UNIT) -> bool:
    """Whether every gain is within ``tol`` of one."""
    return all(abs(g - 1.0) <= tol for g in gains)


def _same(a: Candidate, b: Candidate) -> bool:
    """Whether two candidates are one landmark: their columns and their whole red-top-to-blue-bottom
    spans each share more than half of the smaller one's.

    The two searches can place one landmark's bands a row or two apart (a band's rim pixels are in
    one class under one balance and not under the other), so its red boxes alone may overlap by
    less than half. Two landmarks never share most of their columns: the nearer one hides the
    other there (a robot's body standing under a landmark spans other rows).
    """
    return _share(_cols(a), _cols(b)) and _share(_span(a), _span(b))


def _cols(c: Candidate) -> Tuple[int, int]:
    return c.red_bbox_px[0], c.red_bbox_px[0] + c.red_bbox_px[2]


def _span(c: Candidate) -> Tuple[int, int]:
    return c.red_bbox_px[1], c.blue_bbox_px[1] + c.blue_bbox_px[3]


def _share(a: Tuple[int, int], b: Tuple[int, int]) -> bool:
    """Whether the intervals ``[a0, a1)`` and ``[b0, b1)`` share more than half of the shorter one."""
    return 2 * (min(a[1], b[1]) - max(a[0], b[0])) > min(a[1] - a[0], b[1] - b[0])


def merge_candidates(first: Sequence[Candidate], more: Sequence[Candidate], max_landmarks: int) -> List[Candidate]:
    """``first``, then those of ``more`` that are no landmark of ``first``, at most ``max_landmarks`` in all.

    Where both searches found one landmark, the one with the clearly taller white body stays: under
    one balance a mast or flag in front of the body may leave only a smaller red–white–blue piece of
    it (its band's rim pixels in or out of a class), read as a landmark twice as far. A landmark
    clearly taller than each of several of ``first`` it shares most of its place with replaces them
    all: being nearer it hides whatever lies there, so they are pieces of it (its robot's red top
    plate over a pale bumper, a speck of edge noise in its band).
    """
    out = list(first[:max_landmarks])
    for c in more:
        same = [k for k, o in enumerate(out) if _same(c, o)]
        if not same and len(out) < max_landmarks:
            out.append(c)
        elif same and all(c.white_px > TALLER * out[k].white_px for k in same):
            out[same[0]] = c
            out = [o for k, o in enumerate(out) if k not in same[1:]]
    return out


def _body_sample(bgr: np.ndarray, c: Candidate) -> Optional[np.ndarray]:
    """The pixels :func:`white_body_colour` samples of a candidate's white body (a strided view), or ``None``."""
    rx, ry, rw, rh = c.red_bbox_px
    top, bottom = ry + rh, c.blue_bbox_px[1]
    h, w = bottom - top, rw
    if h < 3 or w < 2:
        return None
    y0, y1 = top + h // 6, bottom - h // 6
    x0, x1 = rx + w // 4, rx + w - w // 4
    y0, y1, x0, x1 = max(0, y0), min(bgr.shape[0], y1), max(0, x0), min(bgr.shape[1], x1)
    if y1 <= y0 or x1 <= x0:
        return None
    sy, sx = max(1, (y1 - y0) // SAMPLES), max(1, (x1 - x0) // SAMPLES)
    return bgr[y0:y1:sy, x0:x1:sx]


def white_body_colour(bgr: np.ndarray, c: Candidate) -> Optional[np.ndarray]:
    """Median (B, G, R) of a candidate's white body, or ``None`` when too little of it is usable.

    The inner half of its columns (limbs are shaded and mixed with the
    background) and the middle two thirds of the rows between the bands; clipped
    pixels (a channel ≥ 250: the ratio is lost) and dark ones (max < 20) are
    left out. The median ignores a flag or mast in front of part of the body.
    """
    return _body_colours(bgr, [c])[0]


def _body_colours(bgr: np.ndarray, cands: Sequence[Candidate]) -> List[Optional[np.ndarray]]:
    """:func:`white_body_colour` of every candidate, the usable pixels of all picked in one go."""
    samples = [_body_sample(bgr, c) for c in cands]
    live = [s.reshape(-1, 3) for s in samples if s is not None]
    if not live:
        return [None] * len(samples)
    px = live[0] if len(live) == 1 else np.concatenate(live)
    # the channels' maximum pairwise: numpy's reduction over a length-3 axis is ~10x slower
    top_ch = np.maximum(np.maximum(px[:, 0], px[:, 1]), px[:, 2])
    usable = (top_ch >= DARK) & (top_ch < CLIPPED)
    ends = np.cumsum([len(s) for s in live])
    kept = np.cumsum(usable)[ends - 1].tolist()  # usable pixels up to each sample's end
    px = np.compress(usable, px, axis=0)  # = px[usable], in order: each sample's pixels stay together
    out: List[Optional[np.ndarray]] = []
    j, start = 0, 0
    for s in samples:
        if s is None:
            out.append(None)
            continue
        stop = kept[j]
        j += 1
        out.append(median_rows(px[start:stop]) if stop - start >= MIN_WHITE_PX else None)
        start = stop
    return out


def white_body_gains(bgr: np.ndarray, cands: Sequence[Candidate], limit: float = 2.0) -> Optional[Gains]:
    """Gains ``(g_b, g_g, g_r)`` that make the candidates' white bodies grey; ``None`` without a usable one.

    Parameters
    ----------
    bgr : (H, W, 3) uint8
        The full-resolution frame the candidates' boxes refer to.
    cands : sequence of Candidate
        Landmarks found by the structure search.
    limit : float
        Gains are clipped to ``[1/limit, limit]``, as grey-world's are.

    Notes
    -----
    Each landmark's white body gives its median colour (:func:`white_body_colour`);
    the median over landmarks is made grey at its own mean level. A false
    candidate's "white body" (a pale bumper, a wall) is near-neutral too, and
    one landmark out of three cannot move a median.
    """
    colours = [col for col in _body_colours(bgr, cands) if col is not None]
    if not colours:
        return None
    # np.median's value by a partial sort (core/stats.py): np.median imports numpy.ma at a process's first call
    mean = np.maximum(median_rows(np.asarray(colours, np.float64)), 1.0)
    gains = np.clip(mean.mean() / mean, 1.0 / limit, limit)
    return tuple(float(g) for g in gains)  # type: ignore[return-value]


def balanced_search(
    find: Callable[[Gains], Union[List[Candidate], Found]], bgr: np.ndarray, gains: Gains, max_landmarks: int,
    relaxed: Optional[Callable[[Gains, List[Box]], Union[List[Candidate], Found]]] = None,
) -> Tuple[List[Candidate], Gains]:
    """Candidates under the grey-world ``gains`` and, unless those are near one, under unit gains too
    (under a strong cast also :func:`halfway` between them); and the gains to measure them with:
    their white bodies', else ``gains``.

    ``find(gains)`` is the structure search of this frame (BGR or YUV path): its candidates, or a
    :class:`.structure.Found`. When the grey-world search found landmarks that explain every red and
    blue region it saw, the other balances are not searched: what they could add is a landmark
    whose bands are among those regions (its body not white under these gains, a smaller piece of it
    found, a neighbour merged with it), and there is none. A frame with nothing found, or with
    band-coloured things no candidate explains, is searched under every balance as before.

    ``relaxed(gains, boxes)``, when given, is the same search with the lower colour floors of
    :func:`.color.relaxed_floors`, blind inside the ``(x0, y0, x1, y1)`` boxes of the landmarks
    found: its landmarks are added where :func:`second_look` allows, and the gains stay those of
    the landmarks found without it.
    """
    first = find(gains)
    cands = first.candidates if isinstance(first, Found) else first
    # judged only when another balance would be searched (near one it would not)
    done = isinstance(first, Found) and bool(cands) and not near_unit(gains) and first.explained()
    if not near_unit(gains) and not done:
        cands = merge_candidates(cands, _candidates(find(UNIT_GAINS)), max_landmarks)
    if not near_unit(gains, STRONG_CAST) and not done:
        cands = merge_candidates(cands, _candidates(find(halfway(gains))), max_landmarks)
    measured = white_body_gains(bgr, cands) or gains
    if relaxed is not None and len(cands) < max_landmarks:
        more = _candidates(relaxed(gains, [_box(c) for c in cands]))
        cands = cands + second_look(cands, more, bgr.shape[1])[: max_landmarks - len(cands)]
    return cands, measured


def second_look(found: Sequence[Candidate], more: Sequence[Candidate], frame_w_px: Optional[int] = None
                ) -> List[Candidate]:
    """The candidates of a search with lower colour floors (``more``) that are landmarks the
    searches at the normal floors missed: wholly apart from every one of ``found``, and ending in
    a limb on at least one side.

    Another camera's bands may fall under the class floors: a frame 1–2 stops under (white
    bodies at V 20–40, bands at V 15–25), another maker's paler paint, chroma coded in 2×2
    blocks. Lower floors frame-wide move the rims of every landmark found at the normal ones
    (their boxes, cut flags and measured rows) and let in stripes: so a landmark found without
    them keeps what the normal search made of it, and what the second look adds must not touch
    it (its red-top-to-blue-bottom box overlaps none). A background's stripes (an orange brick
    wall over a white skirting board over a blue floor, a dark skirting board read as a pale
    blue band) run on beyond both sides of whatever the search cuts out of them: a candidate cut
    on both sides is no second-look landmark, though a real one between two neighbours may be.
    The frame's edge (``frame_w_px`` wide) shows no limb either: a stripe running out of the frame
    is cut there (:func:`.limbs.cut_sides`). A run several silhouettes wide is split into pieces of one
    size (:mod:`.structure`: the same rows, side by side, cut where they meet): a piece between two
    shows no limb, and the pieces at the run's ends go with it (:func:`_pieces_of`): a wide can's
    limbs are its ends', not a landmark's.
    """
    boxes = [_box(c) for c in found]
    no_limb = [c for c in more if not _limb_shown(c, frame_w_px)]
    dropped = _pieces_of(no_limb, more)
    return [c for c in more if not any(c is d for d in dropped) and not any(_meet(_box(c), b) for b in boxes)]


def _pieces_of(seeds: Sequence[Candidate], cands: Sequence[Candidate]) -> List[Candidate]:
    """``seeds`` and every one of ``cands`` split from one run with one of them: a chain of pieces whose
    rows and white body are the same and whose columns meet, cut where they do."""
    out, todo = list(seeds), list(seeds)
    while todo:
        a = todo.pop()
        for b in cands:
            if not any(b is o for o in out) and _split_beside(a, b):
                out.append(b)
                todo.append(b)
    return out


def _split_beside(a: Candidate, b: Candidate) -> bool:
    """Whether ``a`` and ``b`` are neighbouring pieces of one split run."""
    if not one_run(a, b):
        return False
    ax, aw, bx, bw = a.red_bbox_px[0], a.red_bbox_px[2], b.red_bbox_px[0], b.red_bbox_px[2]
    return (ax + aw == bx and a.cut_right and b.cut_left) or (bx + bw == ax and b.cut_right and a.cut_left)


def _limb_shown(c: Candidate, frame_w_px: Optional[int]) -> bool:
    """Whether a second-look candidate shows the cylinder's outline: a side where neither band runs on, or,
    inside the frame, on each side one band that ends (a landmark before a wall of its other band's colour:
    the red bands before a blue wall end at the limbs; a background's stripes run on in both colours)."""
    if not all(cut_sides(c, frame_w_px) if frame_w_px else (c.cut_left, c.cut_right)):
        return True
    inside = not frame_w_px or not any(at_frame_edges(c, frame_w_px))
    return inside and all(c.band_ends) and c.visible >= WHOLE  # both limbs of a band: the whole silhouette


def _box(c: Candidate) -> Box:
    """``(x0, y0, x1, y1)`` of a candidate from its red band's top to its blue band's bottom."""
    x, y, w, _ = c.red_bbox_px
    bx, by, bw, bh = c.blue_bbox_px
    return min(x, bx), y, max(x + w, bx + bw), by + bh


def _meet(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _candidates(found: Union[List[Candidate], Found]) -> List[Candidate]:
    return found.candidates if isinstance(found, Found) else found


def halfway(gains: Gains) -> Gains:
    """The gains halfway (geometrically) between the camera's balance and ``gains``: half the correction."""
    return tuple(float(np.sqrt(g)) for g in gains)  # type: ignore[return-value]
