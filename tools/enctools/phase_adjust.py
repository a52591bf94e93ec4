#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The technician's view of the phase adjustment (the note's Assembly Procedure, Figure 11).

A modelled encoder is "adjusted": while the shaft runs forward at ~110 clocks per cycle, the
encoder body is turned so that the phase between the channels moves slowly from 60 to 120
electrical degrees between the pulse centres (pulse-width errors +6 / -4 e-degrees, so the rising
edges are 5 degrees further apart than that); then the shaft is run in reverse at the 90 degree setting, the note's advice to
"turn the shaft in both directions". The averaging phase meter (rtl/enc_phase_meter.v,
WINDOW_LOG2 = 13) runs in a cocotb simulation (Icarus by default; SIM=verilator for Verilator),
through tb/common/harness.run and the `phase_adjust_sweep` test in tb/enc_phase_meter/test_enc_phase_meter.py.

Prints each reading with the two LEDs as a table, and saves sim/figures/phase_adjust.png (meter
reading vs true phase). Usage: scripts/phase_adjust.py [--readings N] [--sim icarus|verilator]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

from .paths import TOP
FIG = TOP / "sim" / "figures" / "phase_adjust.png"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--readings", type=int, default=25, help="readings during the forward sweep")
    ap.add_argument("--sim", default=os.environ.get("SIM", "icarus"), choices=("icarus", "verilator"))
    ap.add_argument("--out", type=Path, default=FIG, help="figure path")
    args = ap.parse_args()
    os.environ["SIM"] = args.sim
    from .harness import run

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "phase_adjust.json"
        print(f"phase_adjust: simulating enc_phase_meter on {args.sim}: {args.readings} readings "
              f"sweeping 60 -> 120 e-degrees, then 2 in reverse ...", flush=True)
        t0 = time.monotonic()
        run("enc_phase_meter", "enctools.benches.phase_adjust", name="phase_adjust",
            parameters={"WINDOW_LOG2": 13}, testcase="phase_adjust_sweep",
            extra_env={"ENC_PHASE_ADJUST_OUT": str(out), "ENC_PHASE_ADJUST_READINGS": str(args.readings),
                       "COCOTB_LOG_LEVEL": "WARNING"})
        data = json.loads(out.read_text())
        print(f"phase_adjust: simulation done in {time.monotonic() - t0:.1f} s", flush=True)

    rows = data["readings"]
    print()
    print(f"  window 2^{data['window_log2']} clocks, {data['clocks_per_cycle']:.2f} clocks/cycle")
    print("   #   time ms  rotation  true phase  meter reads   error   A-leads(red)  B-leads")
    worst = 0.0
    for i, r in enumerate(rows):
        err = r["phase_err"] - r["true_err"]
        worst = max(worst, abs(err))
        led = lambda v: "  ON " if v else "  -- "  # noqa: E731
        print(f"  {i:2d}  {r['t_ms']:7.3f}  {'forward' if r['forward'] else 'reverse':8s}"
              f"  {r['true_err'] + 90:9.3f}   {r['phase_err']:+9.3f}   {err:+7.3f}"
              f"      {led(r['a_leads'])}      {led(r['b_leads'])}")
    zero = min((r for r in rows if r["forward"]), key=lambda r: abs(r["phase_err"]))
    print(f"\n  meter closest to zero: {zero['phase_err']:+.3f} at true phase {zero['true_err'] + 90:.3f}"
          f" e-degrees; worst |reading - true| {worst:.3f} e-degrees")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fwd = [r for r in rows if r["forward"]]
    rev = [r for r in rows if not r["forward"]]
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.3]})
    xs = [r["true_err"] + 90 for r in fwd]
    ax.plot([58, 122], [-32, 32], color="0.8", lw=1, label="ideal: reading = phase - 90")
    ax.plot(xs, [r["phase_err"] for r in fwd], "o-", ms=4, label="enc_phase_meter, shaft forward (A leads)")
    if rev:
        ax.plot([r["true_err"] + 90 for r in rev], [r["phase_err"] for r in rev], "s", ms=7,
                mfc="none", label="shaft reversed at the 90-degree setting (B leads)")
    ax.axhline(0, color="k", lw=0.6)
    ax.axvline(90, color="k", lw=0.6, ls=":")
    ax.set_ylabel("meter reading phase_err (e-degrees)")
    ax.set_title("Phase adjustment with the averaging phase meter (Figure 11)")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    ax2.plot(xs, [r["phase_err"] - r["true_err"] for r in fwd], "o-", ms=3)
    if rev:
        ax2.plot([r["true_err"] + 90 for r in rev], [r["phase_err"] - r["true_err"] for r in rev], "s",
                 ms=6, mfc="none")
    ax2.axhspan(-0.25, 0.25, color="g", alpha=0.12, label="contract bound +/-0.25")
    ax2.set_ylim(-0.4, 0.4)
    ax2.set_xlabel("true phase between pulse centres (e-degrees)")
    ax2.set_ylabel("error (e-deg)")
    ax2.legend(loc="upper left", fontsize=8)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"phase_adjust: wrote {args.out.relative_to(TOP) if args.out.is_relative_to(TOP) else args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
