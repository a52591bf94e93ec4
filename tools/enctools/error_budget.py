#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""HEDS-5000 error-budget calculator: the application note's worked examples, inputs as flags.

Subcommands (run with no flags, each reproduces the note's example):
  position      position error from cyclic eccentricity (Table 2)            15' / 6' / 27', 225 e°
  state-width   room-temperature state-width error of a batch (Tables 2, 3)  30 / 8.7 / 44 e°
  guardband     room-temperature test limit for a hot, fast minimum state    72 - 28 = 44 e°
  sampling      programmed-input sampling period (or, with --tp-s, speed)    25 µs at 600 rpm
  count-limit   fastest encoder this library's conditioner + decoder counts exactly (ours)

Each prints a table, or with --json one JSON object. Invalid input exits with status 2 and one
line on stderr. The maths lives in python/src/hedsmodel/budget.py, shared with the tests.
"""

from __future__ import annotations

import argparse
import json
import math
import sys


from hedsmodel import budget, note  # noqa: E402


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump), for this and every subparser."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def count(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def build_parser() -> Parser:
    p = Parser(prog="error_budget.py", description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def command(name, help_text, cpr=True):
        sp = sub.add_parser(name, help=help_text, description=help_text)
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        if cpr:
            sp.add_argument("--cpr", type=count, default=note.CPR,
                            help="cycles per revolution (default 500)")
        return sp

    sp = command("position", "Position error from cyclic eccentricity: vector sum x Q_p; "
                             "max = mean + 2 sigma.")
    sp.add_argument("--factor", nargs=2, type=number, action="append", metavar=("MEAN_MM", "SD_MM"),
                    help="an eccentricity factor in mm TIR (repeat; default: Table 2)")
    sp.add_argument("--radius-mm", type=number, default=note.RADIUS_MM,
                    help=f"code wheel radius (default {note.RADIUS_MM})")

    sp = command("state-width", "State-width error of a batch: eccentricity/2 x Q_e + random phase "
                                "+ internal (means summed, sds root-sum-square); p95 = mean + "
                                "1.65 sigma.", cpr=False)
    sp.add_argument("--ecc-mean-mm", type=number, help="total eccentricity mean, mm TIR "
                                                      "(default: Table 2 combined, 0.047)")
    sp.add_argument("--ecc-sd-mm", type=number, help="total eccentricity sd, mm TIR "
                                                    "(default: Table 2 combined, 0.019)")
    sp.add_argument("--random", nargs=3, type=number, action="append", metavar=("MEAN", "SD", "Q"),
                    help="a random phase factor and its sensitivity in e° per unit (repeat; "
                         "default: Table 3)")
    sp.add_argument("--internal", nargs=2, type=number, metavar=("MEAN", "SD"),
                    default=note.INTERNAL, help="internal error in e° (default 12 6)")
    sp.add_argument("--q-e", type=number, default=note.Q_E, help="Q_e, e°/mm (default 550)")

    sp = command("guardband", "Room-temperature state-width test limit that guarantees a minimum "
                              "state time at speed and temperature. The note's text says 60 °C "
                              "but its arithmetic uses 70 °C: the result always follows --temp-c "
                              "(default 70, which reproduces 28 and 44). f is in Hz.")
    sp.add_argument("--rpm", type=number, default=3000.0, help="top speed (default 3000)")
    sp.add_argument("--temp-c", type=number, default=70.0, help="temperature in °C (default 70)")
    sp.add_argument("--alpha", type=number, default=note.ALPHA_WORST,
                    help="pulse-width coefficient, e°/(°C·Hz), 0 .. 1e-3 "
                         "(default 2.5e-5, the worst case)")
    sp.add_argument("--min-state-us", type=number, default=2.0,
                    help="required minimum state time in µs (default 2)")

    sp = command("sampling", "Programmed-input sampling: the longest sampling period for a speed "
                             "(T_p <= T_s (1 - ΔS/90)), or with --tp-s the highest speed for a "
                             "period (f_max = (1 - ΔS/90) / (4 T_p), ω = 2π f_max / N).")
    what = sp.add_mutually_exclusive_group()
    what.add_argument("--rpm", type=number, help="speed (default 600)")
    what.add_argument("--tp-s", type=number, help="sampling period in seconds")
    sp.add_argument("--state-error-deg", type=number, default=45.0,
                    help="state width error ΔS in e°, 0 .. <90 (default 45)")

    sp = command("count-limit", "Highest encoder frequency at which enc_conditioner + decoder "
                                "count exactly: states >= 1.05 clocks and pulses >= 1.05 x "
                                "FILTER_LEN clocks, narrowest state 90 - ΔS, narrowest pulse "
                                "180 - ΔP.")
    sp.add_argument("--clk-hz", type=number, default=12e6,
                    help="sampling clock (default 12e6, the iCEBreaker's)")
    sp.add_argument("--filter-len", type=count, default=3, help="FILTER_LEN, 1 .. 16 (default 3)")
    sp.add_argument("--state-error-deg", type=number, default=45.0,
                    help="state width error ΔS, e° (default 45, the note's data-sheet maximum)")
    sp.add_argument("--pulse-error-deg", type=number,
                    help="pulse width error ΔP, e° (default 2 x ΔS: a pulse is two states)")
    return p


def compute(args) -> tuple[dict, list[tuple[str, str]]]:
    """(JSON object, table rows) for the parsed command line."""
    if args.command == "position":
        factors = [tuple(f) for f in args.factor] if args.factor else None
        r = budget.position_error(factors, args.radius_mm, args.cpr)
        rows = [("Q_p", f"{note.q_p(args.radius_mm):.3f} angular °/mm"),
                ("mean position error", f"{r['mean_arcmin']:.1f} arcmin"),
                ("standard deviation", f"{r['sd_arcmin']:.1f} arcmin"),
                ("maximum (mean + 2 sigma)", f"{r['max_arcmin']:.1f} arcmin"),
                ("maximum, electrical", f"{r['max_elec_deg']:.0f} e°")]
    elif args.command == "state-width":
        factors = [tuple(f) for f in args.random] if args.random else None
        r = budget.state_width_error(args.ecc_mean_mm, args.ecc_sd_mm, factors,
                                     tuple(args.internal), args.q_e)
        rows = [("mean state width error", f"{r['mean_deg']:.1f} e°"),
                ("standard deviation", f"{r['sd_deg']:.1f} e°"),
                ("95 % of units below (mean + 1.65 sigma)", f"{r['p95_deg']:.1f} e°")]
    elif args.command == "guardband":
        r = budget.guardband(args.rpm, args.temp_c, args.alpha, args.min_state_us, args.cpr)
        rows = [("output frequency f", f"{r['f_hz'] / 1e3:.3f} kHz"),
                ("minimum state S_min", f"{r['s_min_deg']:.1f} e°"),
                ("allowed error ΔS_max = 90 - S_min", f"{r['ds_max_deg']:.1f} e°"),
                (f"temperature error α ΔT f at {args.temp_c:g} °C", f"{r['ds_temp_deg']:.1f} e°"),
                ("room-temperature test limit", f"{r['room_limit_deg']:.1f} e°")]
        if r["room_limit_deg"] <= 0:
            rows.append(("note", "no unit can pass: the temperature error alone exceeds ΔS_max"))
    elif args.command == "sampling" and args.tp_s is not None:
        r = budget.sampling_speed(args.tp_s, args.state_error_deg, args.cpr)
        rows = [("highest output frequency", f"{r['f_max_hz']:.1f} Hz"),
                ("highest speed", f"{r['rpm_max']:.1f} rpm"),
                ("highest angular speed", f"{r['omega_max_rad_s']:.2f} rad/s")]
    elif args.command == "sampling":
        r = budget.sampling_period(600.0 if args.rpm is None else args.rpm,
                                   args.state_error_deg, args.cpr)
        rows = [("output frequency f", f"{r['f_hz']:.1f} Hz"),
                ("nominal state time T_s = 1/(4f)", f"{r['ts_s'] * 1e6:.2f} µs"),
                ("longest sampling period T_p", f"{r['tp_max_s'] * 1e6:.2f} µs")]
    else:
        full = budget.count_limit(args.clk_hz, args.filter_len, args.state_error_deg,
                                  args.pulse_error_deg, args.cpr)
        r = {k: full[k] for k in ("f_max_hz", "rpm_max")}
        rows = [("state limit (90 - ΔS) / 360 / 1.05 T", f"{full['f_state_hz'] / 1e3:.1f} kHz"),
                (f"pulse limit (180 - {full['pulse_error_deg']:g}) / 360 / (1.05 x "
                 f"{args.filter_len} T)", f"{full['f_level_hz'] / 1e3:.1f} kHz"),
                ("binding constraint", full["binding"]),
                ("highest output frequency", f"{r['f_max_hz'] / 1e3:.1f} kHz"),
                ("highest speed", f"{r['rpm_max']:.0f} rpm")]
    return r, rows


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        result, rows = compute(args)
    except ValueError as exc:
        parser.exit(2, f"error_budget.py {args.command}: error: {exc}\n")
    if args.json:
        print(json.dumps(result))
    else:
        width = max(len(k) for k, _ in rows)
        print(f"{args.command}:")
        for k, v in rows:
            print(f"  {k:<{width}}  {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
