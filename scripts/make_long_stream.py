#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Long 30 Hz FAP streams assembled from the nine Xface streams (docs/rate-distortion.md).

usage: make_long_stream.py [FAP_DIR [OUT_DIR]]

FAP_DIR defaults to tests/data/xface-fap, OUT_DIR to tests/data/long-30hz. Writes two .fap
files (version 2.1, 30 Hz), deterministic (same bytes on every run and machine):

xface-30hz.fap
    The nine Xface streams (25 Hz) in name order, then again in reverse name order (77.8 s in
    all), each resampled on its own to 30 Hz: output frame m lies at source position
    p = m * 25 / 30; a FAP in both neighbouring source frames gets their linear interpolation,
    rounded (halves away from zero); otherwise, and for the FAP mask and FAP 1/2, the nearer
    frame (the earlier one at a tie). Frames are renumbered 0, 1, ... through the whole stream.
    These are key-framed synthetic animations (Xface's script-to-FAP tool), not tracked data.

xface-30hz-tracked.fap
    The same with what tracked video adds, imitated: the sample positions are jittered by up
    to +-0.15 source frames (uniform), and every low-level value gets coloured noise (AR(1),
    coefficient 0.8) whose standard deviation is 2 % of that FAP's value span in the clean
    stream, at least 1 FAPU. Python's random.Random(1999): Mersenne Twister, the same
    sequence on every platform. It only imitates tracking noise; it is not tracked data.
"""
import math
import os
import random
import sys

SOURCE_RATE = 25
TARGET_RATE = 30
FIELDS = {1: 4, 2: 6}  # FAP 1 and 2 take 4 and 6 integers in a values line
JITTER = 0.15  # source frames
NOISE_AR = 0.8
NOISE_SHARE = 0.02  # of a FAP's value span
SEED = 1999


def read_fap(path):
    """The frames of a .fap as (mask, values) with values {fap: int or tuple}; checks the rate."""
    with open(path) as f:
        lines = [l.split() for l in f if l.strip() and not l.lstrip().startswith("#")]
    header, rows = lines[0], lines[1:]
    if float(header[-2]) != SOURCE_RATE:
        raise SystemExit("%s: %s Hz, expected %d" % (path, header[-2], SOURCE_RATE))
    frames = []
    for mask_line, value_line in zip(rows[0::2], rows[1::2]):
        mask = [int(t) for t in mask_line[-68:]]
        tokens = [int(t) for t in value_line[1:]]
        values, k = {}, 0
        for fap in range(1, 69):
            if mask[fap - 1]:
                n = FIELDS.get(fap, 1)
                values[fap] = tuple(tokens[k:k + n]) if n > 1 else tokens[k]
                k += n
        if k != len(tokens):
            raise SystemExit("%s: values line of frame %s does not match its mask"
                             % (path, value_line[0]))
        frames.append((mask, values))
    return frames


def round_half_away(x):
    return int(math.floor(x + 0.5)) if x >= 0 else -int(math.floor(-x + 0.5))


def resample(frames, jitter_rng):
    """The frames at 30 Hz (see the module doc); jitter_rng None: no jitter."""
    count = (len(frames) - 1) * TARGET_RATE // SOURCE_RATE + 1
    out = []
    for m in range(count):
        p = m * SOURCE_RATE / TARGET_RATE
        if jitter_rng is not None:
            p += jitter_rng.uniform(-JITTER, JITTER)
        p = min(max(p, 0.0), len(frames) - 1.0)
        i = min(int(math.floor(p)), len(frames) - 2) if len(frames) > 1 else 0
        w = p - i
        a = frames[i]
        b = frames[i + 1] if len(frames) > 1 else a
        mask, nearest = (a[0], a[1]) if w <= 0.5 else (b[0], b[1])
        values = {}
        for fap, v in nearest.items():
            if fap >= 3 and fap in a[1] and fap in b[1]:
                values[fap] = round_half_away(a[1][fap] * (1 - w) + b[1][fap] * w)
            else:
                values[fap] = v
        out.append((list(mask), values))
    return out


def add_noise(frames, rng):
    """Coloured noise on every low-level value, 2 % of each FAP's span (at least 1)."""
    span = {}
    for _, values in frames:
        for fap, v in values.items():
            if fap >= 3:
                lo, hi = span.get(fap, (v, v))
                span[fap] = (min(lo, v), max(hi, v))
    state = {fap: 0.0 for fap in span}
    out = []
    for mask, values in frames:
        noisy = dict(values)
        for fap in sorted(span):
            sigma = max(1.0, NOISE_SHARE * (span[fap][1] - span[fap][0]))
            state[fap] = NOISE_AR * state[fap] + rng.gauss(0.0, sigma * math.sqrt(1 - NOISE_AR ** 2))
            if fap in noisy:
                noisy[fap] = round_half_away(noisy[fap] + state[fap])
        out.append((mask, noisy))
    return out


def write_fap(path, name, frames):
    lines = ["2.1 %s %d %d" % (name, TARGET_RATE, len(frames))]
    for number, (mask, values) in enumerate(frames):
        lines.append(" ".join(str(b) for b in mask))
        tokens = [str(number)]
        for fap in sorted(values):
            v = values[fap]
            tokens += [str(x) for x in v] if isinstance(v, tuple) else [str(v)]
        lines.append(" ".join(tokens))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main(argv):
    if len(argv) > 3:
        print(__doc__, file=sys.stderr)
        return 2
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    fap_dir = argv[1] if len(argv) > 1 else os.path.join(root, "tests", "data", "xface-fap")
    out_dir = argv[2] if len(argv) > 2 else os.path.join(root, "tests", "data", "long-30hz")
    names = sorted(n for n in os.listdir(fap_dir) if n.endswith(".fap"))
    order = names + names[::-1]
    sources = {n: read_fap(os.path.join(fap_dir, n)) for n in names}
    os.makedirs(out_dir, exist_ok=True)

    clean = []
    for n in order:
        clean += resample(sources[n], None)
    write_fap(os.path.join(out_dir, "xface-30hz.fap"), "xface-30hz", clean)

    rng = random.Random(SEED)
    tracked = []
    for n in order:
        tracked += resample(sources[n], rng)
    tracked = add_noise(tracked, rng)
    write_fap(os.path.join(out_dir, "xface-30hz-tracked.fap"), "xface-30hz-tracked", tracked)
    for name, frames in (("xface-30hz", clean), ("xface-30hz-tracked", tracked)):
        print("%s.fap: %d frames, %.1f s at %d Hz" % (name, len(frames), len(frames) / TARGET_RATE,
                                                      TARGET_RATE))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
