# SPDX-License-Identifier: Apache-2.0
"""The results table: goal verdicts, the printed table, doc/results/synth_results.md, and the rows
that differ from the table a run replaces."""

from __future__ import annotations

import re
from pathlib import Path

from .blocks import (BLOCK_DEVICE_NAME, BOARD_CLOCK_MHZ, BRAM_CAPACITY, BRAM_CELL, CAPACITY, CHANNELS_MD,
                     ECP5_DEVICE_NAME, FMAX_TARGET_MHZ, PLACED_CELL, SEED, Result)


# ------------------------------------------------------------------------------------------------
# table
# ------------------------------------------------------------------------------------------------
def goal_cells(r: Result) -> tuple[str, str]:
    b = r.block
    if b.board:
        if r.status != "ok":
            return "meet 12 MHz", "-"
        ok = r.fmax is not None and r.fmax >= BOARD_CLOCK_MHZ and not r.failures
        return "meet 12 MHz (constrained)", "met" if ok else "**missed**"
    goals, verdicts = [], []
    if b.lut_goal is not None:
        goals.append(f"≤ {b.lut_goal} LUT4")
        if r.status == "ok":
            over = r.luts - b.lut_goal
            verdicts.append("met" if over <= 0 else f"**missed by {over} LUT4**")
    if b.fmax_goal is not None:
        goals.append(f"≥ {b.fmax_goal:g} MHz")
        if r.status == "ok" and not r.fits:
            verdicts.append("**missed: does not fit the part**")
        elif r.status == "ok" and r.fmax is None and r.stopped:
            verdicts.append("**missed: not routed in time**")
        elif r.status == "ok" and r.fmax is not None:
            short = b.fmax_goal - r.fmax
            verdicts.append("met" if short <= 0 else f"**missed by {short:.1f} MHz**")
    if not goals:
        return "-", "-"
    if r.status != "ok":
        return ", ".join(goals), "-"
    return ", ".join(goals), ("met" if all(v == "met" for v in verdicts) else ", ".join(verdicts))


def ram_cell(r: Result) -> str:
    """The build's block RAMs (and the ECP5's distributed RAM), or -."""
    out = [f"{r.brams} {BRAM_CELL[r.block.device]}" if r.brams else "",
           f"{r.lutrams} DPR16X4" if r.lutrams else ""]
    return " + ".join(o for o in out if o) or "-"


def placed_cell(r: Result) -> str:
    """The LUT4 sites nextpnr used (iCE40 logic cells, ECP5 TRELLIS_COMB) of the part's, or -."""
    if r.placed is None:
        return "-"
    unit = "LC" if PLACED_CELL[r.block.device] == "ICESTORM_LC" else "COMB"
    if r.packed_only:
        return f"needs {r.placed:,} / {r.placed_of:,} {unit} (packed, {100 * r.placed / r.placed_of:.0f} %)"
    return f"{r.placed:,} / {r.placed_of:,} {unit}"


HEAD = ["module", "params", "part", "LUT4", "FF", "carry", "Fmax (MHz)", "seeds", "block RAM", "placed", "goal",
        "result"]


def table(results: list[Result | dict]) -> str:
    """The rows in order: a Result, or a row kept from the table file (column name -> cell)."""
    rows = ["| " + " | ".join(HEAD) + " |", "|---|---|---|---:|---:|---:|---:|---:|---|---:|---|---|"]
    for r in results:
        if isinstance(r, dict):
            rows.append("| " + " | ".join(r.get(h, "-") for h in HEAD) + " |")
            continue
        b = r.block
        part = b.part
        if r.status != "ok":
            rows.append(f"| {b.name} | {b.param_text} | {part} | - | - | - | - | {b.seeds} | - | - | "
                        f"{goal_cells(r)[0]} | {r.note} |")
            continue
        stopped = "; ".join(r.stopped)  # seeds stopped at the route time limit
        fmax = (f"not routed ({stopped})" if r.fmax is None and stopped else
                f"{r.fmax:.1f} (median of {b.seeds - len(r.stopped)}; {stopped})" if stopped else
                f"{r.fmax:.1f}" if r.fmax is not None else
                "not placed (does not fit)" if not r.fits else "n/a (no clocked path)")
        goal, verdict = goal_cells(r)
        if r.dsps:
            verdict += f"; {r.dsps} SB_MAC16"
        rows.append(f"| {b.name} | {b.param_text} | {part} | {r.luts} | {r.ffs} | {r.carries} | {fmax} "
                    f"| {b.seeds} | {ram_cell(r)} | {placed_cell(r)} | {goal} | {verdict} |")
    return "\n".join(rows)


def row_figures(r: Result | dict) -> dict | None:
    """A row's figures for the FIFO table, from a Result or from a row kept from the table file:
    module, part, parameters (name -> text), LUT4, FF, block RAM and distributed RAM counts, Fmax
    (text), or None for a row without figures (not built, not synthesised)."""
    if isinstance(r, Result):
        if r.status != "ok":
            return None
        b = r.block
        return {"module": b.name, "part": b.part, "params": {k: str(v) for k, v in b.params.items()},
                "luts": r.luts, "ffs": r.ffs, "brams": r.brams, "lutrams": r.lutrams,
                "fmax": f"{r.fmax:.1f}" if r.fmax is not None else "-"}
    if not (r.get("LUT4", "").isdigit() and r.get("FF", "").isdigit()):
        return None
    params = dict(p.split("=", 1) for p in r.get("params", "-").split(", ") if "=" in p)
    ram = r.get("block RAM", "-")
    brams = re.search(r"(\d+) (?:SB_RAM40_4K|DP16KD)", ram)
    lutrams = re.search(r"(\d+) DPR16X4", ram)
    if brams is None:  # rows written before the block RAM column: "...; 3 SB_RAM40" in the result
        brams = re.search(r"(\d+) SB_RAM40", r.get("result", ""))
    fmax = re.match(r"\d+\.\d+", r.get("Fmax (MHz)", ""))
    return {"module": r.get("module", "-"), "part": r.get("part", "-"), "params": params,
            "luts": int(r["LUT4"]), "ffs": int(r["FF"]), "brams": int(brams.group(1)) if brams else 0,
            "lutrams": int(lutrams.group(1)) if lutrams else 0, "fmax": fmax.group(0) if fmax else "-"}


def efifo_table(results: list[Result | dict]) -> list[str]:
    """The edge FIFO's cost: each row with EFIFO_LOG2 against the row of the same build without
    it (LUT4, FF and RAM over it, and its Fmax). `results` is the whole table (rows measured by
    this run and rows kept from the table file alike), so a run that replaces some rows writes the
    section for all of them."""
    figs = [f for f in map(row_figures, results) if f is not None]
    key = lambda f, params: (f["module"], f["part"], tuple(sorted(params.items())))  # noqa: E731
    base_of = {key(f, f["params"]): f for f in figs}
    rows = []
    for f in figs:
        log2 = f["params"].get("EFIFO_LOG2")
        if not log2 or log2 == "0":
            continue
        base = base_of.get(key(f, {k: v for k, v in f["params"].items() if k != "EFIFO_LOG2"}))
        if base is None:
            continue
        ram = [f"{f['brams'] - base['brams']:+d}"]
        if f["lutrams"] or base["lutrams"]:
            ram.append(f"{f['lutrams'] - base['lutrams']:+d} DPR16X4")
        params = ", ".join(f"{k}={v}" for k, v in f["params"].items() if k != "EFIFO_LOG2") or "-"
        rows.append(f"| {f['module']} | {params} | {f['part']} | {1 << int(log2)} | {f['luts']} | "
                    f"{f['luts'] - base['luts']:+d} | {f['ffs'] - base['ffs']:+d} | {', '.join(ram)} | "
                    f"{f['fmax']} (without: {base['fmax']}) |")
    if not rows:
        return []
    return ["", "Edge-capture FIFO (EFIFO_LOG2): the cost of the FIFOs (one per channel), against the "
            "same build without them (rows above). Block RAM for them: SB_RAM40_4K (HX8K) or DP16KD "
            "(ECP5), and the ECP5's DPR16X4.", "",
            "| module | params | part | entries | LUT4 | LUT4 for the FIFOs | FF for them | block RAM for them "
            "| Fmax (MHz) |",
            "|---|---|---|---:|---:|---:|---:|---|---|", *rows]


def markdown(results: list[Result | dict]) -> str:
    """The table file: the rows (measured, or kept from the file by --update) and the FIFO section
    computed from all of them."""
    return "\n".join([
        "<!-- generated by scripts/synth.py (`make synth`); do not edit by hand -->",
        "Yosys `synth_ice40` + nextpnr-ice40 (yowasp builds pinned in requirements.txt), nextpnr "
        f"seeds {SEED} to n, n in the seeds column. Blocks: {BLOCK_DEVICE_NAME}, I/O placed by nextpnr, "
        f"target {FMAX_TARGET_MHZ} MHz so that Fmax is the best nextpnr achieved. Board top: "
        "iCE40UP5K-SG48 (iCEBreaker) with "
        "boards/icebreaker/icebreaker.pcf and the 12 MHz clock of boards/icebreaker/icebreaker.sdc. "
        f"ECP5 rows: `synth_ecp5` + nextpnr-ecp5, {ECP5_DEVICE_NAME}. "
        "LUT4 = SB_LUT4 (iCE40) or LUT4 (ECP5) cells after synthesis (carry-chain LUTs included on "
        "iCE40), FF = SB_DFF* / TRELLIS_FF cells, carry = SB_CARRY / CCU2C. Fmax: median over the "
        "seeds shown (a seed whose nextpnr run was stopped at the route time limit, --pnr-limit, "
        "is left out, and the cell names it). Block RAM: SB_RAM40_4K / DP16KD cells, and the ECP5's distributed RAM "
        "(TRELLIS_DPR16X4, 16 x 4 bits in the LUTs of a slice, not in the LUT4 column). Placed: the "
        "LUT4 sites nextpnr used after packing (iCE40 logic cells, ECP5 TRELLIS_COMB: LUT4, carry "
        "and distributed RAM) of the part's. A build with more LUT4, flip-flops or block RAMs than "
        f"its part holds ({CAPACITY['hx8k']:,} logic cells and {BRAM_CAPACITY['hx8k']} SB_RAM40_4K on "
        f"the HX8K; {CAPACITY['ecp5']:,} LUT4, where each CCU2C takes two more, and "
        f"{BRAM_CAPACITY['ecp5']} DP16KD on the LFE5U-25F) is not placed: its placed cell shows the "
        "sites it needs once nextpnr has packed it (--pack-only; a flip-flop or carry that cannot share "
        "a LUT4's site takes one of its own, so this is more than the LUT4 column). ENGINE=1: the channels "
        "share one engine (rtl/enc_qei_engine.v); without it, a datapath per channel. LUT4 versus "
        "CHANNELS for both, with the cost of one more channel: "
        f"[{CHANNELS_MD.name}]({CHANNELS_MD.name}).",
        "",
        table(results),
        *efifo_table(results),
        "",
    ])


# ------------------------------------------------------------------------------------------------
# the table a run replaces
# ------------------------------------------------------------------------------------------------
def kept_rows(path: Path) -> dict[tuple[str, str, str], dict]:
    """The table file's rows, (module, params, part) -> column name -> cell (by the file's own
    header, so a row of a table with other columns keeps what it has). The edge FIFO section is
    not kept: markdown() computes it again from the whole table."""
    rows: dict[tuple[str, str, str], dict] = {}
    if not path.exists():
        return rows
    lines = path.read_text().splitlines()
    head = next((split_row(l) for l in lines if l.startswith("| module |")), [])
    for line in lines:
        if line.startswith("Edge-capture FIFO"):
            break  # the FIFO table: its rows are not results rows
        cols = split_row(line)
        if head and len(cols) == len(head) and cols != head and not set(cols[0]) <= set("-:"):
            rows.setdefault((cols[0], cols[1], cols[2]), dict(zip(head, cols)))
    return rows


def split_row(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")] if line.startswith("|") else []


def previous_rows(path: Path) -> dict[tuple[str, str, str], tuple[int, float | None]]:
    """(module, params, part) -> (LUT4, Fmax) of each row of the results table on disk that has
    figures (kept_rows' rows; Fmax None where the cell is not a plain number)."""
    out = {}
    for key, row in kept_rows(path).items():
        if not row.get("LUT4", "").isdigit():
            continue
        try:
            fmax = float(row.get("Fmax (MHz)", ""))
        except ValueError:
            fmax = None
        out[key] = (int(row["LUT4"]), fmax)
    return out


def changes(results: list[Result], before: dict) -> list[str]:
    """One line per row whose LUT4 or Fmax differs from the table this run replaces."""
    lines = []
    for r in results:
        b = r.block
        old = before.get((b.name, b.param_text, b.part))
        if r.status != "ok" or old is None:
            continue
        luts, fmax = old
        diff = []
        if r.luts != luts:
            diff.append(f"LUT4 {luts} -> {r.luts} ({r.luts - luts:+d})")
        if fmax is not None and r.fmax is not None and abs(r.fmax - fmax) >= 0.05:
            diff.append(f"Fmax {fmax:.1f} -> {r.fmax:.1f} MHz ({r.fmax - fmax:+.1f})")
        if diff:
            lines.append(f"  {b.name} {b.param_text} ({b.part}): {', '.join(diff)}")
    return lines
