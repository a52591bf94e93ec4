#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Count-rate benchmark: the shortest state width (in clock periods) at which the conditioner +

The command line of enctools.count_rate (tools/enctools/count_rate.py); --help lists its options."""

import sys

from enctools.count_rate import main

if __name__ == "__main__":
    sys.exit(main())
