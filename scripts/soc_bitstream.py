#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The LiteX SoC with enc_qei on an FPGA board, through Yosys and nextpnr (`make soc-bitstream`).

The command line of enctools.litex.boards (tools/enctools/litex/boards.py); --help lists its
options."""

import sys

from enctools.litex.boards import main

if __name__ == "__main__":
    sys.exit(main())
