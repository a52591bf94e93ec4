#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""HEDS-5000 error-budget calculator: the application note's worked examples, inputs as flags.

The command line of enctools.error_budget (tools/enctools/error_budget.py); --help lists its options."""

import sys

from enctools.error_budget import main

if __name__ == "__main__":
    sys.exit(main())
