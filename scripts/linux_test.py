#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The enc-qei Linux counter driver in User-Mode Linux against the RTL (`make linux-test`).

The command line of enctools.linux.cli (tools/enctools/linux/cli.py); --help lists its options."""

import sys

from enctools.linux.cli import main

if __name__ == "__main__":
    sys.exit(main())
