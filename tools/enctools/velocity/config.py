# SPDX-License-Identifier: Apache-2.0
"""The benchmark's fixed choices: outputs, read rate, the variants compared, the goals, the
scenarios, the prescaler table and the simulated layer's cases."""

from __future__ import annotations

from ..paths import TOP

TABLE = TOP / "doc" / "results" / "velocity_methods.md"
FIGURE = TOP / "sim" / "figures" / "velocity_methods.png"

CPR = 500                          # HEDS-5000 cycles per revolution
READ_HZ = 1000.0
FILTER_LEN = 3                     # enc_qei's reset value
LATENCY_CLOCKS = FILTER_LEN + 4    # pins to timestamp in enc_qei (RDL); a constant, it cancels
VARIANTS = (("M", "any"), ("T", "any"), ("T", "a_rising"), ("MT", "any"), ("MT", "a_rising"))
LABEL = {("M", "any"): "M", ("T", "any"): "T any edge", ("T", "a_rising"): "T A↑",
         ("MT", "any"): "M/T any edge", ("MT", "a_rising"): "M/T A↑"}
GOAL_ADDED_TYP = 1e-3              # hardware adds <= 0.1 % of the reading (30 .. 12,000 rpm)
GOAL_ADDED_IDEAL = 2e-4            # <= 0.02 % on the ideal unit
GOAL_NONZERO_RPM = 6.0
GOAL_BAND = (30.0, 12000.0)
# Shaft speeds are detuned by this factor: a round speed makes every edge interval a whole number
# of clocks (12,000 rpm = 1,000 clocks per cycle at 100 MHz), which hides the timebase's
# quantisation; detuned, the edges meet every clock phase, as a real shaft's do.
DETUNE = 1.000137

SCENARIOS = {
    # name: (profile, description)
    "ramp": ([("ramp", 30.0, 3000.0, 0.5)], "ramp 30 → 3000 rpm in 0.5 s (5,940 rpm/s)"),
    "reversal": ([("ramp", 300.0, -300.0, 0.4)], "ramp 300 → −300 rpm in 0.4 s (reverses at 0.2 s)"),
    "stop": ([("constant", 60.0, 0.3), ("stop", 0.6)], "60 rpm for 0.3 s, then stop for 0.6 s"),
    "stop6": ([("constant", 6.0, 0.5), ("stop", 0.6)], "6 rpm for 0.5 s, then stop for 0.6 s"),
}
PRESCALES = (0, 4, 9, 49, 99)
PRESCALE_RPMS = (30.0, 300.0, 3000.0, 12000.0)

# The simulated layer
SIM_UNITS = 2          # the ideal unit and the first typical one
READ_REGS = ("SNAP_COUNT_LO", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA", "SNAP_EDGE_DELTA",
             "PERIOD", "PERIOD_CTRL", "STATUS")   # what the bench reads after each snapshot
SETUP_REGS = ("TB_PRESCALE", "PERIOD_CTRL", "STALL_TIMEOUT", "SNAP_CTRL", "TIMEBASE")
SIM_T0_MS = 0.3        # first read, ms after the waveform starts
SIM_STOP_RPM = 300.0   # the simulated stop: 3 ms at this speed, then 6 ms standing
SIM_STALL_S = 2e-3     # ... with this stall timeout (STALL_TIMEOUT and the estimators)
