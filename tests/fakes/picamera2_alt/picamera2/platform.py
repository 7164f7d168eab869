"""Which ISP the board has (picamera2/platform.py): VC4 on Pi 4 and earlier, PiSP on Pi 5."""

from enum import Enum


class Platform(Enum):
    VC4 = 0
    PISP = 1


def get_platform() -> Platform:
    import picamera2_alt_rig

    return Platform.PISP if picamera2_alt_rig.RIG.platform == "pisp" else Platform.VC4
