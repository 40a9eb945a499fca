#!/usr/bin/env python3
"""Adds an effect to recorded hadynet logs after recording (issue 12's
finding 3: effects declared nowhere and made by nothing in the project's
plant, so that the residual loop meets them as it would a real sensor's).

usage: inject_effect.py EFFECT SRC_DIR DST_DIR

Reads every *.csv under SRC_DIR (any depth), writes each, changed, as
DST_DIR/<file name>; comment lines and the header are kept. EFFECT is one
of (channels by their log names, times from the row index and the log's
dt_s):

  delay:CH:STEPS           CH reported STEPS rows late (the first rows
                           repeat its first value)
  drift:GROUP:RATE         every channel of GROUP (GROUP followed by digits)
                           gains a bias RATE * sum |y| dt (RATE per s: a
                           load-driven drift)
  leak:SRC:DST:K           DST reads DST + K * SRC (a cross-talk)
  backlash:CH:WIDTH        CH reads through a play of WIDTH (its units): the
                           reading moves only when the value leaves the band
                           [reading - WIDTH/2, reading + WIDTH/2]
  cyclic:CH:AMPLITUDE:PERIOD
                           CH reads y + AMPLITUDE sin(2 pi y / PERIOD) (an
                           incremental encoder's interpolation error: static,
                           periodic in the reading)
  curve:CH:EXPONENT:REFERENCE
                           CH (a force, read from 0) reads REFERENCE
                           (max(y, 0) / REFERENCE)^EXPONENT (a calibration curve)
  wobble:CH:AMPLITUDE:PERIOD
                           CH (a force, read from 0) reads max(y, 0) (1 +
                           AMPLITUDE sin(2 pi t / PERIOD)), t in s from the
                           log's start (a gain that swings with temperature)
"""
import glob
import math
import os
import sys


def die(message):
    sys.stderr.write("inject_effect: " + message + "\n")
    sys.exit(2)


def column(header, name, path):
    if name not in header:
        die("%s: no channel %s" % (path, name))
    return header.index(name)


def inject(effect, path, lines):
    header_row = next(i for i, l in enumerate(lines) if not l.startswith("#"))
    header = lines[header_row].split(",")
    dt = next((float(l.split(":", 1)[1]) for l in lines[:header_row] if l.startswith("# dt_s:")), None)
    if dt is None:
        die(path + ": no dt_s")
    rows = [l.split(",") for l in lines[header_row + 1:] if l]
    kind, *args = effect.split(":")

    def values(c):
        return [float(r[c]) for r in rows]

    def write(c, ys):
        for r, y in zip(rows, ys):
            r[c] = repr(round(y, 6))

    if kind == "delay" and len(args) == 2:
        c, steps = column(header, args[0], path), int(args[1])
        y = values(c)
        write(c, [y[max(i - steps, 0)] for i in range(len(y))])
    elif kind == "drift" and len(args) == 2:
        rate = float(args[1])
        group = [i for i, n in enumerate(header) if n.startswith(args[0]) and n[len(args[0]):].isdigit()]
        if not group:
            die("%s: no channel of group %s" % (path, args[0]))
        for c in group:
            y, load, out = values(c), 0.0, []
            for v in y:
                load += abs(v) * dt
                out.append(v + rate * load)
            write(c, out)
    elif kind == "leak" and len(args) == 3:
        s, d, k = column(header, args[0], path), column(header, args[1], path), float(args[2])
        write(d, [yd + k * ys for yd, ys in zip(values(d), values(s))])
    elif kind == "backlash" and len(args) == 2:
        c, half = column(header, args[0], path), float(args[1]) / 2
        y = values(c)
        out, reading = [], y[0]
        for v in y:
            reading = min(max(reading, v - half), v + half)
            out.append(reading)
        write(c, out)
    elif kind == "cyclic" and len(args) == 3:
        c, amplitude, period = column(header, args[0], path), float(args[1]), float(args[2])
        write(c, [v + amplitude * math.sin(2 * math.pi * v / period) for v in values(c)])
    elif kind == "curve" and len(args) == 3:
        c, exponent, reference = column(header, args[0], path), float(args[1]), float(args[2])
        write(c, [reference * (max(v, 0.0) / reference) ** exponent for v in values(c)])
    elif kind == "wobble" and len(args) == 3:
        c, amplitude, period = column(header, args[0], path), float(args[1]), float(args[2])
        write(c, [max(v, 0.0) * (1.0 + amplitude * math.sin(2.0 * math.pi * (i * dt) / period))
                  for i, v in enumerate(values(c))])
    else:
        die("unknown effect " + effect + " (see --help)")
    return lines[:header_row + 1] + [",".join(r) for r in rows]


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return
    if len(sys.argv) != 4:
        die("usage: inject_effect.py EFFECT SRC_DIR DST_DIR (--help)")
    effect, src, dst = sys.argv[1:]
    paths = sorted(glob.glob(os.path.join(src, "**", "*.csv"), recursive=True))
    if not paths:
        die("no .csv under " + src)
    os.makedirs(dst, exist_ok=True)
    for path in paths:
        lines = open(path).read().splitlines()
        with open(os.path.join(dst, os.path.basename(path)), "w") as f:
            f.write("\n".join(inject(effect, path, lines)) + "\n")


if __name__ == "__main__":
    main()
