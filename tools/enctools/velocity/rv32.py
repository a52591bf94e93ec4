# SPDX-License-Identifier: Apache-2.0
"""A small RV32IM instruction-set simulator that counts what a program executes: enough to run a
bare-metal ELF of riscv64-unknown-elf-gcc -march=rv32im -mabi=ilp32 (no compressed, no CSR, no
traps) and tell how many instructions, and of which kind, each part of it took.

Memory is one flat little-endian space from address 0 (``mem_size`` bytes). Two words outside it
talk to the simulator: a store to ``MARK`` records the value with the instruction count at that
moment (``marks``); a store to ``EXIT`` stops the run with that value. Anything else outside
memory, an unknown instruction or an ECALL raises :class:`SimError`. ``marks`` holds (value,
instructions, multiplications, divisions) so far at each MARK store. Counts per kind: ``insns``
(all), ``mul`` (MUL, MULH, MULHSU, MULHU), ``div`` (DIV, DIVU, REM, REMU), ``load``, ``store``,
``taken`` (jumps and taken branches).
"""

from __future__ import annotations

import struct

MARK = 0xF0000000
EXIT = 0xF0000004
MASK = 0xFFFFFFFF
KINDS = ("insns", "mul", "div", "load", "store", "taken")


class SimError(RuntimeError):
    pass


def _sx(v: int, bits: int) -> int:
    """v (bits wide) as a signed number."""
    return v - (1 << bits) if v >> (bits - 1) & 1 else v


def load_elf(path, mem: bytearray) -> int:
    """Copy the PT_LOAD segments of a 32-bit little-endian RISC-V ELF into ``mem``; the entry."""
    data = open(path, "rb").read()
    if data[:4] != b"\x7fELF" or data[4] != 1 or data[5] != 1:
        raise SimError(f"{path}: not a 32-bit little-endian ELF")
    entry, phoff = struct.unpack_from("<II", data, 24)
    phentsize, phnum = struct.unpack_from("<HH", data, 42)
    for i in range(phnum):
        p_type, off, vaddr, _pa, filesz, memsz = struct.unpack_from("<6I", data, phoff + i * phentsize)
        if p_type != 1:
            continue
        if vaddr + memsz > len(mem):
            raise SimError(f"{path}: segment at {vaddr:#x} beyond memory ({len(mem):#x} bytes)")
        mem[vaddr:vaddr + filesz] = data[off:off + filesz]
        mem[vaddr + filesz:vaddr + memsz] = bytes(memsz - filesz)
    return entry


def _decode(w: int):
    op, rd, f3, rs1, rs2, f7 = w & 0x7F, (w >> 7) & 31, (w >> 12) & 7, (w >> 15) & 31, (w >> 20) & 31, w >> 25
    if op == 0x37:
        return ("lui", rd, 0, 0, w & 0xFFFFF000)
    if op == 0x17:
        return ("auipc", rd, 0, 0, w & 0xFFFFF000)
    if op == 0x6F:
        imm = _sx(((w >> 31) & 1) << 20 | ((w >> 12) & 0xFF) << 12 | ((w >> 20) & 1) << 11
                  | ((w >> 21) & 0x3FF) << 1, 21)
        return ("jal", rd, 0, 0, imm)
    if op == 0x67:
        return ("jalr", rd, rs1, 0, _sx(w >> 20, 12))
    if op == 0x63:
        imm = _sx(((w >> 31) & 1) << 12 | ((w >> 7) & 1) << 11 | ((w >> 25) & 0x3F) << 5
                  | ((w >> 8) & 0xF) << 1, 13)
        name = {0: "beq", 1: "bne", 4: "blt", 5: "bge", 6: "bltu", 7: "bgeu"}.get(f3)
        if name:
            return (name, 0, rs1, rs2, imm)
    if op == 0x03:
        name = {0: "lb", 1: "lh", 2: "lw", 4: "lbu", 5: "lhu"}.get(f3)
        if name:
            return (name, rd, rs1, 0, _sx(w >> 20, 12))
    if op == 0x23:
        name = {0: "sb", 1: "sh", 2: "sw"}.get(f3)
        if name:
            return (name, 0, rs1, rs2, _sx(((w >> 25) << 5) | ((w >> 7) & 31), 12))
    if op == 0x13:
        imm = _sx(w >> 20, 12)
        if f3 == 1 and f7 == 0:
            return ("slli", rd, rs1, 0, rs2)
        if f3 == 5:
            return ("srli" if f7 == 0 else "srai", rd, rs1, 0, rs2)
        name = {0: "addi", 2: "slti", 3: "sltiu", 4: "xori", 6: "ori", 7: "andi"}.get(f3)
        if name:
            return (name, rd, rs1, 0, imm)
    if op == 0x33:
        if f7 == 1:
            return (("mul", "mulh", "mulhsu", "mulhu", "div", "divu", "rem", "remu")[f3],
                    rd, rs1, rs2, 0)
        name = {(0, 0): "add", (0, 0x20): "sub", (1, 0): "sll", (2, 0): "slt", (3, 0): "sltu",
                (4, 0): "xor", (5, 0): "srl", (5, 0x20): "sra", (6, 0): "or", (7, 0): "and"}.get((f3, f7))
        if name:
            return (name, rd, rs1, rs2, 0)
    if op == 0x0F:
        return ("fence", 0, 0, 0, 0)
    raise SimError(f"unknown instruction {w:#010x}")


class Sim:
    """``run()`` from the ELF's entry until a store to EXIT; ``counts`` and ``marks``
    afterwards (one ``run`` per Sim: the marks count from its start)."""

    def __init__(self, elf, mem_size: int = 1 << 23):
        self.mem = bytearray(mem_size)
        self.pc = load_elf(elf, self.mem)
        self.x = [0] * 32
        self.counts = dict.fromkeys(KINDS, 0)
        self.marks = []
        self._dec = {}

    def write_words(self, addr: int, words) -> None:
        struct.pack_into(f"<{len(words)}I", self.mem, addr, *[w & MASK for w in words])

    def read_words(self, addr: int, n: int):
        return list(struct.unpack_from(f"<{n}I", self.mem, addr))

    def run(self, max_insns: int = 10**10) -> int:
        mem, x, dec = self.mem, self.x, self._dec
        size = len(mem)
        n = nmul = ndiv = nld = nst = ntk = 0
        pc = self.pc
        unpack_from, pack_into = struct.unpack_from, struct.pack_into
        code = None
        try:
            while n < max_insns:
                d = dec.get(pc)
                if d is None:
                    if pc + 4 > size or pc & 3:
                        raise SimError(f"pc {pc:#x} outside memory or misaligned")
                    d = dec[pc] = _decode(unpack_from("<I", mem, pc)[0])
                name, rd, rs1, rs2, imm = d
                n += 1
                npc = pc + 4
                if name == "addi":
                    v = (x[rs1] + imm) & MASK
                elif name in ("lw", "lbu", "lb", "lhu", "lh"):
                    a = (x[rs1] + imm) & MASK
                    nld += 1
                    if a >= size:
                        raise SimError(f"load from {a:#x} at pc {pc:#x}")
                    if name == "lw":
                        v = unpack_from("<I", mem, a)[0]
                    elif name == "lbu":
                        v = mem[a]
                    elif name == "lb":
                        v = _sx(mem[a], 8) & MASK
                    elif name == "lhu":
                        v = unpack_from("<H", mem, a)[0]
                    else:
                        v = unpack_from("<h", mem, a)[0] & MASK
                elif name in ("sw", "sb", "sh"):
                    a = (x[rs1] + imm) & MASK
                    nst += 1
                    val = x[rs2]
                    if a >= size:
                        if a == MARK:
                            self.marks.append((val, n, nmul, ndiv))
                        elif a == EXIT:
                            code = val
                            break
                        else:
                            raise SimError(f"store to {a:#x} at pc {pc:#x}")
                    elif name == "sw":
                        pack_into("<I", mem, a, val)
                    elif name == "sb":
                        mem[a] = val & 0xFF
                    else:
                        pack_into("<H", mem, a, val & 0xFFFF)
                    pc = npc
                    continue
                elif name in ("beq", "bne", "blt", "bge", "bltu", "bgeu"):
                    p, q = x[rs1], x[rs2]
                    if name == "beq":
                        t = p == q
                    elif name == "bne":
                        t = p != q
                    elif name == "bltu":
                        t = p < q
                    elif name == "bgeu":
                        t = p >= q
                    elif name == "blt":
                        t = _sx(p, 32) < _sx(q, 32)
                    else:
                        t = _sx(p, 32) >= _sx(q, 32)
                    if t:
                        ntk += 1
                        npc = (pc + imm) & MASK
                    pc = npc
                    continue
                elif name == "add":
                    v = (x[rs1] + x[rs2]) & MASK
                elif name == "sub":
                    v = (x[rs1] - x[rs2]) & MASK
                elif name == "lui":
                    v = imm
                elif name == "auipc":
                    v = (pc + imm) & MASK
                elif name == "jal":
                    v = npc
                    npc = (pc + imm) & MASK
                    ntk += 1
                elif name == "jalr":
                    v = npc
                    npc = (x[rs1] + imm) & ~1 & MASK
                    ntk += 1
                elif name == "slli":
                    v = (x[rs1] << imm) & MASK
                elif name == "srli":
                    v = x[rs1] >> imm
                elif name == "srai":
                    v = (_sx(x[rs1], 32) >> imm) & MASK
                elif name == "andi":
                    v = x[rs1] & (imm & MASK)
                elif name == "ori":
                    v = x[rs1] | (imm & MASK)
                elif name == "xori":
                    v = x[rs1] ^ (imm & MASK)
                elif name == "sltiu":
                    v = int(x[rs1] < (imm & MASK))
                elif name == "slti":
                    v = int(_sx(x[rs1], 32) < imm)
                elif name == "and":
                    v = x[rs1] & x[rs2]
                elif name == "or":
                    v = x[rs1] | x[rs2]
                elif name == "xor":
                    v = x[rs1] ^ x[rs2]
                elif name == "sltu":
                    v = int(x[rs1] < x[rs2])
                elif name == "slt":
                    v = int(_sx(x[rs1], 32) < _sx(x[rs2], 32))
                elif name == "sll":
                    v = (x[rs1] << (x[rs2] & 31)) & MASK
                elif name == "srl":
                    v = x[rs1] >> (x[rs2] & 31)
                elif name == "sra":
                    v = (_sx(x[rs1], 32) >> (x[rs2] & 31)) & MASK
                elif name in ("mul", "mulh", "mulhsu", "mulhu"):
                    nmul += 1
                    p, q = x[rs1], x[rs2]
                    if name == "mul":
                        v = (p * q) & MASK
                    elif name == "mulhu":
                        v = (p * q) >> 32
                    elif name == "mulh":
                        v = ((_sx(p, 32) * _sx(q, 32)) >> 32) & MASK
                    else:
                        v = ((_sx(p, 32) * q) >> 32) & MASK
                elif name in ("div", "divu", "rem", "remu"):
                    ndiv += 1
                    p, q = x[rs1], x[rs2]
                    if name == "divu":
                        v = p // q if q else MASK
                    elif name == "remu":
                        v = p % q if q else p
                    else:
                        sp, sq = _sx(p, 32), _sx(q, 32)
                        if sq == 0:
                            v = MASK if name == "div" else p
                        elif sp == -2**31 and sq == -1:
                            v = p if name == "div" else 0
                        else:
                            qq = abs(sp) // abs(sq) * (1 if (sp < 0) == (sq < 0) else -1)
                            v = (qq if name == "div" else sp - qq * sq) & MASK
                elif name == "fence":
                    pc = npc
                    continue
                else:
                    raise SimError(f"unhandled {name} at pc {pc:#x}")
                if rd:
                    x[rd] = v
                pc = npc
            else:
                raise SimError(f"no exit within {max_insns} instructions")
        finally:
            self.pc = pc
            c = self.counts
            c["insns"] += n
            c["mul"] += nmul
            c["div"] += ndiv
            c["load"] += nld
            c["store"] += nst
            c["taken"] += ntk
        return code
