# SPDX-License-Identifier: Apache-2.0
"""pytest (board tests): the shared helpers in tb/common/ (harness, models, tbutil) are importable by name from
every test folder."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tb" / "common"))
