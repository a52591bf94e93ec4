# SPDX-License-Identifier: Apache-2.0
"""FPGA synthesis of every contract block, of the iCEBreaker board top and of enc_qei_wb at 1 to 16
channels (`make synth`, doc/results/synth_results.md and synth_channels.md).

- ``blocks``: the parts, the rows of the results table (``BLOCKS``), a build's ``Result``.
- ``build``: one build: Yosys and its warning waivers, nextpnr per seed, the board clock check.
- ``channels``: the channel table (LUT4 versus CHANNELS, the fitted line).
- ``report``: the results table, its Markdown file, the rows that changed.
- ``cli``: the command line (scripts/synth.py), the jobs on threads.
"""

from .blocks import BLOCKS, Block, Result, fits
from .channels import SWEEP_CHANNELS, Fit, channel_table, channels_markdown, fit_line, sweep_block, sweep_blocks
from .cli import main, parse_channels, run_jobs
from .report import changes, markdown, previous_rows, table

__all__ = ["BLOCKS", "Block", "Fit", "Result", "SWEEP_CHANNELS", "changes", "channel_table",
           "channels_markdown", "fit_line", "fits", "main", "markdown", "parse_channels",
           "previous_rows", "run_jobs", "sweep_block", "sweep_blocks", "table"]
