# SPDX-License-Identifier: Apache-2.0
"""The integer calibrating estimator (sw/enc_qei_calib_fx.c) against the double one
(sw/enc_qei_calib.c, which test_velocity_calibration.py holds to hedsmodel.calibration).

Both run on the same entry streams in one process (calibfx_driver.c, gcc -std=c99 -Wall -Wextra
-Werror -pedantic): after every entry every counter and flag must be equal (a decision taken
differently is counted and fails the test), and every reading, in units of 2^-F count/s, within
one unit of the double reading * 2^F (clipped to the integer range), exactly 0 where the double
is 0. Streams: modelled 50-cycle units (constant speed, ramp, reversal, stop, a dip while
learning, no index, LOST entries with and without an index, a missing entry, a missed pulse and
its re-index, a false IDX, a wheel changed, a slipped hub) and a 500-cycle unit on a 16-bit
timebase that wraps every 65 ms, at F = 8 and 16; every disturbed run of the bench
(enctools.velocity.calib_disturb) on a 500-cycle unit at F = 8. Also: no floating point in the
integer version (gcc -mgeneral-regs-only, and no soft-float routine linked on RV32IM), the
comparison fails on broken copies of the integer code, the RV32IM cost program reads what the
native build reads, bad configurations are refused, and doc/results/velocity_calib_fx.md is
current.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess

import numpy as np
import pytest

from enctools.paths import TOP
from enctools.velocity import calib_disturb as cd
from enctools.velocity import calib_fx as cf
from hedsmodel import EncoderUnit, Profile
from hedsmodel.calibration import CalibConfig, stream_ops
from hedsmodel.velocity import Timebase, edge_entries_with_ticks

SW = TOP / "sw"
TB = Timebase(latency_clocks=7)
TOL_UNITS = 1.0
RV_GCC = shutil.which(cf.RV_GCC)


@pytest.fixture(scope="session")
def driver(tmp_path_factory):
    if shutil.which("gcc") is None:
        pytest.skip("gcc not found: the C estimators cannot be compiled here")
    return cf.build_driver(tmp_path_factory.mktemp("calibfx") / "calibfx_driver")


def stream(wf, tb, t_end, cut=None, read_hz=1000.0, t0=0.5e-3):
    ents, ticks = edge_entries_with_ticks(wf, tb)
    if cut is not None:
        ents, ticks = cut(ents, ticks, tb, np.random.default_rng(0))
    tr = np.arange(t0, t_end, 1 / read_hz)
    return list(stream_ops(ents, ticks, tb.ticks(tb.clock_of(tr)), (1 << tb.ts_w) - 1))


def check(exe, name, cfg, ops, fracs=(8, 16), ties_allowed=False):
    """Both versions on ``ops`` at each F: no decision difference (and no tied vote unless
    ``ties_allowed``), every reading within TOL_UNITS; returns the largest difference."""
    worst = 0.0
    for f in fracs:
        c = cf.compare(exe, cfg, ops, f)
        assert c.mismatch is None, (f"{name}, F = {f}: decision difference at entry "
                                    f"{c.mismatch}; figures double / integer "
                                    f"{c.mismatch_figures}")
        assert c.worst <= TOL_UNITS, f"{name}, F = {f}: {c.worst:.4f} units at {c.worst_at}"
        assert c.zero_bad == 0, f"{name}, F = {f}: {c.zero_bad} readings of 0 read non-zero"
        assert ties_allowed or not c.ties, f"{name}, F = {f}: votes tied at {c.ties}"
        for key in ("shape", "line", "edge", "motion"):
            d, i = c.figures[0][key], c.figures[1][key]
            if i >= 0:      # -1: beyond the integer's range (the revolution disagreed)
                assert abs(d - i) <= 1e-6 * abs(d) + 2**-30, f"{name}: {key} {d!r} / {i!r}"
        for key in ("frac fine", "frac coarse"):
            assert abs(c.figures[0][key] - c.figures[1][key]) < 1e-12, (name, key, c.figures)
        print(f"{name}, F = {f}: {c.entries} entries, {c.reads} reads ({c.calibrated_reads} "
              f"calibrated), largest difference {c.worst:.4f} unit, {len(c.ties)} votes tied")
        worst = max(worst, c.worst)
    return worst


def small(rng, cpr=50):
    return EncoderUnit.typical(rng, cpr=cpr)


def lost_entries(frac, n_drop):
    """``n_drop`` consecutive entries missing at ``frac`` of the stream, the next says LOST."""
    def cut(ents, ticks, tb, rng):
        i = int(frac * len(ents))
        keep = ents[:i] + ents[i + n_drop:]
        keep[i] = dataclasses.replace(keep[i], lost=True)
        return keep, np.concatenate([ticks[:i], ticks[i + n_drop:]])
    return cut


def model_cases(rng, cpr=50):
    """(name, cfg, ops) of the model streams (the cases test_velocity_calibration.py runs)."""
    u = small(rng, cpr)
    rpm = float(np.exp(rng.uniform(np.log(300), np.log(6000))))
    rev = 60 / rpm
    cfg = CalibConfig(tick_s=TB.tick_s, cycles=cpr, learn_revs=3,
                      stall_ticks=int(0.05 / TB.tick_s))
    noidx = dataclasses.replace(cfg, use_index=False)
    P = lambda: Profile(cpr=cpr)
    cases = {
        f"constant {rpm:.0f} rpm": (P().constant(rpm, 9 * rev), None, cfg),
        "ramp 100 -> 3000 rpm": (P().ramp(100, 3000, 0.4), None, cfg),
        "reversal 1500 -> -1500 rpm": (P().ramp(1500, -1500, 0.5), None, cfg),
        "stop after 600 rpm": (P().constant(600, 0.6).stop(0.1), None, cfg),
        "dip while learning": (P().constant(1200, 0.1).ramp(1200, 50, 0.02).ramp(50, 1200, 0.02)
                               .constant(1200, 0.6), None, cfg),
        "no index": (P().constant(rpm, 9 * rev), None, noidx),
        "lost entries": (P().constant(rpm, 12 * rev), lost_entries(0.55, 5), cfg),
        "lost, no index": (P().constant(rpm, 12 * rev), lost_entries(0.4, 5), noidx),
        "missing entry": (P().constant(rpm, 12 * rev), cd.drop_entry(8.2 * rev), cfg),
        "missed pulse (re-index)": (P().constant(rpm, 12 * rev), cd.missed_pulse(6.6 * rev), cfg),
        "false IDX": (P().constant(rpm, 12 * rev), cd.index_glitch(6.3 * rev), cfg),
    }
    for name, (prof, cut, c) in cases.items():
        yield name, c, stream(u.waveform(prof, index=True), TB, prof.duration_s, cut)
    for name, u2 in (("wheel changed", small(rng, cpr)),
                     ("hub slipped 90°", dataclasses.replace(
                         u, eccentricity_angle_deg=u.eccentricity_angle_deg + 90))):
        p1 = Profile(cpr=cpr).constant(1200.0, 0.3)
        p2 = Profile(start_deg=p1.end_deg, cpr=cpr).constant(1200.0, 0.6)
        wf = cd.splice(u.waveform(p1, index=True), u2.waveform(p2, index=True), 0.3)
        yield name, cfg, stream(wf, TB, 0.9)


@pytest.mark.parametrize("seed", [11, 12])
def test_matches_double_on_model_streams(driver, seed):
    print(f"stream seed {seed}")
    worst = max(check(driver, name, cfg, ops)
                for name, cfg, ops in model_cases(np.random.default_rng(seed)))
    print(f"largest difference {worst:.4f} unit")


def test_matches_double_with_a_wrapping_timebase(driver):
    """The HEDS-5000's 500 cycles on a 16-bit timebase of 1 us ticks (wraps every 65 ms),
    learnt and in use; a reversal through the index and back. At 3000 rpm a count is 10 ticks:
    the table's deviations are tenths of a count and an edge-check vote can land exactly on its
    threshold, where the double version's rounding and the integer one's go different ways: such
    ties are allowed here, counted and printed (the driver gives the integer version the
    double's vote fraction and goes on): each within 1e-9 of its threshold in the double."""
    rng = np.random.default_rng(13)
    print("seed 13")
    tb16 = Timebase(prescale=99, ts_w=16, latency_clocks=7, tb_offset=(2**16 - 50) * 100)
    u = EncoderUnit.typical(rng)
    prof = Profile().constant(3000, 8 * 0.02).ramp(3000, -3000, 0.05).constant(-3000, 0.1) \
        .ramp(-3000, 3000, 0.05).constant(3000, 0.1)
    cfg = CalibConfig(tick_s=tb16.tick_s, ts_w=16, learn_revs=3, stall_ticks=20000)
    ops = stream(u.waveform(prof, index=True), tb16, prof.duration_s)
    check(driver, "500 cycles, TS_W 16", cfg, ops, ties_allowed=True)
    c = cf.compare(driver, cfg, ops, 8)
    print(f"ties: {c.ties}")
    assert c.calibrated_reads > 100 and all(m < 1e-9 for *_, m in c.ties)


@pytest.mark.parametrize("case", sorted(cd.CASES))
def test_matches_double_on_the_bench_disturbed_runs(driver, case):
    """Every disturbed run of make velocity on a 500-cycle unit, as the bench feeds it."""
    unit = EncoderUnit.typical(np.random.default_rng(61))
    print("seed 61")
    (name, cfg, ops), = cf.disturbed_streams(TB, [("typical", unit)], [case], 0.2, 3.1e-4, 61)
    check(driver, name, cfg, ops, fracs=(8,))


MUTANTS = {
    "a vote cast at 2x the table's effect": ("#define EDGE_SEEN 3u", "#define EDGE_SEEN 2u"),
    "readings one bit off": ("const unsigned s = 32u - st->cfg.frac_bits;",
                             "const unsigned s = 31u - st->cfg.frac_bits;"),
    "the acceleration term's sign": ("return T2 >= T3 ? (int64_t)q : -(int64_t)q;",
                                     "return T2 >= T3 ? -(int64_t)q : (int64_t)q;"),
    "a vote the wrong way round": ("wd_ucmp(&ac, &ar) > 0 : -1", "wd_ucmp(&ac, &ar) < 0 : -1"),
    "the table's mean over one more revolution": ("div_round_i64(st->acc[j], st->cand_n)",
                                                  "div_round_i64(st->acc[j], st->cand_n + 1u)"),
}


@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_the_comparison_fails_on_broken_code(tmp_path, mutant):
    """A copy of the integer code with one deliberate fault: the comparison must see it."""
    if shutil.which("gcc") is None:
        pytest.skip("gcc not found")
    old, new = MUTANTS[mutant]
    src = (SW / "enc_qei_calib_fx.c").read_text()
    assert src.count(old) == 1, f"mutant {mutant!r}: {old!r} not found once"
    (tmp_path / "enc_qei_calib_fx.c").write_text(src.replace(old, new))
    exe = tmp_path / "drv"
    subprocess.run(["gcc", *cf.CFLAGS, f"-I{SW}", str(SW / "enc_qei_calib.c"),
                    str(tmp_path / "enc_qei_calib_fx.c"), str(cf.DRIVER_C), "-lm", "-o",
                    str(exe)], check=True)
    rng = np.random.default_rng(21)
    u = small(rng)
    prof = Profile(cpr=50).constant(1200, 0.3).ramp(1200, 1500, 0.05).constant(1500, 0.3)
    cfg = CalibConfig(tick_s=TB.tick_s, cycles=50, learn_revs=3)
    ops = stream(u.waveform(prof, index=True), TB, prof.duration_s,
                 cut=cd.missed_pulse(0.45))
    with pytest.raises(AssertionError) as e:
        check(exe, mutant, cfg, ops)
    print(f"{mutant}: {str(e.value).splitlines()[0][:200]}")


def test_no_floating_point():
    """gcc -mgeneral-regs-only refuses any float or double operation: the integer version
    compiles with it, the double version does not; on RV32IM the integer version links no
    soft-float routine of libgcc, the double version does."""
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found")
    flags = [gcc, *cf.CFLAGS, "-mgeneral-regs-only", f"-I{SW}", "-c", "-o", "/dev/null"]
    res = subprocess.run(flags + [str(SW / "enc_qei_calib_fx.c")], capture_output=True,
                         text=True)
    assert res.returncode == 0, res.stderr
    res = subprocess.run(flags + [str(SW / "enc_qei_calib.c")], capture_output=True, text=True)
    assert res.returncode != 0, "the check does not see the double version's floating point"
    if RV_GCC is None:
        pytest.skip(f"{cf.RV_GCC} not found: the RV32IM half of the check is skipped")


@pytest.mark.skipif(RV_GCC is None, reason=f"{cf.RV_GCC} not found")
def test_rv32im_build_and_cost(driver, tmp_path):
    """The cost program on RV32IM (enctools.velocity.rv32): no soft-float routine in the integer
    build, some in the double one; the simulated readings equal the native build's."""
    fx, dbl = cf.build_cost(tmp_path), cf.build_cost(tmp_path, double=True)
    assert cf.soft_float_calls(fx) == []
    assert cf.soft_float_calls(dbl), "the soft-float check sees nothing in the double build"
    rng = np.random.default_rng(11)
    print("seed 11")
    u = small(rng)
    prof = Profile(cpr=50).constant(1500, 0.36)
    ops = stream(u.waveform(prof, index=True), TB, prof.duration_s,
                 cut=cd.missed_pulse(0.25))
    cfg = CalibConfig(tick_s=TB.tick_s, cycles=50, learn_revs=3,
                      stall_ticks=int(0.05 / TB.tick_s))
    c = cf.cost(fx, cfg, ops, 8)
    native = cf._native_fx_readings(driver, cfg, ops, 8)
    assert c["readings"] == native
    assert any(r[2] for r in native), "the table was never in use"
    print({k: v for k, v in c.items() if k not in ("readings",)})


def test_bad_configuration_is_refused(driver):
    base = "1e-08 32 500 1 8 0 0.001 0.05 0.005 0.15"
    for fx in ("100000000 32 1000 50000 5000 150000", "100000000 8 0 50000 5000 150000",
               "100000000 8 1000 50000 0 150000", "0 8 1000 50000 5000 150000"):
        res = subprocess.run([str(driver)], input=f"{base} {fx}\n", capture_output=True,
                             text=True)
        assert res.returncode == 2 and "out of range" in res.stderr, fx


def test_results_table_is_current():
    """doc/results/velocity_calib_fx.md names the code it was made with: rerun
    scripts/calib_fx_check.py when that code changes."""
    text = cf.TABLE.read_text()
    assert f"<!-- source {cf.source_hash()} -->" in text, \
        f"{cf.TABLE.relative_to(TOP)} is stale: {', '.join(cf.SOURCES)} changed since it was written"
