#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""FPGA synthesis of every contract block, of the iCEBreaker board top and of enc_qei at 1 to 16
channels (`make synth`).

The command line of enctools.synth (tools/enctools/synth/cli.py); --help lists its options."""

import sys

from enctools.synth import main

if __name__ == "__main__":
    sys.exit(main())
