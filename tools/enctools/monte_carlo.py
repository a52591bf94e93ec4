#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Monte Carlo of a HEDS-5000 production batch: the state-width error distribution of Figure 7.

Draws --units encoders from the note's Tables 2 and 3 (the hedsmodel package, python/), turns each through one
revolution, measures its worst state-width error from its own waveform, prints mean, sigma and
the fraction under the 44 e° room-temperature limit (--limit) next to the note's algebraic
prediction, and saves a histogram (default sim/figures/state_width_histogram.png). --rpm,
--temp-c and --alpha set the test conditions (default: slow, 25 °C, where temperature plays no part). Deterministic
for a given --seed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .paths import TOP
FIGURE = TOP / "sim" / "figures" / "state_width_histogram.png"

import numpy as np  # noqa: E402

from hedsmodel import budget, note  # noqa: E402
from hedsmodel.montecarlo import Batch, state_width_batch  # noqa: E402


def histogram(batch: Batch, prediction: dict, limit: float, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    errors = batch.errors_deg
    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    bins = np.arange(0, max(80.0, errors.max() + 2), 2.0)
    ax.hist(errors, bins=bins, color="#4c72b0", edgecolor="white",
            label=f"simulated: mean {batch.mean_deg:.1f}, σ {batch.sd_deg:.1f} e°")
    x = np.linspace(0, bins[-1], 400)
    mu, sd = prediction["mean_deg"], prediction["sd_deg"]
    ax.plot(x, errors.size * 2.0 * np.exp(-0.5 * ((x - mu) / sd) ** 2) / (sd * np.sqrt(2 * np.pi)),
            color="#dd8452", lw=2, label=f"note's estimate: mean {mu:.0f}, σ {sd:.1f} e°")
    ax.axvline(limit, color="k", ls="--", lw=1)
    ax.text(limit + 1, ax.get_ylim()[1] * 0.92,
            f"{limit:g} e° limit: {100 * batch.fraction_under(limit):.1f} % below", fontsize=8)
    ax.set_xlabel("maximum state width error over one revolution (electrical degrees)")
    ax.set_ylabel("units")
    ax.set_title(f"HEDS-5000 batch, {errors.size} units (seed {batch.seed}, {batch.rpm:g} rpm, "
                 f"{batch.temp_c:g} °C)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="monte_carlo.py", description=__doc__.split("\n")[0])
    p.add_argument("--units", type=int, default=2000, help="encoders in the batch (default 2000)")
    p.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    p.add_argument("--out", type=Path, default=FIGURE,
                   help="histogram PNG path (default sim/figures/state_width_histogram.png)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--rpm", type=float, default=60.0, help="test speed (default 60)")
    p.add_argument("--temp-c", type=float, default=note.T_REF_C, help="temperature (default 25)")
    p.add_argument("--alpha", type=float, default=note.ALPHA_TYPICAL,
                   help="pulse-width coefficient e°/(°C·Hz) (default 1e-5)")
    p.add_argument("--limit", type=float, default=note.STATE_LIMIT,
                   help="state width error limit to count units under (default 44 e°)")
    args = p.parse_args(argv)
    if args.units < 2 or args.seed < 0 or args.rpm <= 0:
        p.error("need --units >= 2, --seed >= 0 and --rpm > 0")
    if not note.ALPHA_RANGE[0] <= args.alpha <= note.ALPHA_RANGE[1]:
        p.error(f"--alpha must be in {note.ALPHA_RANGE[0]:g} .. {note.ALPHA_RANGE[1]:g}")

    step = max(1, args.units // 20)

    def progress(done, total):
        if total >= 200 and (done % step == 0 or done == total):
            print(f"\r  {done}/{total} units", end="\n" if done == total else "", file=sys.stderr,
                  flush=True)

    batch = state_width_batch(args.units, args.seed, args.rpm, args.temp_c, args.alpha, progress)
    prediction = budget.state_width_error()
    histogram(batch, prediction, args.limit, args.out)
    result = {"units": args.units, "seed": args.seed, "rpm": args.rpm, "temp_c": args.temp_c,
              "alpha": args.alpha, "mean_deg": batch.mean_deg, "sd_deg": batch.sd_deg,
              "p95_deg": batch.p95_deg, "limit_deg": args.limit,
              "fraction_under_limit": batch.fraction_under(args.limit),
              "note_mean_deg": prediction["mean_deg"], "note_sd_deg": prediction["sd_deg"],
              "note_p95_deg": prediction["p95_deg"], "histogram": str(args.out)}
    if args.json:
        print(json.dumps(result))
    else:
        print(f"state width error, {args.units} units (seed {args.seed}, {args.rpm:g} rpm, "
              f"{args.temp_c:g} °C, alpha {args.alpha:g}):")
        print(f"  simulated   mean {batch.mean_deg:5.1f}  sigma {batch.sd_deg:4.1f}  "
              f"95th percentile {batch.p95_deg:5.1f} e°  "
              f"under {args.limit:g} e°: {100 * batch.fraction_under(args.limit):.1f} %")
        print(f"  note, 25 °C mean {prediction['mean_deg']:5.1f}  "
              f"sigma {prediction['sd_deg']:4.1f}  mean + 1.65 sigma {prediction['p95_deg']:5.1f} e°  (worst-case algebraic sum)")
        print(f"  histogram: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
