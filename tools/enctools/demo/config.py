# SPDX-License-Identifier: Apache-2.0
"""The demo's fixed design choices: files, the circuits' parameters, the limits the verdicts use,
the motion profile (in encoder cycles at the peak speed) and the run-length budget."""

from __future__ import annotations

from ..paths import TOP

NAME = "demo"
VCD = TOP / "sim" / "waves" / "demo.vcd"
GTKW = TOP / "sim" / "demo.gtkw"
DEFAULT_PNG = TOP / "sim" / "waves" / "demo_waves.png"
README_PNG = TOP / "sim" / "figures" / "demo_waves.png"
# The save file's view: GTKW_CYCLES cycles at the peak speed from the first rising edge of A after
# the middle of the hold (where the README picture's left panel starts), with half a cycle either
# side. GTKWave's zoom is time per pixel, so the visible span follows the window: GTKW_WAVE_PX is
# the width of GTKWave 3.3's wave pane at the save file's [size] (measured under Xvfb; the signal
# pane takes the rest). A window narrower by up to a quarter still shows the three cycles.
GTKW_CYCLES = 3
GTKW_VIEW_CYCLES = GTKW_CYCLES + 1.0
GTKW_WAVE_PX = 800

CPR = 500                  # HEDS-5000 code wheel count
FILTER_LEN = 3             # the conditioner's filter (the HCTL-2016's 3 samples)
SAMPLING_LIMIT = 1.05      # clocks: narrowest state a decoder counts (any sampler needs > 1)
LEVEL_LIMIT = 1.05 * FILTER_LEN  # clocks: narrowest state that passes the FILTER_LEN filter
NOTE_STATE_ERR = 44.0      # e-degrees: the note's 95 % state-width error at room temperature
ALPHA = 1.0e-5             # e-degree / (degC Hz): the note's typical pulse-width temperature coeff.
TEST_LIMIT_DEG = 46.0      # characterizer pass limit: 90 - 44 (the note's room-temperature limit)
CHAR_CYCLES = 64           # characterizer window, cycles
CHAR_CNT_W = 16
PM_MIN_CYCLES = 64         # phase meter contract: >= 64 cycles per window ...
PM_MIN_CPC = 100           # ... and >= 100 clocks per cycle for its 0.25 degree accuracy
PM_BOUND = 0.25
# enc_qei_wb velocity: reads, estimator and the two checks
READ_TAU = 10.0            # a snapshot every 10 encoder cycles at the peak speed (tau each)
STALL_TAU = 8.0            # STALL_TIMEOUT: 8 tau without a count edge (longer than a cycle at
                           # -rpm/5, shorter than the stop's 5-tau rest after the last edge)
VEL_EDGE = "a_rising"      # SNAP_CTRL.EDGE for the recommended M/T method
VEL_TOL_PCT = 1.2          # M/T vs the true speed at constant speed: the encoder's own error floor
                           # for M/T on A-rising edges is at most 1.17 % (worst modelled unit, one
                           # cycle per reading; 0.3-0.4 % rms), doc/results/velocity_methods.md
VEL_HW_TICKS = 2.0         # registers vs the same estimator on the model's exact edge times: each
                           # timestamp is quantised to one clock, so a span is off by < 2 ticks
VEL_MATCH_CLOCKS = 48      # a timestamp is at most this far behind its edge at the pins (the
                           # synchroniser, filter and pipeline: ~FILTER_LEN + 5 clocks)
VEL_SHOW_PCT = 5.0         # error % shown where |true speed| >= 5 % of the peak
# Measured: Icarus runs demo_top at ~18k clocks/s and builds at once; Verilator ~150k clocks/s
# after a ~20 s C++ build.
ICARUS_MAX_CLOCKS = 350_000   # --sim auto takes Icarus up to here (~20 s), Verilator beyond
MAX_CLOCKS = 1_000_000     # runtime and VCD budget: ~40 bytes of VCD per simulated clock
TEMP_RANGE = (-40.0, 125.0)
CLK_RANGE = (1.0e5, 2.0e8)  # 100 kHz .. 200 MHz
DEFAULTS = {"rpm": 3000.0, "temp_c": 25.0, "clk_hz": 12.0e6, "seed": 1}

# Profile, in periods tau of one encoder cycle at the peak speed (tau = 40 us at 3000 rpm).
TAU_RAMP_UP = 50.0         # 0 -> rpm                (25 cycles)
TAU_REVERSE = 60.0         # rpm -> -rpm/5
TAU_BACK = 25.0            # -rpm/5 constant         (5 cycles)
TAU_STOP_RAMP = 25.0       # -rpm/5 -> 0
TAU_REST = 5.0             # standstill between moves
CREEP_DIV = 20.0           # creep to the dither transition at rpm/20
DITHER_PERIODS = 8
TAU_DITHER = 5.0           # one dither period
DITHER_AMP_DEG = 20.0
DITHER_OFFSET_DEG = 2.0    # dither centre: this far on the near side of the transition
