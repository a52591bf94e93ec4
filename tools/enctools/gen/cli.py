# SPDX-License-Identifier: Apache-2.0
"""`make regs`: write every file derived from rtl/enc_qei.rdl and enc_ip.core; --check compares
instead (exit 1, naming the stale files, with a diff). All outputs are committed:

  rtl/enc_qei_regs.v          the register block (regblock)
  rtl/enc_qei_regs.vh         the map for Verilog: offsets, fields, enum codes (regs_vh)
  rtl/enc_qei_regs_fields.vh  the global bundles' fields by name (bundle)
  rtl/enc_qei_chan_fields.vh  a channel's bundle fields by name (bundle)
  rtl/enc_params.vh           the parameter guards, from enc_ip.core's ranges (params_vh)
  formal/enc_qei_regs_table.vh  the map as tables for the register block's proof (regs_table)
  sw/enc_qei_regs.h           the C header (c_header)
  doc/enc_qei_regs.md         the register reference (markdown)
"""

from __future__ import annotations

import argparse
import difflib
import sys
import tempfile
from pathlib import Path

from ..paths import TOP
from ..regmap import compile_rdl
from . import bundle, c_header, markdown, params_vh, regblock, regs_table, regs_vh

OUT_V = TOP / "rtl" / "enc_qei_regs.v"
OUT_VH = TOP / "rtl" / "enc_qei_regs.vh"
OUT_FIELDS = TOP / "rtl" / "enc_qei_regs_fields.vh"
OUT_CHFIELDS = TOP / "rtl" / "enc_qei_chan_fields.vh"
OUT_PARAMS = TOP / "rtl" / "enc_params.vh"
OUT_TABLE = TOP / "formal" / "enc_qei_regs_table.vh"
OUT_H = TOP / "sw" / "enc_qei_regs.h"
OUT_MD = TOP / "doc" / "enc_qei_regs.md"


def generate(out_dir: Path | None = None) -> dict[Path, Path]:
    """Write every output; with out_dir, into it instead of the tree. Returns {tree path: written}."""
    top = compile_rdl()
    texts = {OUT_V: lambda: regblock.render(top), OUT_VH: lambda: regs_vh.render(top),
             OUT_FIELDS: lambda: bundle.render_fields("glb"),
             OUT_CHFIELDS: lambda: bundle.render_fields("chan"), OUT_PARAMS: params_vh.render,
             OUT_TABLE: lambda: regs_table.render(top)}
    files = {OUT_H: lambda p: c_header.c_header(top, p), OUT_MD: lambda p: markdown.markdown(top, p)}
    written = {}
    for dest in [*texts, *files]:
        path = (out_dir / dest.name) if out_dir else dest
        path.parent.mkdir(parents=True, exist_ok=True)
        if dest in texts:
            path.write_text(texts[dest]())
        else:
            files[dest](path)
        written[dest] = path
    return written


def check(outputs: dict[Path, Path] | None = None) -> list[str]:
    """Names of the committed outputs that differ from what the RDL generates (with a diff on
    stderr). ``outputs`` maps each output to the file to compare (default: itself)."""
    stale = []
    with tempfile.TemporaryDirectory() as tmp:
        for dest, fresh in generate(Path(tmp)).items():
            rel = dest.relative_to(TOP)
            dest = (outputs or {}).get(dest, dest)
            if not dest.exists():
                stale.append(f"{rel} (missing)")
                continue
            old, new = dest.read_text(), fresh.read_text()
            if old != new:
                diff = difflib.unified_diff(old.splitlines(), new.splitlines(), str(rel), "generated",
                                            lineterm="", n=1)
                print("\n".join(list(diff)[:40]), file=sys.stderr)
                stale.append(str(rel))
    return stale


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true",
                    help="do not write; exit 1 if a committed output differs from what the RDL generates")
    args = ap.parse_args()
    if not args.check:
        for dest in generate():
            print(f"make regs: wrote {dest.relative_to(TOP)}")
        return 0
    stale = check()
    if stale:
        print("make regs --check: stale (run `make regs`): " + ", ".join(stale), file=sys.stderr)
        return 1
    print("make regs --check: every output matches rtl/enc_qei.rdl")
    return 0
