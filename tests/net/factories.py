"""Landmarks with hand-checkable values for the network tests."""

from __future__ import annotations

from rangebearing.core.types import Landmark


def make_landmark(range_m: float = 0.412, bearing_rad: float = 0.2147, in_envelope: bool = True,
                  x_px: float = 250.25) -> Landmark:
    return Landmark(
        range_m=range_m, bearing_rad=bearing_rad, d_v_m=range_m * 0.98, d_h_m=range_m * 0.21,
        l_px=84.56, red_xy_px=(x_px, 120.5), blue_xy_px=(x_px + 1.0, 205.06), width_px=12.3,
        bbox_px=(int(x_px) - 6, 110, 13, 105), in_envelope=in_envelope,
    )
