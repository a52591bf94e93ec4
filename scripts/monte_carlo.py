#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Monte Carlo of a HEDS-5000 production batch: the state-width error distribution of Figure 7.

The command line of enctools.monte_carlo (tools/enctools/monte_carlo.py); --help lists its options."""

import sys

from enctools.monte_carlo import main

if __name__ == "__main__":
    sys.exit(main())
