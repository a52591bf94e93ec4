#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Velocity-method accuracy on modelled HEDS-5000 units (`make velocity`).

The command line of enctools.velocity (tools/enctools/velocity/cli.py); --help lists its options."""

import sys

from enctools.velocity import main

if __name__ == "__main__":
    sys.exit(main())
