# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP streams onto shape keys (bpy-free): which keys a stream drives, the key values per
scene frame (the FAT rule of docs/fat.md), resampling to the scene's frame rate and the
scene's frame-rate fields.

A shape key is named by the grammar of docs/fat.md (fap3_open_jaw@512, viseme1,
expression1@40); the Basis and other keys are not driven.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import mpeg4face
import numpy as np
import numpy.typing as npt

VISEME_FAP = 1
EXPRESSION_FAP = 2
BLEND_FULL = 63  # viseme_blend: 63 is viseme_select1 alone
SLIDER_LIMIT = 10.0  # Blender's bound for a shape key's slider_min / slider_max
RESAMPLE_METHODS = ("HOLD", "LINEAR")

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class FaceKey:
    """A shape key the grammar names: a low-level FAP at an amplitude, or a viseme /
    expression (fap 1 / 2) with its select and amount."""

    name: str
    fap: int
    select: int
    amplitude: int


@dataclass
class FaceKeys:
    """The shape keys of a mesh sorted by what drives them."""

    keys: list[FaceKey] = field(default_factory=list)
    malformed: list[str] = field(default_factory=list)  # "name: reason"

    def of(self, fap: int) -> list[FaceKey]:
        return [k for k in self.keys if k.fap == fap]


def face_keys(names: Iterable[str]) -> FaceKeys:
    """Parses shape key names; names that are not ours are skipped, ours but malformed
    (fap3@512.001, Blender's duplicate suffix) are listed with the parser's reason."""
    out = FaceKeys()
    for name in names:
        try:
            parsed = mpeg4face.parse_shape_key_name(name)
        except mpeg4face.Error as error:
            out.malformed.append(f"{name}: {error}")
            continue
        if parsed is not None:
            out.keys.append(FaceKey(name, parsed["fap"], parsed["select"], parsed["amplitude"]))
    return out


def border_weights(values: npt.ArrayLike, amplitudes: Sequence[int]) -> Array:
    """The weight of each amplitude's key for each value: (F, len(amplitudes)).

    The FAT rule through the core (mpeg4face.border_weights), the borders being {0,
    amplitudes} (0: the Basis): a value between borders b_i < b_i+1 gives the key at b_i
    1 - t and the key at b_i+1 t; beyond the outermost border the outermost interval
    continues. Keys at the same amplitude each get that amplitude's weight."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    borders = sorted({0, *(int(a) for a in amplitudes)})
    if len(borders) == 1:
        return np.zeros((len(v), len(amplitudes)))
    weights = mpeg4face.border_weights(borders, v)
    return weights[:, [borders.index(int(a)) for a in amplitudes]]


def viseme_weights(visemes: npt.ArrayLike, select: int) -> Array:
    """The weight of viseme `select`'s key per frame from (F, 4) select1, select2, blend,
    def: blend / 63 as select1 plus (63 - blend) / 63 as select2 (they add when equal)."""
    v = np.asarray(visemes, dtype=np.float64).reshape(-1, 4)
    blend = v[:, 2] / BLEND_FULL
    return (v[:, 0] == select) * blend + (v[:, 1] == select) * (1.0 - blend)


def expression_weights(expressions: npt.ArrayLike, keys: Sequence[FaceKey]) -> Array:
    """The weights of expression keys (one select, their amounts) per frame from (F, 6)
    select1, intensity1, select2, intensity2, ...: the intensity of that select through the
    FAT rule over the amounts (one key at amount a: intensity / a)."""
    e = np.asarray(expressions, dtype=np.float64).reshape(-1, 6)
    select = keys[0].select
    intensity = (e[:, 0] == select) * e[:, 1] + (e[:, 2] == select) * e[:, 3]
    return border_weights(intensity, [k.amplitude for k in keys])


def sent_selects(fap: int, rows: np.ndarray) -> set[int]:
    """The visemes (fap 1, rows (F, 4)) or expressions (fap 2, rows (F, 6)) the stream shows
    with some weight, the neutral 0 left out."""
    if fap == VISEME_FAP:
        shown = ((rows[:, 0], rows[:, 2] > 0), (rows[:, 1], rows[:, 2] < BLEND_FULL))
    else:
        shown = ((rows[:, 0], rows[:, 1] != 0), (rows[:, 2], rows[:, 3] != 0))
    return {int(s) for select, weighted in shown for s in select[weighted & (select > 0)]}


def sample_times(frame_numbers: npt.ArrayLike, frame_rate: float) -> Array:
    """Seconds of each stream sample."""
    return np.asarray(frame_numbers, dtype=np.float64) / frame_rate


def scene_frame_count(duration: float, fps: float) -> int:
    """Scene frames k = 0.. whose time k / fps falls inside the stream (k / fps < duration)."""
    return max(1, math.ceil(duration * fps - 1e-9))


def resample(times: Array, rows: npt.ArrayLike, at: Array, method: str) -> Array:
    """Rows (F, C) given at `times` (increasing), at the times `at`. HOLD: the last sample
    at or before the time, as a decoder holds a FAP until it is sent again; LINEAR:
    interpolated between the neighbouring samples. Before the first sample and after the
    last, the first and last rows hold."""
    r = np.asarray(rows, dtype=np.float64)
    r = r.reshape(len(times), -1)
    after = np.searchsorted(times, at, side="right")
    before = np.clip(after - 1, 0, len(times) - 1)
    if method == "HOLD":
        return r[before]
    if method != "LINEAR":
        raise ValueError(f"resample method {method!r}: expected one of {RESAMPLE_METHODS}")
    nxt = np.clip(after, 0, len(times) - 1)
    span = times[nxt] - times[before]
    t = np.divide(at - times[before], span, out=np.zeros_like(at), where=span > 0)
    t = np.clip(t, 0.0, 1.0)[:, None]
    return (1.0 - t) * r[before] + t * r[nxt]


@dataclass
class Bake:
    """Shape key values per scene frame (frame 0 is the stream's start)."""

    frames: int
    curves: dict[str, Array]  # shape key name -> (frames,) values
    baked_faps: list[int]  # FAPs of the stream with a key (1: visemes, 2: expressions)
    missing: list[str]  # what the stream sends that no key shows


def bake(stream: mpeg4face.FapStream, keys: FaceKeys, fps: float, method: str = "HOLD") -> Bake:
    """Key values at the scene frames (k / fps seconds) from the stream's resolved values
    (held, unsent left/right partners mirrored, as the decoder does).

    LINEAR interpolates the low-level FAP values and then applies the FAT rule; viseme and
    expression selects cannot be interpolated, so their key weights are (a cross-fade).
    Visemes 0 and expressions 0 are the neutral face and drive no key. A low-level FAP
    that overrides a viseme or expression (the standard's priority) is not modelled: the
    keys add, so the bake approximates where both move the same vertices."""
    if len(stream) == 0:
        raise ValueError("the stream has no frames")
    resolved = stream.resolved()
    times = sample_times(resolved["frame_numbers"], stream.frame_rate)
    at = np.arange(scene_frame_count(stream.duration, fps)) / fps
    active = np.asarray(resolved["active"]).any(axis=0)
    curves: dict[str, Array] = {}
    baked: set[int] = set()
    missing: list[str] = []

    for fap in range(3, mpeg4face.FAP_COUNT + 1):
        fap_keys = keys.of(fap)
        if not fap_keys:
            if active[fap - 1]:
                missing.append(f"FAP {fap} ({mpeg4face.fap(fap).name})")
            continue
        values = resample(times, resolved["values"][:, fap - 1], at, method)[:, 0]
        weights = border_weights(values, [k.amplitude for k in fap_keys])
        for column, key in enumerate(fap_keys):
            curves[key.name] = weights[:, column]
        if active[fap - 1]:
            baked.add(fap)

    for fap, name, rows in ((VISEME_FAP, "viseme", resolved["visemes"]),
                            (EXPRESSION_FAP, "expression", resolved["expressions"])):
        rows = np.asarray(rows)
        selects = sent_selects(fap, rows)
        by_select: dict[int, list[FaceKey]] = {}
        for key in keys.of(fap):
            by_select.setdefault(key.select, []).append(key)
        for select, select_keys in by_select.items():
            if fap == VISEME_FAP:
                weights = viseme_weights(rows, select)[:, None].repeat(len(select_keys), 1)
            else:
                weights = expression_weights(rows, select_keys)
            weights = resample(times, weights, at, method)
            for column, key in enumerate(select_keys):
                curves[key.name] = weights[:, column]
        if selects & set(by_select):
            baked.add(fap)
        missing.extend(f"{name} {s}" for s in sorted(selects - set(by_select)))

    return Bake(len(at), curves, sorted(baked), missing)


def frame_ranges(frames: npt.ArrayLike) -> str:
    """Increasing frame numbers as runs: [3, 4, 5, 9] -> "3-5, 9"."""
    f = np.asarray(frames, dtype=np.int64).reshape(-1)
    if not len(f):
        return ""
    breaks = np.flatnonzero(np.diff(f) != 1)
    firsts, lasts = f[np.r_[0, breaks + 1]], f[np.r_[breaks, len(f) - 1]]
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in zip(firsts, lasts))


def widened_slider(current: tuple[float, float], values: tuple[float, float]
                   ) -> tuple[float, float, bool]:
    """A shape key's (slider_min, slider_max) widened to hold the values, within Blender's
    ±10, and whether a value lies beyond that (it will be clamped)."""
    low = max(-SLIDER_LIMIT, min(current[0], values[0]))
    high = min(SLIDER_LIMIT, max(current[1], values[1]))
    return low, high, values[0] < -SLIDER_LIMIT or values[1] > SLIDER_LIMIT


def scene_fps(frame_rate: float) -> tuple[int, float]:
    """Blender's (render.fps, render.fps_base) for a frame rate: fps / fps_base = rate
    (29.97 -> 30, 1.001)."""
    fps = max(1, round(frame_rate))
    return fps, fps / frame_rate


def live_index(frame_numbers: npt.ArrayLike, frame_rate: float, seconds: float) -> int:
    """The stream sample shown at a time: the last one at or before it (a decoder holds),
    the first before the stream starts."""
    times = sample_times(frame_numbers, frame_rate)
    return int(max(0, np.searchsorted(times, seconds + 1e-9, side="right") - 1))


def animated_faps(stream: mpeg4face.FapStream) -> set[int]:
    """The FAPs a decoder animates at some frame of the stream (sent, held, or mirrored
    from the other side's; 1: visemes, 2: expressions): the tables of no other FAP can
    show anything while it plays."""
    return {int(i) + 1 for i in np.flatnonzero(stream.resolved()["active"].any(axis=0))}


def encoding_summary(bits: int, bits_per_second: float, psnr: float | None) -> str:
    """"20752 bits, 4803.7 bit/s, PSNR 47.75 dB" (lossless: PSNR infinite; none when there
    was nothing to compare)."""
    if psnr is None or math.isnan(psnr):
        quality = "no PSNR"
    elif math.isinf(psnr):
        quality = "lossless"
    else:
        quality = f"PSNR {psnr:.2f} dB"
    return f"{bits} bits, {bits_per_second:.1f} bit/s, {quality}"

