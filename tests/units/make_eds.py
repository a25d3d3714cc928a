#!/usr/bin/env python3
"""Writes the drive-unit test EDS files of this folder from
config/examples/cia402-emu.eds (the project's own emulator EDS) by adding
the CiA 402 factor group objects. Run from the repository root:
  /usr/bin/python3 tests/units/make_eds.py
"""
import re
import sys

BASE = "config/examples/cia402-emu.eds"


def var(index, name, dtype, access, value):
    v = "" if value is None else f"DefaultValue={value}\n"
    return (f"[{index:04X}]\nParameterName={name}\nObjectType=0x7\nDataType={dtype}\n"
            f"AccessType={access}\n{v}PDOMapping=0\n\n")


def array2(index, name, s1, s2, v1, v2):
    out = f"[{index:04X}]\nParameterName={name}\nObjectType=0x8\nSubNumber=3\n\n"
    out += f"[{index:04X}sub0]\nParameterName=Highest sub-index supported\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\nPDOMapping=0\n\n"
    for sub, sname, v in ((1, s1, v1), (2, s2, v2)):
        out += f"[{index:04X}sub{sub}]\nParameterName={sname}\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\nDefaultValue={v}\nPDOMapping=0\n\n"
    return out


def make(name, description, objects):
    text = open(BASE).read()
    text = text.replace("FileName=cia402-emu.eds", f"FileName={name}")
    text = re.sub(r"Description=.*", f"Description={description}", text, count=1)
    m = re.search(r"\[OptionalObjects\]\nSupportedObjects=(\d+)\n((?:\d+=0x[0-9A-Fa-f]+\n)+)", text)
    entries = [int(x.split("=")[1], 16) for x in m.group(2).split()]
    entries = sorted(set(entries) | {i for i, _ in objects})
    listing = "[OptionalObjects]\nSupportedObjects=%d\n" % len(entries) + "".join(
        f"{k}=0x{i:04X}\n" for k, i in enumerate(entries, 1))
    text = text[:m.start()] + listing + text[m.end():]
    text = text.rstrip("\n") + "\n\n" + "".join(body for _, body in objects)
    open(f"tests/units/{name}", "w").write(text)


RES = (0x608F, array2(0x608F, "Position encoder resolution", "Encoder increments", "Motor revolutions", 4096, 1))
make("rpm-drive.eds", "canmotion test drive: velocity in rpm (0x60A9 = 0x00B44700, 4096 increments per revolution)",
     [RES, (0x60A9, var(0x60A9, "SI unit velocity", "0x0007", "rw", "0x00B44700"))])
make("incs-drive.eds", "canmotion test drive: velocity in inc/s (0x60A9 = 0x00B50300)",
     [RES, (0x60A9, var(0x60A9, "SI unit velocity", "0x0007", "rw", "0x00B50300"))])
make("unknown-velocity-drive.eds",
     "canmotion test drive: velocity in rpm without 0x608F, so its counts per revolution cannot be known",
     [(0x60A9, var(0x60A9, "SI unit velocity", "0x0007", "ro", "0x00B44700"))])
make("older-factor-drive.eds",
     "canmotion test drive: no 0x60A9, but 0x6094 velocity encoder factor 10:1 (older factor objects)",
     [(0x6094, array2(0x6094, "Velocity encoder factor", "Numerator", "Divisor", 10, 1))])
make("degree-drive.eds",
     "canmotion test drive: position in 0.1 degree (0x60A8 = 0xFF410000), feed constant 3600 per revolution, "
     "velocity in rpm (Nanotec's defaults)",
     [RES, (0x6092, array2(0x6092, "Feed constant", "Feed", "Driving shaft revolutions", 3600, 1)),
      (0x60A8, var(0x60A8, "SI unit position", "0x0007", "rw", "0xFF410000")),
      (0x60A9, var(0x60A9, "SI unit velocity", "0x0007", "rw", "0x00B44700"))])
sys.exit(0)
