# SPDX-License-Identifier: Apache-2.0
"""The results table: goal verdicts, the printed table, doc/results/synth_results.md, and the rows
that differ from the table a run replaces."""

from __future__ import annotations

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


def efifo_table(results: list[Result | dict]) -> list[str]:
    """The edge FIFO's cost: each row with EFIFO_LOG2 against the row of the same build without
    it (LUT4, FF and block RAM over it, and its Fmax), from the rows measured by this run."""
    results = [r for r in results if isinstance(r, Result)]
    ok = {(r.block.name, r.block.device, tuple(sorted(r.block.params.items()))): r
          for r in results if r.status == "ok"}
    rows = []
    for r in results:
        log2 = r.block.params.get("EFIFO_LOG2")
        if r.status != "ok" or not log2:
            continue
        base_params = tuple(sorted((k, v) for k, v in r.block.params.items() if k != "EFIFO_LOG2"))
        base = ok.get((r.block.name, r.block.device, base_params))
        if base is None:
            continue
        fmax = f"{r.fmax:.1f}" if r.fmax is not None else "-"
        bfmax = f"{base.fmax:.1f}" if base.fmax is not None else "-"
        rows.append(f"| {r.block.name} | {base.block.param_text} | {1 << log2} | {r.luts} | "
                    f"{r.luts - base.luts:+d} | {r.ffs - base.ffs:+d} | {r.brams - base.brams:+d} | "
                    f"{fmax} (without: {bfmax}) |")
    if not rows:
        return []
    return ["", "Edge-capture FIFO (EFIFO_LOG2): the cost of one channel's FIFO, against the same build "
            "without it (rows above).", "",
            "| module | params | entries | LUT4 | LUT4 for the FIFO | FF for it | SB_RAM40 for it | Fmax (MHz) |",
            "|---|---|---:|---:|---:|---:|---:|---|", *rows]


def markdown(results: list[Result | dict], efifo: list[str] | None = None) -> str:
    """The table file; `efifo`: the FIFO section kept from the table file when this run measured
    none of its rows."""
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
        f"{BRAM_CAPACITY['ecp5']} DP16KD on the LFE5U-25F) is not placed. ENGINE=1: the channels "
        "share one engine (rtl/enc_qei_engine.v); without it, a datapath per channel. LUT4 versus "
        "CHANNELS for both, with the cost of one more channel: "
        f"[{CHANNELS_MD.name}]({CHANNELS_MD.name}).",
        "",
        table(results),
        *(efifo_table(results) or efifo or []),
        "",
    ])


# ------------------------------------------------------------------------------------------------
# the table a run replaces
# ------------------------------------------------------------------------------------------------
def kept_rows(path: Path) -> tuple[dict[tuple[str, str, str], dict], list[str]]:
    """The table file's rows, (module, params, part) -> column name -> cell (by the file's own
    header, so a row of a table with other columns keeps what it has), and its edge FIFO section
    (the lines from its blank line before "Edge-capture FIFO" on)."""
    rows: dict[tuple[str, str, str], dict] = {}
    if not path.exists():
        return rows, []
    lines = path.read_text().splitlines()
    head = next((split_row(l) for l in lines if l.startswith("| module |")), [])
    for line in lines:
        cols = split_row(line)
        if head and len(cols) == len(head) and cols != head and not set(cols[0]) <= set("-:"):
            rows.setdefault((cols[0], cols[1], cols[2]), dict(zip(head, cols)))
        if line.startswith("| module | params | entries"):
            break  # the FIFO table: its rows are not results rows
    start = next((i for i, l in enumerate(lines) if l.startswith("Edge-capture FIFO")), None)
    efifo = [""] + "\n".join(lines[start:]).rstrip().splitlines() if start is not None else []
    return rows, efifo


def split_row(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")] if line.startswith("|") else []


def previous_rows(path: Path) -> dict[tuple[str, str, str], tuple[int, float | None]]:
    """(module, params, part) -> (LUT4, Fmax) of each row of the results table on disk."""
    out = {}
    if not path.exists():
        return out
    for line in path.read_text().splitlines():
        cols = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cols) < 7 or not cols[3].isdigit():
            continue
        try:
            fmax = float(cols[6])
        except ValueError:
            fmax = None
        out[(cols[0], cols[1], cols[2])] = (int(cols[3]), fmax)
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
