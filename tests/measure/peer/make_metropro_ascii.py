"""Writes metropro-1-window.asc: a 64 x 48 window of metropro-1.dat as
Zygo MetroPro's ASCII export lays it out (MetroPro Reference Guide,
Zygo OMP-0347-M, "ASCII Data File Format", p. 449). No public ASCII
export was found; this file is built from that documentation, from the
header values and raw phase integers of the binary file another program
(a Zygo instrument) wrote. Run from this folder: python3 make_metropro_ascii.py
"""
import struct

X0, Y0, W, H = 100, 200, 64, 48

b = open("metropro-1.dat", "rb").read()
hdr = struct.unpack(">I", b[6:10])[0]
iw, ih, nb = struct.unpack(">HHH", b[52:58])
intens_bytes = struct.unpack(">I", b[60:64])[0]
pw, ph = struct.unpack(">HH", b[68:72])
s, lam, na, obl, mag, res = struct.unpack(">ffffff", b[164:188])
phase_res = struct.unpack(">H", b[218:220])[0]
inverted = struct.unpack(">H", b[232:234])[0]
ts = struct.unpack(">I", b[76:80])[0]
start = hdr + intens_bytes
phase = struct.unpack(">%di" % (pw * ph), b[start:start + 4 * pw * ph])

lines = [
    "Zygo ASCII Data File - Format 2",
    '1 8 2 0 "built from metropro-1.dat"',
    "0 0 0 0 0 0",
    "%d %d %d %d" % (X0, Y0, W, H),
    '"window of metropro-1.dat"',
    '""',
    '""',
    "0 %r %r %r %r %r %r %d" % (s, lam, na, obl, mag, res, ts),
    '640 480 0 0 0 0 ""',
    "0 0 0 0 0 0 0 0 0 0",
    "%d 1 0 0 0 0 0 %d 0" % (phase_res, inverted),
    '0 ""',
    "1 0",
    '""',
    "#",
    "#",
]
vals = [phase[(Y0 + j) * pw + X0 + i] for j in range(H) for i in range(W)]
for k in range(0, len(vals), 10):
    lines.append(" ".join(str(v) for v in vals[k:k + 10]))
lines.append("#")
open("metropro-1-window.asc", "w").write("\n".join(lines) + "\n")
