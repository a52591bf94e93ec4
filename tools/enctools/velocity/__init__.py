# SPDX-License-Identifier: Apache-2.0
"""Velocity-method accuracy on modelled HEDS-5000 units (`make velocity`).

Which velocity method to use at which speed, and how accurate each really is on this encoder:
the unit-time (M), period (T) and timestamp (M/T, hostmot2) estimators of
``hedsmodel.velocity`` (the same as ``sw/enc_qei_velocity.c``), each with edges of any type or A
rising only, read at 1 kHz, on an ideal unit and on units drawn from the application note's
tables, at constant speeds from 1 to 12,000 rpm (log-spaced), a ramp, a reversal and a stop.

Two layers:

(a) **model** (always): the snapshots an ideal enc_qei latches (``hedsmodel.velocity.
    snapshot_trace``: edges seen at the first clock after the pins plus the pipeline latency,
    timestamps in timebase ticks of a ``--clk-mhz`` clock with ``--prescale``, TS_W = 32). For
    every reading, the *floor* is the same estimator on the model's exact edge times for the same
    edges and counts (``exact_twin``): the encoder's own error. *Added* = |latched - floor| /
    true speed: what the timebase quantisation adds. A prescaler table shows the trade-off.
(b) **sim** (``--sim icarus|verilator``, default: whichever is there): the same for a short
    window per speed (``--sim-reads`` reads at 1 kHz) read through enc_qei_wb over Wishbone
    (cocotb: ``enctools.benches.velocity_sim``): the host writes SNAP_CTRL.CMD and reads the
    snapshot registers; the readings are compared with the floor on the same edges (each
    SNAP_EDGE_TIME is matched to its model edge) and SNAP_EDGE_DELTA with the model's count.
    Skipped, and said so, when the RTL lacks the timing registers. ``--rtl-rev REV`` simulates
    rtl/ as of a git revision (through a harness hook, enctools.rtlcopy) instead of the working
    tree; the table names the revision either way.

Writes doc/results/velocity_methods.md and sim/figures/velocity_methods.png; one progress line
per speed. Usage:
  scripts/velocity_bench.py [--rpm-min R] [--rpm-max R] [--points N] [--units N] [--seed N]
                            [--quick] [--jobs N] [--sim auto|none|icarus|verilator]
                            [--sim-reads N] [--rtl-rev REV] [--prescale P] [--clk-mhz F]
                            [--stall-ms T]

Modules: config (fixed choices), cli (options, main), plan (speeds, units, jobs, simulated
cases), model (the model layer), simulate (the simulated layer through enctools.harness),
analyse (one simulated case against the model), sim_table and report (the table), goals (the
verdicts), format (number formats), figure (the plot), calib (the calibrated methods of
hedsmodel.calibration on ideal edge-FIFO entries, pure Python; ``--calib on|off|only``),
calib_disturb (its disturbed runs and their one-second windows) and calib_report
(doc/results/velocity_calibration.md and its PNG).
"""

from .analyse import analyse_case
from .cli import main, parse_args
from .plan import sim_cases, timebase
from .sim_table import sim_report
from .simulate import reg_layout

__all__ = ["analyse_case", "main", "parse_args", "sim_cases", "timebase", "sim_report",
           "reg_layout"]
