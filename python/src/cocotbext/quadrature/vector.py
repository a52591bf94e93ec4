# SPDX-License-Identifier: Apache-2.0
"""Drive single bits of a vector input: one encoder channel each of a multi-channel DUT.

cocotb writes a packed vector as a whole, so several drivers sharing ``a_in[CHANNELS-1:0]`` would
overwrite each other's bits. :class:`SharedVector` keeps the vector's value and hands out
:meth:`~SharedVector.bit` views that set their bits in it (writing the whole vector each time);
:meth:`~SharedVector.all_bits` is one view driving every bit alike (one shared motion)::

    a, b = SharedVector(dut.a_in), SharedVector(dut.b_in)
    drivers = [QuadratureDriver(a.bit(k), b.bit(k)) for k in range(channels)]
"""

from __future__ import annotations


class SharedVector:
    """A vector input whose bits are driven by several drivers (``width``: the handle's)."""

    def __init__(self, handle, value: int = 0):
        self.handle = handle
        self.width = len(handle)
        self.value = value & ((1 << self.width) - 1)
        handle.value = self.value

    def bit(self, k: int) -> "_Bits":
        if not 0 <= k < self.width:
            raise IndexError(f"SharedVector: bit {k} outside a {self.width}-bit vector")
        return _Bits(self, 1 << k)

    def all_bits(self) -> "_Bits":
        return _Bits(self, (1 << self.width) - 1)


class _Bits:
    """A signal-like view: ``.value = level`` sets every bit of ``mask`` to level."""

    def __init__(self, vec: SharedVector, mask: int):
        self.vec, self.mask = vec, mask

    @property
    def value(self) -> int:
        return int(bool(self.vec.value & self.mask))

    @value.setter
    def value(self, level) -> None:
        v = self.vec
        v.value = (v.value | self.mask) if int(level) else (v.value & ~self.mask)
        v.handle.value = v.value
