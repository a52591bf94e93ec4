#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Generate everything that depends on the enc_qei register map from rtl/enc_qei.rdl.

The command line of enctools.gen.cli (tools/enctools/gen/cli.py); --help lists its options."""

import sys

from enctools.gen.cli import main

if __name__ == "__main__":
    sys.exit(main())
