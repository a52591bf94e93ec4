#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Formal proofs and covers of the counting circuits with SymbiYosys (`make formal`).

The command line of enctools.formal (tools/enctools/formal.py); --help lists its options."""

import sys

from enctools.formal import main

if __name__ == "__main__":
    sys.exit(main())
