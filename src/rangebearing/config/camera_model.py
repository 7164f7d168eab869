"""``camera.model``: intrinsics from a Raspberry Pi camera preset, under any explicit ``camera.*`` keys.

``camera.model`` names a preset of :mod:`rangebearing.core.camera_models`
(``custom``, the default, means none); the intrinsics are worked out for
``camera.width_px × camera.height_px`` (default: the source's size) and the
crop the frames come from: ``camera.scaler_crop`` (libcamera's ``ScalerCrop``,
as ``rangebearing tune`` prints it) or, failing that, the largest centred window
of ``camera.sensor_crop`` (the sensor mode's ``crop_limits``) with the output's
aspect ratio. Explicit ``fx_px``, ``fy_px``, ``cx_px``, ``cy_px`` and
``distortion`` still override the preset's values. A written config holds the
resolved numbers.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Dict, List, Mapping, Optional, Tuple

from ..core.camera_models import MODELS, preset_intrinsics
from ..core.types import CameraIntrinsics
from . import checks as ck

PRESET_KEYS = ("model", "sensor_crop", "scaler_crop")


def rect(v: Any) -> Tuple[int, int, int, int]:
    if not isinstance(v, (list, tuple)) or len(v) != 4:
        raise ValueError(f"expected [x, y, width, height] in full-resolution sensor pixels, got {v!r}")
    x, y, w, h = (ck.number(0, 100000, integer=True)(c) for c in v)
    if w <= 0 or h <= 0:
        raise ValueError(f"width and height must be > 0, got {v!r}")
    return (x, y, w, h)


def _size(raw: Mapping[str, Any], source: Any, base: CameraIntrinsics, key: str) -> Optional[int]:
    for where in (raw, source if isinstance(source, Mapping) else {}):
        if key in where:
            try:
                return ck.positive(True)(where[key])
            except (TypeError, ValueError):
                return None  # reported by the per-key checks
    return getattr(base, key)


def split_camera(
    raw: Mapping[str, Any], source: Any, base: CameraIntrinsics, problems: List[str]
) -> Tuple[CameraIntrinsics, Dict[str, Any]]:
    """The camera a preset gives (or ``base``) and the remaining explicit ``camera.*`` keys to apply over it."""
    rest = {k: v for k, v in raw.items() if k not in PRESET_KEYS}
    crops: Dict[str, Any] = {}
    for key in ("sensor_crop", "scaler_crop"):
        if raw.get(key) is not None:
            try:
                crops[key] = rect(raw[key])
            except (TypeError, ValueError) as exc:
                problems.append(f"camera.{key}: {exc}")
    model = raw.get("model", "custom")
    try:
        model = ck.choice(*MODELS)(model)
    except ValueError as exc:
        problems.append(f"camera.model: {exc}")
        return base, rest
    if model == "custom":
        if crops:
            problems.append("camera.sensor_crop/scaler_crop: need a camera.model preset (they are ignored otherwise)")
        return base, rest
    w, h = _size(raw, source, base, "width_px"), _size(raw, source, base, "height_px")
    if w is None or h is None:
        return base, rest
    try:
        cam = preset_intrinsics(model, w, h, crops.get("scaler_crop"), crops.get("sensor_crop"))
    except ValueError as exc:
        problems.append(f"camera.{'scaler_crop' if 'scaler_crop' in crops else 'sensor_crop'}: {exc}")
        return base, rest
    return dataclasses.replace(cam, distortion=base.distortion), rest
