#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The technician's view of the phase adjustment (the note's Assembly Procedure, Figure 11).

The command line of enctools.phase_adjust (tools/enctools/phase_adjust.py); --help lists its options."""

import sys

from enctools.phase_adjust import main

if __name__ == "__main__":
    sys.exit(main())
