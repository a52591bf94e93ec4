#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Simulation speed: how fast the cocotb regression's typical load runs on each simulator.

The command line of enctools.sim_speed (tools/enctools/sim_speed.py); --help lists its options."""

import sys

from enctools.sim_speed import main

if __name__ == "__main__":
    sys.exit(main())
