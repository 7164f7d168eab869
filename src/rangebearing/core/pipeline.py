"""The pipeline: one BGR frame in, every landmark's range and bearing out.

:class:`Pipeline` is pure apart from its own state: when tracking it keeps the
previous frame's landmarks and measures them again in small windows where they
should be (:mod:`rangebearing.core.tracking`), with a full-frame search every
``full_scan_interval_s`` of capture time (or ``full_scan_every`` frames; :func:`.scans.scan_due`),
after a landmark is lost, and whenever nothing is tracked, so a newcomer is found within that.

Every landmark of a sequence also gets a stable ``track_id`` and, once its
track has history, range and bearing rates (:mod:`rangebearing.core.identity`,
run after measurement on the landmarks themselves, whether they were found by
a full scan or in tracking windows).
"""

from __future__ import annotations

import dataclasses
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from .balance import balanced_search
from .color import UNIT_GAINS, Gains, grey_world_gains
from .denoise import Box, band_preserving_ksize
from .detect import BandCentroids, detect_paper, downscale, refine, search_candidates
from .hidden import Hidden, still_hidden, tracks_of
from .identity import IdentityState, empty_state, update
from .limbs import cut_sides
from .model import in_envelope, reading, view_edges_rad
from .newcomers import NEW_COLUMNS, SideCounts, SideView, beside_count, came_in, side_view
from .pairing import PairingLimits
from .params import PipelineParams
from .refine import Pyramid
from .scans import Cadence, crossing, periodic, rescanned, scan_due
from .search_image import SearchImage
from .stacked import drop_stacked
from .structure import Found
from .tracking import Track, step
from .types import CameraIntrinsics, FrameResult, Landmark, check_frame
from .uncertainty import chroma_blur_all, chroma_blur_px, reading_sigma, white_clipped
from .verify import verified
from .yuv import Yuv420, half_luma, yuv_grey_world_gains, yuv_search

SEARCH_RANGE_M = 2.2  # the farthest landmark the full-frame search must keep (issue 8: at least 2 m)
# no reading beyond this: the search is built for landmarks out to SEARCH_RANGE_M, and a red-white-blue
# structure far smaller than that landmark is sensor noise or texture more often than a landmark
MAX_RANGE_M = 1.25 * SEARCH_RANGE_M


class Pipeline:
    """Range and bearing to every landmark in a frame.

    Parameters
    ----------
    params : PipelineParams
        Camera intrinsics, landmark geometry, detection settings and model
        (``Config.pipeline`` of a loaded config).
    track : bool, optional
        Search only around last frame's landmarks between full-frame scans.
        ``None`` takes ``params.detection.tracking``. Use ``False`` for frames
        that are not a sequence.
    ids : bool, optional
        Give every landmark a track id and rates. ``None``: unless ``track``
        is ``False`` (independent frames), so a sequence gets ids even with
        window tracking switched off in the config.
    first_track_id : int
        The id of the first track (a daemon that rebuilds its pipeline on a
        config reload passes the old pipeline's :attr:`next_track_id`, so no
        id is reused within its run).
    """

    def __init__(self, params: PipelineParams, track: Optional[bool] = None, ids: Optional[bool] = None,
                 first_track_id: int = 0) -> None:
        if not isinstance(params, PipelineParams):
            raise TypeError(f"Pipeline takes PipelineParams (a config's .pipeline), not {type(params).__name__}")
        self.params = params
        self.track = params.detection.tracking if track is None else track
        self.ids = (track is not False) if ids is None else ids
        self.limits = PairingLimits()
        self._cams: Dict[Tuple[int, int], Tuple[CameraIntrinsics, int]] = {}
        self._views: Dict[Tuple[int, int], Tuple[float, float]] = {}
        self._identity: IdentityState = empty_state(first_track_id)
        self.reset()

    @property
    def next_track_id(self) -> int:
        """The id the next new track will get."""
        return self._identity.next_id

    def reset(self, new_run: bool = False) -> None:
        """Forget tracked landmarks; the next frame gets a full-frame search.

        Track ids keep counting, so none is reused for the pipeline's lifetime;
        ``new_run=True`` starts them again at 0, for frames that have nothing
        to do with the earlier ones (another recording).
        """
        self._tracks: List[Track] = []
        self._lost: List[Track] = []  # tracks the last (tracked) frame lost
        self._hidden: List[Hidden] = []
        self._cadence = Cadence()
        self._sides: SideCounts = (0, 0)
        self._side_view: Optional[SideView] = None  # the strips' counts as last classified (core/newcomers.py)
        self._beside = 0  # landmark-like columns beside the tracks at the last full scan (newcomers.beside_count)
        self._gains: Gains = UNIT_GAINS
        self._identity = empty_state(0 if new_run else self._identity.next_id)
        self._size: Optional[Tuple[int, int]] = None  # the frame size the tracks were found in

    def _camera(self, w: int, h: int) -> Tuple[CameraIntrinsics, int]:
        """Intrinsics for this frame size and the band-preserving filter size."""
        key = (w, h)
        if key not in self._cams:
            cam = self.params.camera.for_frame(w, h)
            # the envelope only flags readings: the filter keeps bands out to SEARCH_RANGE_M whatever calibrate wrote
            band_px = cam.fy_px * self.params.landmark.band_height_m / SEARCH_RANGE_M / self.params.detection.downscale
            self._cams[key] = (cam, band_preserving_ksize(self.params.detection.median_ksize, band_px))
            self._views[key] = view_edges_rad(cam)  # the identity filter holds tracks that leave the view there
        return self._cams[key]

    def process(
        self, frame: np.ndarray, t_s: Optional[float] = None, search: Optional[Yuv420] = None
    ) -> FrameResult:
        """Find every landmark in a BGR uint8 frame; nearest first.

        ``t_s`` is the frame's capture time in seconds on any steady clock
        (the daemon passes the camera's timestamp); it sets the time step of
        the rate filters. Without it frames are taken to be 1/30 s apart.

        ``search`` is the same view as a YUV420 image of the frame's size (the
        camera's lores stream, :mod:`.yuv`): a full scan then looks for bands on
        its chroma planes instead of downscaling and converting the frame, and
        measures them on ``frame`` as always. Without it (or with another size,
        or ``downscale`` other than 2) the frame is searched itself.

        Raises
        ------
        FrameError
            The frame is not a non-empty H×W×3 uint8 array.
        """
        bgr = check_frame(frame)
        h, w = bgr.shape[:2]
        if (w, h) != self._size:  # another frame size (a camera reconfigured, mixed recordings): tracks start again
            self.reset()
            self._size = (w, h)
        cam, ksize = self._camera(w, h)
        det = self.params.detection
        tracked = False
        if det.method == "paper":
            found = detect_paper(bgr, det)
        else:
            tracking = self.track and self._tracks and not self._scan_due(t_s)
            # landmarks crossing, one coming out from behind another, or one coming into view: a full scan
            if (tracking and not crossing([*self._tracks, *tracks_of(self._hidden)])
                    and not came_in(self._sides_now(bgr), self._sides)):
                kept, lost = step(bgr, self._tracks, det, self._gains, self.params.landmark, self.limits, cam.fy_px)
                # a landmark lost in its window (gone astray, half hidden, changed): this frame is scanned
                # whole, from the tracks as they were, as if its scan had been due; its reading is not missed
                # ... or one came out from behind a followed one (core/newcomers.py): scanned whole, once
                if not lost and self._beside_now(bgr, kept) < self._beside + NEW_COLUMNS:
                    self._tracks, self._lost = kept, lost
                    self._cadence = Cadence(self._cadence.tracked + 1, self._cadence.scan_t_s)
                    found = [t.bands for t in self._tracks]
                    tracked = True
            else:
                lost = []
            if not tracked:
                yuv = search if search is not None and det.downscale == 2 and search.y.shape == (h, w) else None
                small = downscale(bgr, det.downscale) if yuv is None else None
                y_half = half_luma(yuv.y) if yuv is not None else None
                geometry = self.params.landmark

                hsv_of: Dict[Gains, SearchImage] = {}

                def find(gains: Gains, relaxed: Optional[List[Box]] = None) -> Found:
                    if yuv is None:
                        return search_candidates(small, det, gains, ksize, geometry, relaxed, hsv_of)
                    return yuv_search(yuv, det, gains, ksize, geometry, y_half, relaxed)

                if det.white_balance == "grey_world":
                    grey = grey_world_gains(small) if yuv is None else yuv_grey_world_gains(yuv, y_half=y_half)
                    # measured with the gains of the landmarks' own white bodies; a second look at lower
                    # colour floors adds landmarks apart from those (see core/balance.py)
                    cands, self._gains = balanced_search(find, bgr, grey, det.max_landmarks, find)
                else:
                    cands = find(self._gains).candidates
                pyramid = Pyramid(bgr, small if det.downscale == 2 else None)
                found = refine(bgr, cands, det, self._gains, self.params.landmark, cam.fy_px, pyramid)
                # no landmark without a landmark's properties, nor away from where landmarks stand
                found = verified(bgr, found, self.params.landmark, self.params.model, cam)
                found = drop_stacked(found, frame_w=bgr.shape[1])  # nor one standing under another (that robot's body)
                # the colour's blur, of all landmarks at once; tracked frames keep it (see _reading)
                blurs = chroma_blur_all(bgr, [(c.red_xy_px, c.blue_xy_px, c.width_px) for c in found], self._gains)
                found = [dataclasses.replace(c, chroma_blur_px=b) for c, b in zip(found, blurs)]
                if self.track:
                    self._hidden = still_hidden([*self._tracks, *self._lost], self._hidden, found, det.full_scan_every)
                self._tracks = rescanned(self._tracks, found, self._lost) if self.track else []
                self._lost = []
                if self.track:  # what the sides hold now, the landmarks found blanked (core/newcomers.py)
                    self._side_view = None
                    self._sides = self._sides_now(bgr)
                    self._beside = self._beside_now(bgr, self._tracks)
                # what lost a landmark (one passing behind another, coming out) is still under way: the next frame too
                self._cadence = Cadence(0, t_s, forced=bool(lost))
        # a range that is not positive is no landmark (e.g. a calibration with a large negative c, up close),
        # nor is one beyond MAX_RANGE_M
        readings = sorted((r for r in (self._reading(c, cam, bgr) for c in found) if 0 < r[0] <= MAX_RANGE_M),
                          key=_range)
        if not self.ids:
            return FrameResult(landmarks=tuple(Landmark(*r) for r in readings), tracked=tracked)
        # the identity filter's own call (identify() would build every Landmark a second time to add the ids)
        self._identity, out = update(
            self._identity, [r[0] for r in readings], [r[1] for r in readings], [r[10] for r in readings],
            [r[11] for r in readings], t_s, self.params.identity, [r[12] for r in readings],
            view_rad=self._views[(w, h)],
        )
        landmarks = tuple(
            Landmark(*r, int(tid), None if rr != rr else float(rr), None if br != br else float(br))  # NaN: no rate yet
            for r, tid, rr, br in zip(readings, out.track_id.tolist(), out.range_rate_mps.tolist(),
                                      out.bearing_rate_radps.tolist())
        )
        return FrameResult(landmarks=landmarks, tracked=tracked)

    def process_scan_later(
        self, frame: np.ndarray, t_s: Optional[float] = None, search: Optional[Yuv420] = None
    ) -> Tuple[FrameResult, Optional[Callable[[], FrameResult]]]:
        """:meth:`process`, with a periodic full scan left for after this frame's readings are out.

        When the frame's full scan is only the periodic one (tracks followed,
        none lost, none crossing, nothing coming in), the frame is tracked
        like the ones before it, and the returned ``finish`` runs the full
        scan on the same frame from the state before it: after ``finish()``
        the pipeline is exactly as :meth:`process` would have left it, so every
        later frame reads the same. Only this frame's readings differ (they are
        the tracked ones; a newcomer shows one frame later). ``finish`` is None
        when nothing was left over; call it before the next frame (it reads
        ``frame`` and ``search`` again) or never (the next frame is then the
        full scan).
        """
        det = self.params.detection
        due = (self.track and bool(self._tracks) and det.method != "paper" and self._scan_due(t_s)
               and periodic(self._cadence))
        if not due:
            return self.process(frame, t_s, search), None
        before = dict(self.__dict__)  # the state is rebound, never changed in place: a shallow copy keeps it
        self._cadence = dataclasses.replace(self._cadence, held=True)
        result = self.process(frame, t_s, search)
        if not result.tracked:  # a full scan was needed anyway (crossing, a newcomer): done already
            return result, None
        # left unfinished, the scan is the next frame's (never deferred)
        self._cadence = dataclasses.replace(self._cadence, forced=True)
        after = dict(self.__dict__)

        def finish() -> FrameResult:
            self.__dict__.update(before)
            try:
                return self.process(frame, t_s, search)
            except BaseException:
                self.__dict__.update(after)  # as if the scan had never been started
                raise

        return result, finish

    def _scan_due(self, t_s: Optional[float]) -> bool:
        det = self.params.detection
        return scan_due(self._cadence, t_s, det.full_scan_every, det.full_scan_interval_s,
                        self.params.identity.nominal_dt_s)

    def _sides_now(self, bgr: np.ndarray) -> SideCounts:
        """The side strips' landmark-like columns, the followed landmarks blanked; classified again only when
        the strips changed since they last were (:func:`.newcomers.side_view`)."""
        boxes = [t.reach_px for t in self._tracks]
        self._side_view = side_view(bgr, self.params.detection, self._gains, boxes, self._side_view)
        return self._side_view.counts

    def _beside_now(self, bgr: np.ndarray, tracks: Sequence[Track]) -> int:
        """Landmark-like columns right beside ``tracks`` (:func:`.newcomers.beside_count`)."""
        return beside_count(bgr, self.params.detection, self._gains, [t.bands.bbox_px for t in tracks])

    def _reading(self, c: BandCentroids, cam: CameraIntrinsics, bgr: np.ndarray) -> tuple:
        """A :class:`Landmark`'s fields up to ``visible``, in its order (the ids come after)."""
        model = self.params.model
        rng, bearing, d_v, d_h, l_px = reading(c.red_xy_px, c.blue_xy_px, cam, model, self.params.landmark)
        c_m = model.c_m if model.kind == "pinhole" else 0.0
        width_px = c.width_px
        cut = cut_sides(c.candidate, bgr.shape[1]) if c.candidate is not None else (False, False)
        blur_px = c.chroma_blur_px
        if blur_px is None:
            blur_px = chroma_blur_px(bgr, c.red_xy_px, c.blue_xy_px, width_px, self._gains)
        s_r, s_b = reading_sigma(rng, bearing, l_px, c.sigma_l_px, c.sigma_x_px, width_px, c.visible, c_m, cam.fx_px,
                                 c.spread_l_px, 0.5 * abs(c.red_xy_px[0] - c.blue_xy_px[0]), cut, blur_px,
                                 white_clipped(bgr, c.red_xy_px, c.blue_xy_px, width_px))
        return (rng, bearing, d_v, d_h, l_px, c.red_xy_px, c.blue_xy_px, width_px, c.bbox_px,
                in_envelope(rng, bearing, model), s_r, s_b, c.visible)


def _range(r: tuple) -> float:
    return r[0]
