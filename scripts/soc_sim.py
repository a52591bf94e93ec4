#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""enc_qei in a simulated LiteX SoC with its C firmware (`make soc-sim`).

The command line of enctools.litex.cli (tools/enctools/litex/cli.py); --help lists its options."""

import sys

from enctools.litex.cli import main

if __name__ == "__main__":
    sys.exit(main())
