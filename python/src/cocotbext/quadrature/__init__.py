# SPDX-License-Identifier: Apache-2.0
"""cocotb driver and monitor for quadrature (A/B/Z) encoder signals.

The waveforms come from :mod:`hedsmodel` (ideal walks, glitches, or a physically modelled
HEDS-5000 following a velocity profile); this package plays them onto a DUT and decodes signals
back into a position. See ``QuadratureDriver``, ``QuadratureMonitor``, ``start_clock``, ``reset``;
``SharedVector`` drives one channel each of a multi-channel DUT's vector inputs.
"""

from .clock import reset, start_clock
from .driver import QuadratureDriver, play
from .monitor import QuadratureMonitor
from .vector import SharedVector

__all__ = ["QuadratureDriver", "QuadratureMonitor", "SharedVector", "play", "reset", "start_clock"]
__version__ = "0.1.0"
