# SPDX-License-Identifier: Apache-2.0
"""The builds of the results table: the parts, the `Block` rows (`BLOCKS`), a build's `Result`
and whether it fits its part."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..paths import TOP

RTL = TOP / "rtl"
BUILD = TOP / "build" / "synth"
BOARD_BUILD = TOP / "build" / "icebreaker"
CONSTRAINTS = TOP / "boards" / "icebreaker"
WAIVERS = TOP / "scripts" / "synth_waivers.txt"
RESULTS_MD = TOP / "doc" / "results" / "synth_results.md"
CHANNELS_MD = TOP / "doc" / "results" / "synth_channels.md"

BLOCK_DEVICE = ("--hx8k", "--package", "ct256")
BLOCK_DEVICE_NAME = "HX8K ct256"
BLOCK_PINS = 206  # user I/O of the iCE40HX8K-CT256 (iCE40 LP/HX family data sheet, pin table)
ECP5_DEVICE = ("--25k", "--package", "CABGA256")
ECP5_DEVICE_NAME = "LFE5U-25F CABGA256"
ECP5_PINS = 197  # user I/O of the LFE5U-25F in CABGA256
# what each part holds: logic cells (one LUT4 and one flip-flop each) of the iCE40HX8K, LUT4 and
# flip-flops of the LFE5U-25F; block RAMs: 32 SB_RAM40_4K (4 kbit), 56 DP16KD (18 kbit) (iCE40
# LP/HX and ECP5 family data sheets)
CAPACITY = {"hx8k": 7680, "ecp5": 24288}
BRAM_CAPACITY = {"hx8k": 32, "ecp5": 56}
BRAM_CELL = {"hx8k": "SB_RAM40_4K", "ecp5": "DP16KD"}
# the cell nextpnr places a LUT4 in: the iCE40's logic cell, the ECP5's slice half
PLACED_CELL = {"hx8k": "ICESTORM_LC", "ecp5": "TRELLIS_COMB"}
FMAX_TARGET_MHZ = 500  # unreachable on purpose: nextpnr then reports the best it achieved
BOARD_CLOCK_MHZ = 12.0
SEED = 1

LATCH_CELLS = "t:$dlatch t:$adlatch t:$dlatchsr t:$sr"


@dataclass
class Block:
    name: str
    params: dict = field(default_factory=dict)
    lut_goal: int | None = None
    fmax_goal: float | None = None
    board: bool = False  # the iCEBreaker top: UP5K sg48, pcf + clock constraint, bitstream
    device: str = "hx8k"  # hx8k | ecp5
    seeds: int = 1  # nextpnr runs (seeds 1..n); Fmax is their median
    pnr: bool = True  # False: synthesis only (the channel table)
    # under --quick: {} the same build, {NAME: value, ...} these parameters replaced, None left out
    quick: dict | None = field(default_factory=dict)

    @property
    def key(self) -> str:
        """Build directory and table key: name, parameters and device."""
        parts = [self.name] + [f"{k}{v}" for k, v in self.params.items()]
        return "_".join(parts + ([self.device] if self.device != "hx8k" else []))

    @property
    def param_text(self) -> str:
        if self.board:
            return "defaults (12 MHz, 115200 8N1, POS_WIDTH=24)"
        return ", ".join(f"{k}={v}" for k, v in self.params.items()) or "-"

    @property
    def part(self) -> str:
        return "UP5K sg48" if self.board else ECP5_DEVICE_NAME if self.device == "ecp5" else BLOCK_DEVICE_NAME


BLOCKS = [
    Block("enc_conditioner", {"FILTER_LEN": 3}, lut_goal=12),
    Block("enc_x4_decoder", lut_goal=6),
    Block("enc_x2_xor", lut_goal=4),
    Block("enc_x1_hysteresis", lut_goal=6),
    Block("ls168", {"MODULUS": 10}),
    Block("enc_updown_buffer", {"DIGITS": 4, "MODULUS": 10}, lut_goal=80, fmax_goal=150.0),
    Block("enc_phase_meter", {"WINDOW_LOG2": 16}, lut_goal=80, fmax_goal=150.0),
    Block("enc_characterizer"),  # not a contract block: no goal, shown for its cost
    Block("icebreaker_top", board=True),
    # the peripheral: defaults (COUNT_W 32) and COUNT_W 16, iCE40 HX8K and ECP5, median of 3 seeds
    Block("enc_qei_wb", {"COUNT_W": 32}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 16}, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 16}, seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 32}, device="ecp5", seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32}, device="ecp5", seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 16}, device="ecp5", seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 16}, device="ecp5", seeds=3),
    # the counting peripheral alone (PROFILE 1: no timing unit): the 1,500 LUT4 goal
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 1}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32, "PROFILE": 1}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    # COUNT_W 16 with the function fixed (FUNC_MASK 1: x4 only), no timing unit: the row to
    # compare with the bare open decoders
    Block("enc_qei_wb", {"COUNT_W": 16, "PROFILE": 1, "FUNC_MASK": 1}, seeds=3),
    # the edge-capture FIFO of one full channel at 16, 64 and 256 entries: its cost is the
    # difference to the first enc_qei_wb row (report.efifo_table); --quick builds the 16 only
    Block("enc_qei_wb", {"COUNT_W": 32, "EFIFO_LOG2": 4}, seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 32, "EFIFO_LOG2": 6}, seeds=3, quick=None),
    Block("enc_qei_wb", {"COUNT_W": 32, "EFIFO_LOG2": 8}, seeds=3, quick=None),
    # several channels: 16 lean ones on the HX8K, 8 full ones on the ECP5. --quick places 2 lean
    # channels on the HX8K (the multi-channel flow in about a minute) and leaves the ECP5 row out
    # (its place and route takes tens of minutes; the one-channel ECP5 rows check that flow)
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16}, lut_goal=6000, fmax_goal=50.0,
          seeds=3, quick={"CHANNELS": 2}),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 2, "CHANNELS": 8}, fmax_goal=75.0, device="ecp5",
          seeds=3, quick=None),
    # the shared engine (ENGINE 1): 16 lean and 16 full channels on the HX8K, with the engine's
    # goals, and on the ECP5. --quick places 2 lean channels on the HX8K (the engine's flow and its
    # block RAMs) and leaves the rest out
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16, "ENGINE": 1}, lut_goal=2000,
          fmax_goal=50.0, seeds=3, quick={"CHANNELS": 2}),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 2, "CHANNELS": 16, "ENGINE": 1}, lut_goal=3500,
          fmax_goal=50.0, seeds=3, quick=None),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16, "ENGINE": 1}, device="ecp5",
          seeds=3, quick=None),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 2, "CHANNELS": 16, "ENGINE": 1}, device="ecp5",
          seeds=3, quick=None),
    # the most lean channels the HX8K placed, per architecture (one more did not: 5 per channel
    # fill its 7,680 logic cells, 7 on the engine take 96 %, and nextpnr found no legal
    # placement for either). --quick leaves them out
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 4}, seeds=3, quick=None),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 6, "ENGINE": 1}, seeds=3,
          quick=None),
    # ... with an edge FIFO of 16 entries per channel beside the engine (enc_qei_efifo_bank): its
    # cost is the difference to the 16 lean engine rows. Each FIFO has its own memory: on the
    # iCE40 3 SB_RAM40_4K a channel (the HX8K has 32), on the ECP5 distributed RAM
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16, "ENGINE": 1, "EFIFO_LOG2": 4},
          seeds=3, quick=None),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16, "ENGINE": 1, "EFIFO_LOG2": 4},
          device="ecp5", seeds=3, quick=None),
]


# a nextpnr run longer than this is stopped (a router that does not converge); --pnr-limit
PNR_LIMIT_MIN = 60.0


@dataclass
class Result:
    block: Block
    status: str = "ok"  # ok | missing | error | stopped (one seed: the route time limit)
    note: str = ""
    luts: int = 0
    ffs: int = 0
    carries: int = 0
    brams: int = 0  # block RAMs: SB_RAM40_4K (iCE40) or DP16KD (ECP5)
    lutrams: int = 0  # ECP5 distributed RAM (TRELLIS_DPR16X4: 16 x 4 bits in the LUTs of a slice)
    dsps: int = 0
    placed: int | None = None  # LUT4 sites nextpnr used (PLACED_CELL), with their capacity
    placed_of: int | None = None
    packed_only: bool = False  # placed / placed_of: packed only (a build that does not fit)
    fmax: float | None = None
    clock_constraint: float | None = None
    port_bits: int = 0
    failures: list = field(default_factory=list)  # reasons this run must fail
    seconds: float = 0.0
    fits: bool = True  # False: more than the part holds, not placed
    reused: bool = False  # the tool run's inputs were unchanged: its earlier outputs were read
    stopped: list = field(default_factory=list)  # seeds stopped at the route time limit (notes)


def lut_need(res: Result) -> int:
    """The LUT4 a build needs: on the iCE40 the carry logic is in the counted SB_LUT4; on the ECP5
    each CCU2C (two bits of carry chain) takes the two LUT4 of its slice half besides them."""
    return res.luts + (2 * res.carries if res.block.device == "ecp5" else 0)


def fits(res: Result) -> bool:
    """Whether the synthesised build fits its part: LUT4 and flip-flops, and block RAMs."""
    dev = res.block.device
    capacity = CAPACITY.get(dev)
    return ((capacity is None or max(lut_need(res), res.ffs) <= capacity) and
            res.brams <= BRAM_CAPACITY.get(dev, res.brams))
