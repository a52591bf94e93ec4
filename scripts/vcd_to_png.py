#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Render a short window of a VCD to a PNG, without GTKWave: a small VCD reader plus matplotlib.

The command line of enctools.vcd_png (tools/enctools/vcd_png.py); --help lists its options."""

import sys

from enctools.vcd_png import main

if __name__ == "__main__":
    sys.exit(main())
