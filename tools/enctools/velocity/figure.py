# SPDX-License-Identifier: Apache-2.0
"""sim/figures/velocity_methods.png: rms error against speed for each variant (latched and
floor, per unit), and what the timebase adds to M/T A-rising (model, and the simulated points)."""

from __future__ import annotations

from pathlib import Path

from .config import GOAL_ADDED_IDEAL, GOAL_ADDED_TYP, LABEL, VARIANTS
from .plan import timebase


def _variant_panel(ax, C, rpms, units, v, colours) -> None:
    import numpy as np

    key = f"{v[0]}/{v[1]}"
    for i, (n, _) in enumerate(units):
        c = colours[i % len(colours)]
        hw = [max(C[r][n].get(key, {}).get("rms", np.nan), 1e-7) for r in rpms]
        fl = [max(C[r][n].get(key, {}).get("floor_rms", np.nan), 1e-7) for r in rpms]
        ax.plot(rpms, 100 * np.array(hw), "-o", ms=3, color=c, lw=1.3, label=f"{n}")
        ax.plot(rpms, 100 * np.array(fl), "--", color=c, lw=0.9, alpha=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_title(LABEL[v], fontsize=11)
    ax.set_ylim(1e-5, 1e4)
    ax.grid(True, which="both", alpha=0.3)
    ax.axvline(30, color="grey", lw=0.6, ls=":")


def _added_panel(ax, C, rpms, units, sim, colours) -> None:
    import numpy as np

    key = "MT/a_rising"
    for i, (n, _) in enumerate(units):
        c = colours[i % len(colours)]
        ad = [max(C[r][n].get(key, {}).get("added_max", np.nan), 1e-7) for r in rpms]
        ax.plot(rpms, 100 * np.array(ad), "-o", ms=3, color=c, lw=1.3, label=n)
    if sim and not sim.get("skipped") and sim.get("points"):
        pts = sim["points"]
        ax.scatter([p["rpm"] for p in pts], [max(100 * p["added_max"], 1e-5) for p in pts],
                   marker="x", color="k", s=30, zorder=5, label="through the RTL (sim)")
    ax.axhline(100 * GOAL_ADDED_TYP, color="r", lw=0.8, ls="--", label="goal 0.1 %")
    ax.axhline(100 * GOAL_ADDED_IDEAL, color="r", lw=0.8, ls=":", label="goal 0.02 % (ideal)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(1e-5, 1)
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("M/T A↑: max error added by the timebase", fontsize=11)
    ax.legend(fontsize=7, loc="upper right")


def write_figure(args, units, model, sim, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    C, rpms = model["constant"], model["rpms"]
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5), dpi=110, sharex=True)
    axes = axes.ravel()
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, v in zip(axes, VARIANTS):
        _variant_panel(ax, C, rpms, units, v, colours)
    _added_panel(axes[5], C, rpms, units, sim, colours)
    axes[0].legend(fontsize=7, loc="lower left", title="solid: latched, dashed: floor (they overlap)",
                   title_fontsize=7)
    for ax in axes[3:]:
        ax.set_xlabel("shaft speed (rpm)")
    for ax in axes[::3]:
        ax.set_ylabel("relative error, % (rms)")
    tb = timebase(args)
    fig.suptitle(f"Velocity methods on modelled HEDS-5000 units, 1 kHz reads, "
                 f"{tb.tick_s * 1e9:g} ns timebase (seed {args.seed})", fontsize=12)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
