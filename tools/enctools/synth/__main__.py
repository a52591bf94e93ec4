# SPDX-License-Identifier: Apache-2.0
"""`python -m enctools.synth`: the same command line as scripts/synth.py."""

import sys

from .cli import main

sys.exit(main())
