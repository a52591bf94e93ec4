#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Mutation coverage of the RTL (`make mutate`): would the tests notice a wrong circuit?

The command line of enctools.mutation.cli (tools/enctools/mutation/cli.py); --help lists its options."""

import sys

from enctools.mutation.cli import main

if __name__ == "__main__":
    sys.exit(main())
