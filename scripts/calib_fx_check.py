#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The integer calibrating estimator (sw/enc_qei_calib_fx.c) against the double one on every run
of the velocity bench's calibrated part, and its cost on RV32IM; writes
doc/results/velocity_calib_fx.md. The command line of enctools.velocity.calib_fx; --help lists
its options. Exit status 1 when a reading differs by more than one unit or a decision differs."""

import sys

from enctools.velocity.calib_fx import main

if __name__ == "__main__":
    sys.exit(main())
