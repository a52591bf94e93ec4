# SPDX-License-Identifier: Apache-2.0
"""`make demo`: a modeled HEDS-5000 on a motor driving every circuit of the library at once.

What it does:
  1. Draws one encoder unit with every error factor at the application note's table mean
     (``EncoderUnit.typical``; directions and signs from ``--seed``), at ``--temp-c``.
  2. Runs it through a motion profile: ramp up to RPM, hold (long enough for two phase-meter
     readings), slow down and reverse to -RPM/5, stop, creep to one transition of channel A and
     dither about it (the note's "stationary shaft oscillating slightly about a transition").
  3. Simulates tb/hdl/demo_top.v (conditioner, 1X Figure 14, 2X Figure 15, 4X look-up table,
     Figure 17 BCD up/down buffer, Figure 11 phase meter, characterizer, and the bus peripheral
     enc_qei_wb) with cocotb (enctools.benches.demo_bench) at ``--clk-hz``, printing a progress
     line: on Icarus for short runs (it starts at once), on Verilator for long ones (faster once
     its C++ build is done). The bench reads enc_qei_wb over Wishbone as a host would: a snapshot
     (SNAP_CTRL.CMD, SNAP_CTRL.EDGE = a_rising) every READ_TAU encoder cycles at the peak speed
     (10 cycles: 400 us = 2.5 kHz at 3000 rpm, ~40 reads over the profile at any speed; 1 kHz
     would give a handful in a 15 ms profile), and COUNT at the end.
  4. Prints the position table: the true position against every count (enc_qei_wb's COUNT too),
     the phase meter against the model's true phase over the same cycles, the characterizer
     against the model, the narrowest state against the decoder's limit; then the velocity table:
     per read the model's true speed, the timestamp (M/T, A-rising edges) and unit-time (M)
     readings of hedsmodel.velocity on the registers, and the M/T error; then a verdict per
     circuit. Exit status 1 if any verdict fails.
  5. Leaves sim/waves/demo.vcd and a GTKWave save file for it, sim/waves/demo.gtkw (``make
     waves`` opens both): sim/demo.gtkw's signals, opening on three encoder cycles at the peak
     speed of this run, markers A to D on the rising edges of A that bound them (``--gtkw`` to
     choose the file; sim/demo.gtkw itself is ``--gtkw sim/demo.gtkw`` with the default options).
     Renders a short window of the VCD to sim/waves/demo_waves.png (``--png`` to choose the file;
     the README picture is ``--png sim/figures/demo_waves.png`` with the default options).

Options (``make demo RPM=... TEMP_C=... CLK_HZ=... SEED=...``; an empty value means the default):
  --rpm     peak shaft speed, rpm (default 3000); the reverse speed is -rpm/5
  --temp-c  encoder temperature, deg C, -40 .. 125 (default 25)
  --clk-hz  sampling clock of the circuits, Hz (default 12e6)
  --seed    non-negative integer (default 1)
A bad value stops the demo with a one-line message before anything is built or simulated.

``--view`` (``make waves``): open sim/waves/demo.vcd with its save file (sim/waves/demo.gtkw,
else sim/demo.gtkw) in GTKWave when there is a display and gtkwave is installed, otherwise print
where the files are and the command.

Modules: config (fixed design choices), options (the options and the run-length arithmetic), plan
(unit, profile, waveform, the bench's plan file), simulate (through enctools.harness), analyse
and analyse_qei (records against the model, verdicts), report (the printed tables), gtkw (the
save file), view (the picture, make waves), cli (the command line).
"""

from .cli import main, parse_args
from .config import CPR, GTKW, VCD, VEL_TOL_PCT
from .gtkw import gtkw_text, gtkw_view, gtkw_view_lines, write_gtkw
from .options import OptionError, Options, f_max_hz, rpm_of, validate
from .plan import Plan, make_plan

__all__ = ["main", "parse_args", "CPR", "GTKW", "VCD", "VEL_TOL_PCT", "gtkw_text", "gtkw_view",
           "gtkw_view_lines", "write_gtkw", "OptionError", "Options", "f_max_hz", "rpm_of",
           "validate", "Plan", "make_plan"]
