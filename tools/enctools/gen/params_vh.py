# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_params.vh: one elaboration guard per ranged parameter, from the ranges in enc_ip.core,
and the build constants a module header needs (ADDR_W's default, a channel's bundle widths).

`ENC_CHECK_<NAME>` expands, inside a module's generate region, to a generate `if` that stops
elaboration when the parameter is out of its range, with a message that names the parameter and
the range: `$error` for Verilator and Yosys, an instance of a module that does not exist (named
after the parameter and the range) for Icarus, which does not stop on `$error` in a generate
block."""

from __future__ import annotations

from .. import core
from . import HEADER_V


def guard(r: core.ParamRange) -> tuple[str, str, str]:
    """(condition of a bad value, Icarus module name, message) for one parameter."""
    n = r.name
    if r.values:
        bad = " && ".join(f"{n} != {v}" for v in r.values)
        words = "_or_".join(map(str, r.values))
        return f"({bad})", f"enc__parameter_{n}_must_be_{words}", f"parameter {n} must be {r.text().replace(', ', ' or ')}"
    return (f"({n} < {r.lo} || {n} > {r.hi})", f"enc__parameter_{n}_must_be_{r.lo}_to_{r.hi}",
            f"parameter {n} must be in {r.text()}")


def render() -> str:
    lines = [*HEADER_V,
             "// Elaboration guards of the ranged parameters (their ranges: enc_ip.core, generate:",
             "// enc_params). In a module with the parameter, inside `generate`: `ENC_CHECK_<NAME>",
             "`ifndef ENC_PARAMS_VH", "`define ENC_PARAMS_VH", "`ifdef __ICARUS__"]
    ranges = core.ranges()
    for r in ranges.values():
        cond, mod, _ = guard(r)
        lines.append(f"`define ENC_CHECK_{r.name} if {cond} begin : g_bad_{r.name.lower()} "
                     f"{mod} u_stop (); end")
    lines.append("`else")
    for r in ranges.values():
        cond, _, msg = guard(r)
        lines.append(f"`define ENC_CHECK_{r.name} if {cond} begin : g_bad_{r.name.lower()} "
                     f'$error("{msg}"); end')
    lines.append("`endif")
    lines += ["// Every count function (CTRL.FUNC's codes in rtl/enc_qei.rdl): the default of FUNC_MASK",
              f"`define ENC_QEI_FUNC_ALL {ranges['FUNC_MASK'].hi}"]
    lines += addr_w_default(ranges["CHANNELS"].hi)
    lines += bundle_widths()
    lines += ["`endif", ""]
    return "\n".join(lines)


def bundle_widths() -> list[str]:
    """The widths of one channel's register bundles, for port declarations (enc_qei_channel),
    which come before a module body could include enc_qei_regs.vh."""
    from .bundle import build

    c = build("chan")
    return ["// One channel's register bundles (rtl/enc_qei_chan_fields.vh): reg2hw and hw2reg widths",
            f"`define ENC_QEI_R2H_CH_W {c.r2h_w}", f"`define ENC_QEI_H2R_CH_W {c.h2r_w}"]


def addr_w_default(channels_max: int) -> list[str]:
    """`ENC_QEI_ADDR_W(CHANNELS)`: the least address width that holds CHANNELS pages of 256
    bytes, 8 + ceil(log2(CHANNELS)): the default of ADDR_W in enc_qei and its bus adapters."""
    expr, bits = "8", 0
    while (1 << bits) < channels_max:
        bits += 1
        expr = f"((CH) > {1 << (bits - 1)}) ? {8 + bits} : ({expr})"
    return ["// The least byte-address width that holds CHANNELS pages of 256 bytes (the default of ADDR_W)",
            f"`define ENC_QEI_ADDR_W(CH) ({expr})"]
