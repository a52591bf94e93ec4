# SPDX-License-Identifier: Apache-2.0
"""sw/enc_qei_regs.h: the C header of the register map (C99 and C++; the naming scheme is
explained at the top of the header itself, HEADER_DOC below).

- per field: ENC_QEI__<REG>__<FIELD>_bm (mask in the register word), _bp (lsb), _bw (width),
  _reset (the field's reset value, unshifted, for fields that have one), and the helpers
  _SET(v) (v in place), _GET(w) (the field of word w) and _UPDATE(w, v) (w with the field
  replaced);
- per enum member: ENC_QEI__<REG>__<FIELD>__<MEMBER>_VAL (the value in the field, unshifted)
  and ..._bm (the value in place in the register word): two names that say which they are, and
  no bare member name that could be either;
- per register: ENC_QEI_<REG>_OFFSET (its byte offset in its page: the offset the bus sees in
  page 0) and ENC_QEI_<REG>_RESET (the whole register's reset value, for registers whose every
  field has one);
- the pages: ENC_QEI_PAGE, ENC_QEI_CHANNELS_MAX, ENC_QEI_CHAN_ADDR(k, offset);
- structures: enc_qei_chan_t (one channel's page), enc_qei_glb_t (page 0's global registers) and
  enc_qei_t, a union of the two views of the peripheral's address space: q->glb.CAPS,
  q->chan[k].COUNT_LO. Their sizes are checked by a C99 typedef of an array whose size is -1
  when the struct is not one page (C99 has no static_assert).
"""

from __future__ import annotations

from pathlib import Path

from ..regmap import PAGE, channels_max, nodes

GUARD = "ENC_QEI_REGS_H"

HEADER_DOC = """\
// The enc_qei register map (C99 and C++). Registers are 32 bits wide; the reference is
// doc/enc_qei_regs.md, the walk-through doc/enc_qei.md.
//
// Addresses
//   enc_qei_t                  the peripheral's address space, two views of it: q->glb.<REG> (the
//                              global registers, page 0), q->chan[k].<REG> (channel k's page)
//   ENC_QEI_<REG>_OFFSET       a register's byte offset in its page: the offset the bus sees in
//                              page 0; channel k's register is at ENC_QEI_CHAN_ADDR(k, offset)
//                              = k * ENC_QEI_PAGE + offset. A driver reads CAPS.CHANNELS first
//                              and touches pages 0 .. CHANNELS - 1 only.
//   ENC_QEI_<REG>_RESET        the register's reset value, for registers whose every field has
//                              one (the default build, COUNT_W = TS_W = 32; bits a build does not
//                              hold read 0)
// Fields: ENC_QEI__<REG>__<FIELD> followed by
//   _bm                        the field's mask in the register word
//   _bp, _bw                   its lowest bit and its width
//   _reset                     its reset value, as a field value (unshifted)
//   _SET(v)                    the field value v in place: ((v << _bp) & _bm); OR several together
//   _GET(w)                    the field's value in register word w: ((w & _bm) >> _bp)
//   _UPDATE(w, v)              w with the field replaced by v (for read-modify-write)
// Enumerated fields, member <M> (the RDL's enum member, upper case):
//   ENC_QEI__<REG>__<FIELD>__<M>_VAL  the member as a field value (unshifted): for _SET(), or to
//                                     compare with _GET()
//   ENC_QEI__<REG>__<FIELD>__<M>_bm   the member in place in the register word (= _SET(_VAL)):
//                                     OR it into the word, like a one-bit field's _bm
//
//   q->chan[k].CTRL = ENC_QEI__CTRL__EN_bm | ENC_QEI__CTRL__FUNC__X4_bm |
//                     ENC_QEI__CTRL__FILTER_LEN_SET(3u);
//   if (ENC_QEI__CAPS__PROFILE_GET(q->glb.CAPS) == ENC_QEI__CAPS__PROFILE__LEAN_VAL) ...
//
// What a reader could get wrong: a _VAL written into a register lands at bit 0 (write _bm, or
// _SET(_VAL)); a _bm passed to _SET() is shifted twice and masked away; _SET() keeps only the
// field's width (a value too wide loses its upper bits, silently); a multi-bit field is tested
// with _GET(w) == _VAL, not with w & _bm (the members share bits). Every macro is a constant
// expression when its arguments are, and evaluates each argument once (_UPDATE: w once, v once).
"""


def enum_fields():
    """(register, field, enum type) for every field encoded by a SystemRDL enum."""
    return [(r, f, f.get_property("encode")) for _, _, r in nodes() for f in r.fields()
            if f.get_property("encode") is not None]


def register_reset(reg) -> int | None:
    """The whole register's reset value, or None when a field has none (a live or constant
    field: its value is the build's or the hardware's)."""
    value = 0
    for f in reg.fields():
        reset = f.get_property("reset")
        if reset is None:
            return None
        value |= reset << f.lsb
    return value


def field_macros(reg, f) -> list[str]:
    p = f"ENC_QEI__{reg.inst_name}__{f.inst_name}"
    out = [f"#define {p}_bm 0x{((1 << f.width) - 1) << f.lsb:x}u",
           f"#define {p}_bp {f.lsb}", f"#define {p}_bw {f.width}"]
    reset = f.get_property("reset")
    if reset is not None:
        out.append(f"#define {p}_reset 0x{reset:x}u")
    out += [f"#define {p}_SET(v) ((uint32_t)(((uint32_t)(v) << {p}_bp) & {p}_bm))",
            f"#define {p}_GET(w) ((uint32_t)(((uint32_t)(w) & {p}_bm) >> {p}_bp))",
            f"#define {p}_UPDATE(w, v) ((uint32_t)(((uint32_t)(w) & ~{p}_bm) | {p}_SET(v)))"]
    enum = f.get_property("encode")
    for m in enum or ():
        out += [f"#define {p}__{m.name.upper()}_VAL {m.value}u",
                f"#define {p}__{m.name.upper()}_bm 0x{m.value << f.lsb:x}u"]
    return out


def struct(name: str, what: str, regs: list, size: int) -> list[str]:
    """A struct of 32-bit registers at their offsets, padded to ``size`` bytes."""
    out = [f"/* {what} */", "typedef struct {"]
    at = 0
    for off, r in regs:
        if off > at:
            out.append(f"    uint32_t RESERVED_{at:02X}[{(off - at) // 4}];")
        out.append(f"    uint32_t {r.inst_name};  /* 0x{off:02X} */")
        at = off + 4
    if size > at:
        out.append(f"    uint32_t RESERVED_{at:02X}[{(size - at) // 4}];")
    out += [f"}} {name};",
            "/* C99 size check: the array size is -1 (an error) unless the struct is one page */",
            f"typedef char {name}_size_check[(sizeof({name}) == 0x{size:X}u) ? 1 : -1];", ""]
    return out


def c_header(top, path: Path) -> None:
    regs = nodes()
    n = channels_max()
    out = ["// SPDX-License-Identifier: Apache-2.0",
           "// GENERATED by `make regs` (tools/enctools/gen) from rtl/enc_qei.rdl -- do not edit.",
           "//", *HEADER_DOC.splitlines(),
           f"#ifndef {GUARD}", f"#define {GUARD}", "", "#ifdef __cplusplus", 'extern "C" {', "#endif",
           "", "#include <stdint.h>", "",
           f"#define ENC_QEI_PAGE 0x{PAGE:X}u", f"#define ENC_QEI_CHANNELS_MAX {n}u",
           "#define ENC_QEI_CHAN_ADDR(k, offset) ((uint32_t)(k) * ENC_QEI_PAGE + (offset))", ""]
    for group, off, r in regs:
        where = "global, page 0" if group == "glb" else "per channel"
        out.append(f"// reg - {r.inst_name} (0x{off:02X}, {where})")
        out.append(f"#define ENC_QEI_{r.inst_name}_OFFSET 0x{off:02X}u")
        reset = register_reset(r)
        if reset is not None:
            out.append(f"#define ENC_QEI_{r.inst_name}_RESET 0x{reset:08x}u")
        for f in r.fields():
            out += field_macros(r, f)
        out.append("")
    out += struct("enc_qei_chan_t", "one channel's page: enc_qei_t.chan[k], at ENC_QEI_PAGE * k",
                  [(off, r) for g, off, r in regs if g == "chan"], PAGE)
    out += struct("enc_qei_glb_t", "the global registers, in page 0: enc_qei_t.glb",
                  [(off, r) for g, off, r in regs if g == "glb"], PAGE)
    out += ["/* the peripheral's address space, two views of it: q->glb.CAPS, q->chan[k].COUNT_LO */",
            "typedef union {", "    enc_qei_glb_t glb;", "    enc_qei_chan_t chan[ENC_QEI_CHANNELS_MAX];",
            "} enc_qei_t;", "", "#ifdef __cplusplus", "}", "#endif", "", f"#endif /* {GUARD} */", ""]
    path.write_text("\n".join(out))
