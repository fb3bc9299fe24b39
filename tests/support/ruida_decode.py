#!/usr/bin/env python3
"""Decodes a Ruida job (an .rd file, swizzled) into the cuts it makes.

Written from the public descriptions of the protocol alone (edutechwiki's
"Ruida" page and kkaempf/ruida's doc/commands.md), not from Rotafab's C++
code, so that a test can check the driver's bytes against an independent
reading. Prints one line per cut, "x0 y0 x1 y1 power" in millimetres from
the machine's origin (top-left, y down) and percent; exits 1 with a message
on a stream it cannot read, and checks the file's sum (E5 05).

usage: ruida_decode.py FILE [MAGIC]   (MAGIC in hex, 88 by default)
"""
import sys


def unscramble(byte, magic):
    # On the wire: bits 7 and 0 swapped, XOR the magic, plus one.
    byte = ((byte - 1) & 0xFF) ^ magic
    return (byte & 0x7E) | (byte >> 7) | ((byte & 1) << 7)


def number(chunk):
    # Seven bits a byte, most significant first.
    value = 0
    for b in chunk:
        value = (value << 7) | b
    return value


def absolute(chunk):  # five bytes: 35 bits, a 32-bit two's complement
    value = number(chunk) & 0xFFFFFFFF
    return value - (1 << 32) if value & 0x80000000 else value


def relative(chunk):  # two bytes: a signed 14-bit number
    value = number(chunk)
    return value - (1 << 14) if value & 0x2000 else value


def main():
    magic = int(sys.argv[2], 16) if len(sys.argv) > 2 else 0x88
    data = bytes(unscramble(b, magic) for b in open(sys.argv[1], "rb").read())
    starts = [i for i, b in enumerate(data) if b & 0x80]
    if not starts or starts[0] != 0:
        sys.exit("not a Ruida job: it does not start with a command")
    x = y = 0
    power = 0.0
    layer_power = {}
    total = 0
    summed = None
    ended = False
    for n, start in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(data)
        c = data[start:end]
        op = c[0]
        sizes = {0x88: 11, 0xA8: 11, 0x89: 5, 0xA9: 5, 0x8A: 3, 0xAA: 3, 0x8B: 3, 0xAB: 3}
        if op in sizes and len(c) != sizes[op]:
            sys.exit("command %02X at byte %d: %d bytes, want %d" % (op, start, len(c), sizes[op]))
        if op == 0xE5 and c[1:2] == b"\x05":
            summed = absolute(c[2:7])
            continue
        total += sum(c)
        if op in (0x88, 0xA8):
            to = (absolute(c[1:6]), absolute(c[6:11]))
        elif op in (0x89, 0xA9):
            to = (x + relative(c[1:3]), y + relative(c[3:5]))
        elif op in (0x8A, 0xAA):
            to = (x + relative(c[1:3]), y)
        elif op in (0x8B, 0xAB):
            to = (x, y + relative(c[1:3]))
        else:
            to = None
            if op == 0xC6 and c[1] == 0x32:  # a layer's maximum power
                layer_power[c[2]] = number(c[3:5]) * 100.0 / 0x3FFF
            elif op == 0xC6 and c[1] == 0x02:  # the maximum power from here on
                power = number(c[2:4]) * 100.0 / 0x3FFF
            elif op == 0xCA and c[1] == 0x02:  # this layer's settings from here on
                power = layer_power.get(c[2], power)
            elif op == 0xD7:
                ended = True
        if to is None:
            continue
        if op & 0x20:  # A8-AB: the laser lit
            print("%.3f %.3f %.3f %.3f %.2f" % (x / 1000, y / 1000, to[0] / 1000, to[1] / 1000, power))
        x, y = to
    if not ended:
        sys.exit("the job does not end (no D7)")
    if summed is not None and summed != total:
        sys.exit("the file sum is %d, its bytes sum to %d" % (summed, total))


main()
