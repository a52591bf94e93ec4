# SPDX-License-Identifier: Apache-2.0
"""Where things are in the repository (the package is installed editable from tools/)."""

from __future__ import annotations

from pathlib import Path

TOP = Path(__file__).resolve().parents[2]
if not (TOP / "enc_ip.core").exists():  # an install that is not the editable one of bootstrap
    raise ImportError(f"enctools must run from its repository (no enc_ip.core in {TOP}); "
                      "install it with `pip install -e ./tools`")

RTL = TOP / "rtl"
TB = TOP / "tb"
TB_HDL = TB / "hdl"
SIM = TOP / "sim"
BUILD = TOP / "build"
DOC = TOP / "doc"
RESULTS = DOC / "results"
FORMAL = TOP / "formal"
BOARDS = TOP / "boards"
SCRIPTS = TOP / "scripts"
SW = TOP / "sw"
CORE_FILE = TOP / "enc_ip.core"
RDL = RTL / "enc_qei.rdl"


def rel(path: Path) -> str:
    """``path`` relative to the repository top, as a string (for messages and for YoWASP tools,
    which map their own directory over /tmp and need relative paths)."""
    return str(Path(path).resolve().relative_to(TOP))
