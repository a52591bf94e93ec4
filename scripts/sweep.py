#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dense count-limit sweep (`make sweep`): frequency x FILTER_LEN 1..4 x phase error.

The command line of enctools.sweep (tools/enctools/sweep.py); --help lists its options."""

import sys

from enctools.sweep import main

if __name__ == "__main__":
    sys.exit(main())
