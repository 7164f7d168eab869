import dataclasses

import pytest

from rangebearing.core.types import Landmark
from rangebearing.errors import ProtocolError
from rangebearing.net.protocol import decode_reading, encode_reading, landmark_fields

LM = Landmark(0.5, 0.1, 0.497, 0.05, 60.0, (300.0, 200.0), (300.5, 260.0), 40.0, (280, 190, 42, 80), True)


@pytest.mark.parametrize("change", [{"range_m": -0.05}, {"bearing_rad": 4.0}, {"l_px": -1.0}, {"width_px": -2.0}])
def test_the_encoder_refuses_what_a_consumer_would_drop(change):
    with pytest.raises(ProtocolError, match="outside"):
        encode_reading("r", 0, 1.0, [dataclasses.replace(LM, **change)])


def test_replay_records_and_datagrams_share_the_fields():
    fields = landmark_fields(LM)
    got = decode_reading(encode_reading("r", 0, 1.0, [LM])).landmarks[0]
    assert got.range_m == fields["range_m"] and got.bearing_rad == fields["bearing_rad"]
    assert list(got.red_xy_px) == fields["red_px"]
