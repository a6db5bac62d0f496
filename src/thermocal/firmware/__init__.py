"""Flight-controller thermal calibration maths: pure functions from arrays to the
coefficients PX4 and ArduPilot take, and the table of their parameter dialects.

==========  ==========================================================================
formats     the firmware dialects (:data:`~thermocal.firmware.formats.FORMATS`)
binning     temperature bins (medians of 0.5 °C bins) and the hold-out split
px4         :func:`~thermocal.firmware.px4.px4_coefficients` (``TC_*``)
ardupilot   :func:`~thermocal.firmware.ardupilot.ardupilot_coefficients` (``INS_TCAL*``)
learning    the firmware's own learning emulated on a log's samples:
            :func:`~thermocal.firmware.learning.ardupilot_learning`,
            :func:`~thermocal.firmware.learning.px4_oncal`
==========  ==========================================================================
"""

from thermocal.firmware.ardupilot import ArdupilotFit, ardupilot_coefficients
from thermocal.firmware.formats import FORMATS, FirmwareFormat, firmware_format
from thermocal.firmware.px4 import Px4Fit, px4_coefficients

__all__ = [
    "FORMATS",
    "ArdupilotFit",
    "FirmwareFormat",
    "Px4Fit",
    "ardupilot_coefficients",
    "firmware_format",
    "px4_coefficients",
]
