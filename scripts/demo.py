#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`make demo`: a modeled HEDS-5000 on a motor driving every circuit of the library at once.

The command line of enctools.demo (tools/enctools/demo/cli.py); --help lists its options."""

import sys

from enctools.demo import main

if __name__ == "__main__":
    sys.exit(main())
