# SPDX-License-Identifier: Apache-2.0
"""Number and label formats of the velocity table."""

from __future__ import annotations

import math


def fmt_pct(x, digits=3) -> str:
    """A relative error as a percentage, its precision following its size ('—': none)."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    v = 100 * x
    if v < 1e-7:
        return "0"
    if v >= 100:
        return f"{v:,.0f}"
    if v >= 10:
        return f"{v:.1f}"
    if v >= 0.1:
        return f"{v:.{digits}f}"
    return f"{v:.2g}" if v >= 1e-3 else f"{v:.1e}"


def worst(rows: dict, key: str, metric: str, units=None) -> float:
    """The largest ``metric`` of variant ``key`` over the units' rows (``units``: only these)."""
    vals = [r[key][metric] for u, r in rows.items() if key in r and (units is None or u in units)]
    return max(vals) if vals else math.nan


def edges_label(edge: str, any_text: str = "any") -> str:
    return "A↑" if edge == "a_rising" else any_text
