# SPDX-License-Identifier: GPL-3.0-or-later
"""ARKit heads and Live Link Face captures without bpy, testable with plain pytest: which
shape keys are ARKit blendshapes, the keys `mpeg4face.arkit_fap_keys` made (as shapes in
Blender's axes), the report of the FAPs it made and missed, and where a converted capture's
stream goes (docs/arkit.md)."""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt

import mpeg4face

from . import feature_points, shape_keys

# The labels' endings of the copies arkit_fap_keys adds to hold a FAP key past its reach.
HELD_COPIES = ("_reach", "_held")

Array = npt.NDArray[np.float64]


def arkit_key_names(names: Iterable[str]) -> list[str]:
    """The names that are ARKit blendshapes in any usual spelling (eyeBlinkLeft, eyeBlink_L,
    EyeBlinkLeft, blendShape1.eyeBlinkLeft; the core's arkit_shape_index)."""
    return [n for n in names if mpeg4face.arkit_shape_index(n) is not None]


def made_keys(head: mpeg4face.FaceModel) -> dict[str, Array]:
    """The grammar-named morph targets of the head's first mesh (the FAP, viseme and
    expression keys arkit_fap_keys made) as key name -> displacement in Blender's axes."""
    return {t.name: feature_points.to_blender_axes(t.displacements)
            for t in head.meshes[0].morph_targets if shape_keys.is_grammar_name(t.name)}


def _sign(sign: int) -> str:
    return {1: " +", -1: " -"}.get(sign, "")


@dataclass
class ArkitKeysReport:
    """What "FAP Keys from ARKit Keys" made: a row per FAP key (amplitude, how much of it
    the feature point reached, the residual motion elsewhere), a row per FAP (or FAP side)
    no ARKit shape makes, the number of viseme and expression keys, the core's warnings."""

    head: str
    made: list[str] = field(default_factory=list)
    missed: list[str] = field(default_factory=list)
    visemes: int = 0
    expressions: int = 0
    held: int = 0  # the copies holding FAP keys past their reach (docs/arkit.md, "Held keys")
    written: int = 0
    replaced: int = 0
    warnings: list[str] = field(default_factory=list)

    def summary(self) -> str:
        return (f"{self.head}: {len(self.made)} FAP keys, {self.visemes} viseme and "
                f"{self.expressions} expression keys from its ARKit keys ({self.written} "
                f"shape keys written with {self.held} copies holding the FAP keys past their "
                f"reach, {self.replaced} replaced); {len(self.missed)} FAPs missed")

    def lines(self) -> list[str]:
        return [self.summary(), "Made (amplitude in FAPU units; residual: other feature "
                "points' motion / the FAP's):", *self.made, "Missed:", *self.missed,
                *(f"warning: {w}" for w in self.warnings)]


def keys_report(head: str, result: Mapping[str, object], written: Sequence[str],
                replaced: int) -> ArkitKeysReport:
    """The report of arkit_fap_keys' result; `written` the shape keys written from it."""
    report = ArkitKeysReport(head, written=len(written), replaced=replaced,
                             warnings=list(result["warnings"]))
    for key in result["mapping"]:
        reached = "" if abs(key["reached"] - 1) < 0.005 else f", reached {key['reached']:.0%}"
        pose = "" if key["name"] in written else " (a pose of a Transform: not written)"
        report.made.append(f"{key['name']}: residual {key['residual']:.2f}{reached}{pose}")
    for miss in result["missed"]:
        name = mpeg4face.fap(miss["fap"]).name
        report.missed.append(f"fap{miss['fap']} {name}{_sign(miss['sign'])}: {miss['reason']}")
    for name in written:
        parsed = shape_keys.parse(name)
        report.visemes += parsed["fap"] == 1
        report.expressions += parsed["fap"] == 2
        report.held += parsed["fap"] > 2 and parsed["label"].endswith(HELD_COPIES)
    return report


def capture_stream_path(folder: Path, head: str, capture: str) -> Path:
    """Where a capture converted for a head is written as a .fap (the object remembers it
    for the live preview and the encoder): <head>-<capture's stem>.fap in `folder`."""
    def clean(text: str) -> str:
        return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "face"
    return folder / f"{clean(head)}-{clean(Path(capture).stem)}.fap"
