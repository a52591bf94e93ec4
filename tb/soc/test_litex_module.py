# SPDX-License-Identifier: Apache-2.0
"""EncQEI / add_enc_qei (tools/enctools/litex): every parameter of enc_qei_wb is reachable from
the LiteX wrapper and reaches the Verilog instance; bad values, unknown names and combinations
the peripheral cannot build raise ValueError naming the parameter, before any tool runs.

Plain pytest with LiteX's Python packages (installed by `make soc-sim`; skipped without them),
no simulator: the module is built against a stand-in platform that records the sources.
"""

from __future__ import annotations

import pytest

pytest.importorskip("litex")

from migen import Instance  # noqa: E402

from enctools import core  # noqa: E402
from enctools.litex import EncQEI, module_params  # noqa: E402


class Platform:
    """What EncQEI asks of a LiteX platform."""

    def __init__(self):
        self.sources, self.includes = [], []

    def add_source(self, path):
        self.sources.append(path)

    def add_verilog_include_path(self, path):
        self.includes.append(path)


def instance_params(qei: EncQEI) -> dict[str, int]:
    """The parameters of the Verilog instance the module makes."""
    inst = next(s for s in qei.get_fragment().specials if isinstance(s, Instance))
    assert inst.of == "enc_qei_wb"
    return {p.name: p.value.value for p in inst.items if isinstance(p, Instance.Parameter)}


def test_every_parameter_of_the_module_is_reachable():
    names = module_params()
    assert {"CHANNELS", "ADDR_W", "COUNT_W", "TS_W", "PROFILE", "FUNC_MASK", "EFIFO_LOG2"} <= set(names)
    for name in names:
        r = core.param_range(name)
        value = r.corners[-1] if name != "ADDR_W" else 12
        qei = EncQEI(Platform(), **{name.lower(): value})
        assert instance_params(qei)[name] == value, name


def test_edge_fifo_build():
    qei = EncQEI(Platform(), channels=3, efifo_log2=8)
    p = instance_params(qei)
    assert (p["CHANNELS"], p["EFIFO_LOG2"], p["ADDR_W"], p["PROFILE"]) == (3, 8, 10, 2)
    assert qei.size == 1024 and qei.efifo_log2 == 8


@pytest.mark.parametrize("kwargs, words", [
    (dict(efifo_log2=9), ["EFIFO_LOG2", "0 .. 8"]),
    (dict(channels=0), ["CHANNELS", "1 .. 16"]),
    (dict(profile="counting", efifo_log2=4), ["EFIFO_LOG2", "PROFILE"]),
    (dict(engine=1, profile="counting", efifo_log2=4), ["EFIFO_LOG2", "PROFILE"]),
    (dict(profile="lean", count_w=16), ["PROFILE", "COUNT_W"]),
    (dict(channels=3, addr_w=9), ["ADDR_W", "CHANNELS"]),
    (dict(profile="medium"), ["profile", "medium"]),
    (dict(ts_w="32"), ["TS_W", "integer"]),
    (dict(speed=1), ["SPEED", "no parameter"]),
    (dict(CHANNELS=2), ["CHANNELS", "lower case"]),
])
def test_bad_parameters_are_refused(kwargs, words):
    with pytest.raises(ValueError) as e:
        EncQEI(Platform(), **kwargs)
    assert all(w in str(e.value) for w in words), str(e.value)
