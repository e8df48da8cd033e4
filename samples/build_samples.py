#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the sample heads from the project's copies of the third-party data.

- candide3.glb: CANDIDE-3 with its feature points and its MPEG-4 FAP units as morph
  targets named in the shape-key grammar (fap3_open_jaw@1000, ...).
- ict_head.glb: the ICT-FaceKit head with its ARKit shapes and the FAP, viseme and
  expression keys made from them (samples/ict_head.py, mpeg4face.arkit_fap_keys).
- makehuman_head.glb: MakeHuman's head cut from the hm08 base mesh, with the eyes, teeth and
  tongue as meshes of their own under their own Transforms, its feature points, FAP shape
  keys cloned from the ICT head's ARKit-derived FAP keys (Facial Motion Cloning),
  MakeHuman's own expression units where one fits a FAP (replacing the cloned key), and
  viseme and expression keys cloned from the ICT head's.
- makehuman_units.json: how each expression unit was mapped (docs/samples.md).

CANDIDE-3 (one vertex per FAP unit) is no longer the MakeHuman head's clone source: cloned
onto a dense head each unit became a tent over CANDIDE's few mouth triangles (issue 19); it
stays a sample and the tests' small clone source.

Run with /usr/bin/python3 and the built module on PYTHONPATH (samples/build.sh does that).
Every output is written to FILE.part and renamed, so a failed run leaves no half file.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import ict_head
import mpeg4face
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CANDIDE = ROOT / "tests/data/candide3"
MAKEHUMAN = ROOT / "tests/data/makehuman"
UNITS = ROOT / "samples/makehuman/expression-units"

# The head is cut from the body above this height (model units, y up): the neck, down to
# below its base (7.2 at 5.89), without the shoulders, which a head rotation must not turn.
NECK_CUT_Y = 5.7
# The OBJ groups that become the head's meshes, each under its own Transform.
PART_GROUPS = {
    "eye_left": "helper-l-eye",
    "eye_right": "helper-r-eye",
    "teeth_upper": "helper-upper-teeth",
    "teeth_lower": "helper-lower-teeth",
    "tongue": "helper-tongue",
}
# A FAP's positive motion as a direction in the MPEG-4 frame (x to the face's left, y up,
# z forward); FAPs of other kinds (rotations, growing, concave) are not measured.
DIRECTIONS = {
    "up": (0.0, 1.0, 0.0),
    "down": (0.0, -1.0, 0.0),
    "left": (1.0, 0.0, 0.0),
    "right": (-1.0, 0.0, 0.0),
    "forward": (0.0, 0.0, 1.0),
}
# A unit fits a FAP when its largest response, in FAPU units, is on that FAP and every
# response of a FAP at another feature point is at most this fraction of it: the unit
# then does what the FAP says and little else, so it can stand for the FAP without moving
# what other FAPs' keys already move.
SPECIFICITY = 0.35
# ... and when the motion at that feature point is mostly along the FAP's direction.
ALIGNMENT = 0.8
# A fitting unit replaces the cloned keys of its FAP and sign only when its value is at least
# this fraction of theirs: a stream sends values up to the source face's key (a capture's
# sneer sends FAP 55 at -900), and a unit worth -75 driven there is 12 times itself, a
# crumpled nose.
COVERAGE = 0.5
# MakeHuman's expression units are sculpted for weights 0..1 (its sliders stop at 1), and
# past its value a unit used as a key would be extrapolated: a stream's blink sends FAP 19 /
# 20 at 1024, one IRISD0, while MakeHuman's lids meet at 801, so the upper lid went through
# the lower one (skin edges 2.3 times their length); disgust sends the nose wings (61 / 62)
# at 50 and hate at 100, the dilatation unit is worth 15, and the nostrils went through
# themselves. A second copy of each unit at this many times its value makes the interval
# past the unit flat: a closed lid stays closed, a flared nostril stays as MakeHuman made it.
UNIT_HELD = 2


def candide3() -> mpeg4face.FaceModel:
    """CANDIDE-3 with its feature points and its FAP units named in the grammar."""
    candide = mpeg4face.read_wfm(CANDIDE / "candide3.wfm")
    model = mpeg4face.candide_to_face_model(candide)
    points, warnings = mpeg4face.read_feature_point_csv(CANDIDE / "feature_points.csv", model)
    for warning in warnings:
        print(f"candide3: {warning}", file=sys.stderr)
    model.feature_points = points
    named = mpeg4face.name_candide_fap_units(model, candide)
    mesh = named.meshes[0]
    # The FAP units only: the other action units (shape units, "Jaw drop") are not FAPs.
    mesh.morph_targets = [t for t in mesh.morph_targets if mpeg4face.parse_shape_key_name(t.name)]
    return named


def merged(meshes: list[mpeg4face.IndexedFaceSet], name: str) -> mpeg4face.IndexedFaceSet:
    """One mesh of several (MakeHuman's four eyelash groups)."""
    offsets = np.cumsum([0] + [m.vertex_count for m in meshes])
    coord_index = np.concatenate([np.where(m.coord_index < 0, -1, m.coord_index + o)
                                  for m, o in zip(meshes, offsets)]).astype(np.int32)
    return mpeg4face.IndexedFaceSet(
        name, np.vstack([m.coord for m in meshes]), coord_index,
        source_index=np.concatenate([m.source_index for m in meshes]))


def makehuman_neutral() -> mpeg4face.FaceModel:
    """The head cut from the base mesh. The skin and eyelashes belong to the root Transform
    "head", placed at 7.1 (the head's rotation centre); each part has a child Transform at
    its own centre (an eyeball turns about it). Feature points from the project's CSV."""
    source = mpeg4face.read_obj(MAKEHUMAN / "base.obj")

    def group(name: str) -> mpeg4face.IndexedFaceSet:
        return source.meshes[source.find_mesh(name)]

    skin = group("body")
    skin.name = "skin"
    lashes = merged([group(f"helper-{side}-eyelashes-{n}") for side in "lr" for n in (1, 2)],
                    "eyelashes")
    parts = []
    for name, g in PART_GROUPS.items():
        parts.append(group(g))
        parts[-1].name = name
    points, _ = mpeg4face.read_feature_point_csv(MAKEHUMAN / "feature_points.csv", source)
    rotation_centre = np.asarray(points["7.1"].position)  # a free coordinate in the CSV
    centres = [(p.coord.min(axis=0) + p.coord.max(axis=0)) / 2 for p in parts]
    for mesh in (skin, lashes):
        mesh.coord = mesh.coord - rotation_centre
    for mesh, centre in zip(parts, centres):
        mesh.coord = mesh.coord - centre
    transforms = [mpeg4face.Transform("head", translation=rotation_centre, meshes=[0, 1],
                                      children=list(range(1, len(parts) + 1)))]
    transforms += [mpeg4face.Transform(p.name, translation=c - rotation_centre, meshes=[i + 2])
                   for i, (p, c) in enumerate(zip(parts, centres))]
    head = mpeg4face.FaceModel(meshes=[skin, lashes, *parts], transforms=transforms, roots=[0])
    # The skin above the neck cut (the parts lie wholly above it).
    head = mpeg4face.cut_face_model(head, (0.0, NECK_CUT_Y, 0.0), (0.0, 1.0, 0.0))
    points, warnings = mpeg4face.read_feature_point_csv(MAKEHUMAN / "feature_points.csv", head)
    for warning in warnings:
        print(f"makehuman: {warning}", file=sys.stderr)
    head.feature_points = points
    head.validate()
    return head


def read_target(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A MakeHuman .target: OBJ vertex numbers and their offsets (SystemExit naming the
    line of a row that is not `vertex x y z`)."""
    vertices, offsets = [], []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        fields = line.split()
        if not fields or line.startswith("#"):
            continue
        try:
            if len(fields) != 4:
                raise ValueError(f"{len(fields)} fields")
            offset = [float(v) for v in fields[1:]]
            if not np.isfinite(offset).all():
                raise ValueError("an offset is not finite")
            vertices.append(int(fields[0]))
            offsets.append(offset)
        except ValueError as error:
            raise SystemExit(f"{path}:{number}: expected 'vertex x y z' ({error})") from None
    if not vertices:
        raise SystemExit(f"{path}: a MakeHuman target without offsets")
    return np.array(vertices, dtype=np.int64), np.array(offsets, dtype=np.float64)


def unit_displacements(head: mpeg4face.FaceModel, vertices: np.ndarray, offsets: np.ndarray
                       ) -> tuple[list[np.ndarray], int]:
    """The target's offsets on each of the head's meshes (through source_index), and how
    many of its vertices the head holds (the rest lie below the cut)."""
    out, held = [], 0
    for mesh in head.meshes:
        lookup = {int(s): i for i, s in enumerate(mesh.source_index)}
        d = np.zeros((mesh.vertex_count, 3))
        for v, o in zip(vertices, offsets):
            i = lookup.get(int(v))
            if i is not None:
                d[i] += o
                held += 1
        out.append(d)
    return out, held


@dataclass
class UnitMapping:
    unit: str
    vertices: int  # of the target
    held: int  # of those, in the head
    fap: int  # 0: not mapped
    value: int  # the FAP value the unit is worth (its key's amplitude)
    key: str
    reason: str
    responses: dict[str, float]  # FAP number -> value at its feature point, the largest few
    used: bool = True  # False: a cloned key of its FAP reaches much farther (COVERAGE)


def fap_responses(head: mpeg4face.FaceModel, fapu: mpeg4face.FapuMeasurement,
                  displacements: list[np.ndarray]) -> dict[int, tuple[float, float]]:
    """FAP -> (the FAP value the displacement is worth at the FAP's feature point, the
    cosine between that point's motion and the FAP's direction)."""
    out = {}
    for info in mpeg4face.faps():
        direction = DIRECTIONS.get(info.positive_motion)
        binding = head.feature_points.get(info.feature_point)
        if direction is None or binding is None or binding.vertex < 0 or not info.fapu:
            continue
        d = displacements[binding.mesh][binding.vertex]
        unit = fapu.unit(info.fapu)
        norm = float(np.linalg.norm(d))
        if unit == 0 or norm == 0:
            continue
        along = float(np.dot(d, direction))
        out[info.number] = (along / unit, along / norm)
    return out


def map_unit(name: str, vertices: int, held: int, responses: dict[int, tuple[float, float]]
             ) -> UnitMapping:
    ranked = sorted(responses.items(), key=lambda kv: -abs(kv[1][0]))
    top = {str(f): round(v, 1) for f, (v, _) in ranked[:4]}
    if not ranked:
        return UnitMapping(name, vertices, held, 0, 0, "", "moves no feature point", top)
    fap, (value, cosine) = ranked[0]
    point = mpeg4face.fap(fap).feature_point
    others = [(f, v) for f, (v, _) in ranked[1:] if mpeg4face.fap(f).feature_point != point]
    rival = max(others, key=lambda fv: abs(fv[1]), default=(0, 0.0))
    if abs(cosine) < ALIGNMENT:
        reason = (f"{point} moves {abs(cosine):.2f} along FAP {fap}'s direction "
                  f"(needs {ALIGNMENT})")
        return UnitMapping(name, vertices, held, 0, 0, "", reason, top)
    if abs(rival[1]) > SPECIFICITY * abs(value):
        reason = (f"FAP {rival[0]} at {mpeg4face.fap(rival[0]).feature_point} moves "
                  f"{abs(rival[1]) / abs(value):.0%} as much as FAP {fap} (at most "
                  f"{SPECIFICITY:.0%})")
        return UnitMapping(name, vertices, held, 0, 0, "", reason, top)
    amplitude = int(round(value))
    key = mpeg4face.format_shape_key_name(fap, amplitude, 0, "mh_" + name)
    return UnitMapping(name, vertices, held, fap, amplitude, key,
                       f"{mpeg4face.fap(fap).name} at {point}", top)


# Cloned copies left out: the eyeballs are rigid parts here (their turns are poses below),
# so the source's eyeball FAPs (23-30) are not cloned.
EYEBALL_FAPS = range(23, 31)
# Pose amplitudes: AU (1e-5 rad) for the eyeball and head rotations.
EYE_POSE_AU = 20000
HEAD_POSE_AU = 20000
ROTATION_POSES = {  # FAP -> (Transform name, axis of the positive motion)
    23: ("eye_left", (0, 1, 0)),  # yaw to the face's left: about +y turns z towards +x
    24: ("eye_right", (0, 1, 0)),
    25: ("eye_left", (1, 0, 0)),  # pitch down: about +x turns z towards -y
    26: ("eye_right", (1, 0, 0)),
    48: ("head", (1, 0, 0)),  # head pitch, down
    49: ("head", (0, 1, 0)),  # head yaw, to the left
    50: ("head", (0, 0, 1)),  # head roll, to the right: about +z turns y towards -x
}
# The lower teeth and tongue follow the chin (2.1) in the jaw FAPs' keys, and in the visemes'
# and expressions' (1, 2), which open the jaw too.
JAW_FAPS = (1, 2, 3, 14, 15)
JAW_PARTS = ("teeth_lower", "tongue")

Keys = dict[str, list[np.ndarray]]  # shape key name -> displacement per mesh


def clone_source(ict: mpeg4face.FaceModel) -> mpeg4face.FaceModel:
    """The ICT head with only its FAP, viseme and expression keys: not its ARKit shapes (not
    in the grammar) or poses (the eyeball turns: the target has its own). The viseme and
    expression keys are cloned as they are: arkit_fap_keys made them from the lip FAPs' keys
    localised, which this head's cloned FAP keys (whole-lip motions, like the ARKit shapes
    they come from) are not, so made again here from them they would add up."""
    def cloned(name: str) -> bool:
        parsed = mpeg4face.parse_shape_key_name(name)
        return bool(parsed) and parsed["fap"] not in EYEBALL_FAPS

    meshes = ict.meshes
    for mesh in meshes:
        mesh.morph_targets = [t for t in mesh.morph_targets if cloned(t.name)]
    ict.meshes = meshes
    ict.animations = []
    if not any(mesh.morph_targets for mesh in meshes):
        raise SystemExit("samples: the ICT head has no FAP keys (the module lacks "
                         "mpeg4face.arkit_fap_keys?)")
    return ict


def cloned_keys(source: mpeg4face.FaceModel, head: mpeg4face.FaceModel) -> Keys:
    """The source's FAP, viseme and expression shapes cloned onto the head and relaxed as
    `animate` relaxes them (docs/clone.md): the FAP shapes smoothed over the skin, the visemes'
    and expressions' fringe feathered, the eyelashes following the skin nearest them. The
    lashes are smoothed along themselves at the end (smooth_lashes), with MakeHuman's units."""
    cloned = mpeg4face.clone_face(source, head, relaxation=mpeg4face.CloneRelaxation(
        fap_passes=CLONE_SMOOTHING_PASSES, attached_passes=0))
    for warning in cloned["warnings"]:
        print(f"clone: {warning}", file=sys.stderr)
    return {c["name"]: every_vertex(head, c) for c in cloned["copies"]
            if c["fap"] not in EYEBALL_FAPS}


def every_vertex(head: mpeg4face.FaceModel, shape: dict) -> list[np.ndarray]:
    """A cloned shape (the vertices that move) as the displacement of every vertex of each
    mesh: the keys are edited as whole meshes, then written as morph targets."""
    out = [np.zeros((len(mesh.coord), 3)) for mesh in head.meshes]
    for moved in shape["meshes"]:
        out[moved["mesh"]][moved["vertices"]] = moved["displacement"]
    return out


# Passes of umbrella smoothing over the skin given to every cloned FAP key. MakeHuman's
# surface meets the ICT head's where their shapes differ (its lower lid and outer eye corner
# land on different parts of the source's lids, its mouth bag and nostrils end the cloned
# region in a step), so a cloned key bends sharply where the source's is smooth: the lifted
# cheeks of joy.fap folded the lower lid over the outer eye corner, the capture's playback had
# spike vertices in every frame, and with 2 passes 24 of the 1091 frames of the sample streams
# still did (in the nostrils and under the chin); with `animate`'s 4, none
# (docs/motion-check.md). The viseme and expression keys are only feathered at their fringe:
# smoothed, their open mouths opened less.
CLONE_SMOOTHING_PASSES = 4


# Every key's lashes (cloned or MakeHuman's own units) are smoothed along the lashes in this
# many passes: MakeHuman's lid units move a strip's inner corner less than its neighbours
# (0.9 mm against 1.9 mm), and so does the skin of the eye's corner a cloned lash follows:
# the capture's blinks made spike vertices of both strips' inner corners; with 4 passes none.
LASH_SMOOTHING_PASSES = 4


def smooth_lashes(head: mpeg4face.FaceModel, keys: Keys) -> None:
    """Each key's motion of the eyelashes relaxed along them (once per motion: a unit and its
    held copy share theirs)."""
    m = head.find_mesh("eyelashes")
    lashes = head.meshes[m]
    for displacements in {id(d): d for d in keys.values()}.values():
        displacements[m] = mpeg4face.relax_displacement(lashes, displacements[m],
                                                        LASH_SMOOTHING_PASSES)


# MakeHuman's upper-lid units unfold the lid's crease on a few rows of small edges: closing,
# its skin there stretches up to 13 times, and with a smile and a lifted cheek pride's shut
# eyes passed the motion check's edge bound. Two passes of Laplacian smoothing over the
# vertices that move less than half as far as the unit's farthest spread the unfolding over
# the lid (edges past twice their length: 52 to 39 an eye); the margin, and so the closed
# lid, stays where MakeHuman put it (the largest change is 1.7 mm, under the brow's fold).
LID_FAPS = (19, 20)
LID_SPREAD_BELOW = 0.5
LID_SPREAD_PASSES = 2


def spread_lid_crease(head: mpeg4face.FaceModel, displacements: list[np.ndarray]) -> None:
    skin = head.find_mesh("skin")
    d = displacements[skin]
    size = np.linalg.norm(d, axis=1)
    moving_less = (size > 0) & (size <= LID_SPREAD_BELOW * size.max())
    displacements[skin] = mpeg4face.relax_displacement(head.meshes[skin], d, LID_SPREAD_PASSES,
                                                       where=moving_less)


def replace_with_units(keys: Keys, units: dict[str, list[np.ndarray]],
                       mappings: list[UnitMapping]) -> None:
    """A mapped unit stands for its FAP in its direction: the cloned keys of that FAP with
    the same sign go, unless they reach much farther than the unit (COVERAGE; the unit is
    then not used)."""
    for m in mappings:
        if not m.fap:
            continue
        same = [name for name in keys
                if (parsed := mpeg4face.parse_shape_key_name(name))["fap"] == m.fap
                and np.sign(parsed["amplitude"]) == np.sign(m.value)]
        # The source's keys themselves, not the copies that hold them past their amplitude
        # (arkit_fap_keys' _reach and _held).
        reach = max((abs(parsed["amplitude"]) for n in same
                     if not (parsed := mpeg4face.parse_shape_key_name(n))["label"].endswith(
                         ("_reach", "_held"))), default=0)
        if abs(m.value) < COVERAGE * reach:
            m.used = False
            m.reason += (f"; not used: the cloned key reaches {reach}, the unit "
                         f"{abs(m.value) / reach:.0%} of it (at least {COVERAGE:.0%})")
            continue
        for name in same:
            del keys[name]
        keys[m.key] = units[m.unit]


def hold_units(keys: Keys, units: dict[str, list[np.ndarray]],
               mappings: list[UnitMapping]) -> None:
    """Each used unit's key held past its value (UNIT_HELD)."""
    for m in mappings:
        if m.fap and m.used:
            keys[mpeg4face.format_shape_key_name(m.fap, UNIT_HELD * m.value, 0,
                                                 f"mh_{m.unit}_held")] = units[m.unit]


def quaternion(axis: tuple[int, int, int], angle: float) -> list[float]:
    half = angle / 2
    return [*(np.asarray(axis, dtype=float) * np.sin(half)), float(np.cos(half))]


def poses(head: mpeg4face.FaceModel, keys: Keys) -> list[mpeg4face.MorphWeightAnimation]:
    """Eyeball and head turns as rotations of their Transforms, and the jaw FAPs' keys
    lowering the lower teeth and tongue with the chin (a pose of the same name as a key is
    one deformed copy with it)."""
    Path = mpeg4face.TransformChannel.Path
    out = []
    for fap, (part, axis) in ROTATION_POSES.items():
        amplitude = HEAD_POSE_AU if part == "head" else EYE_POSE_AU
        index = head.find_transform(part)
        for sign in (1, -1):
            rotation = quaternion(axis, sign * amplitude * 1e-5)
            channel = mpeg4face.TransformChannel(index, Path.ROTATION, times=[0.0],
                                                 values=rotation)
            name = mpeg4face.format_shape_key_name(fap, sign * amplitude, 0,
                                                   mpeg4face.fap(fap).name)
            out.append(mpeg4face.MorphWeightAnimation(name, transform_channels=[channel]))
    chin = head.feature_points["2.1"]
    for name, displacements in keys.items():
        if mpeg4face.parse_shape_key_name(name)["fap"] not in JAW_FAPS:
            continue
        moved = displacements[chin.mesh][chin.vertex]
        channels = []
        for part in JAW_PARTS:
            index = head.find_transform(part)
            channels.append(mpeg4face.TransformChannel(
                index, Path.TRANSLATION, times=[0.0],
                values=head.transforms[index].translation + moved))
        out.append(mpeg4face.MorphWeightAnimation(name, transform_channels=channels))
    return out


def with_keys(head: mpeg4face.FaceModel, keys: Keys,
              animations: list[mpeg4face.MorphWeightAnimation]) -> mpeg4face.FaceModel:
    """The head with each key as a morph target of the meshes it moves."""
    meshes = head.meshes
    for i, mesh in enumerate(meshes):
        mesh.morph_targets = [mpeg4face.MorphTarget(name, d[i]) for name, d in keys.items()
                              if np.any(d[i])]
    head.meshes = meshes
    head.animations = animations
    return head


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "samples/build")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    candide = candide3()
    mpeg4face.write_gltf(candide, args.out / "candide3.glb")
    print(f"samples: candide3.glb, {len(candide.meshes[0].morph_targets)} FAP units")

    ict_head.main(["--out", str(args.out)])
    ict = mpeg4face.read_gltf(args.out / "ict_head.glb")

    head = makehuman_neutral()
    fapu = mpeg4face.measure_fapu(head)
    mappings, units = [], {}
    for path in sorted(UNITS.glob("*.target")):
        vertices, offsets = read_target(path)
        units[path.stem], held = unit_displacements(head, vertices, offsets)
        mappings.append(map_unit(path.stem, len(vertices), held,
                                 fap_responses(head, fapu, units[path.stem])))
    for m in mappings:
        if m.fap in LID_FAPS:
            spread_lid_crease(head, units[m.unit])
    keys = cloned_keys(clone_source(ict), head)
    replace_with_units(keys, units, mappings)
    hold_units(keys, units, mappings)
    smooth_lashes(head, keys)
    head = with_keys(head, keys, poses(head, keys))
    mpeg4face.write_gltf(head, args.out / "makehuman_head.glb")
    mpeg4face.write_file_atomically(args.out / "makehuman_units.json", (
        json.dumps([asdict(m) for m in mappings], indent=1) + "\n").encode())
    mapped = [m for m in mappings if m.fap and m.used]
    print(f"samples: makehuman_head.glb, {sum(m.vertex_count for m in head.meshes)} vertices in "
          f"{len(head.meshes)} meshes, {len(keys)} shape keys ({len(mapped)} of MakeHuman's "
          f"{len(mappings)} expression units), {len(head.animations)} poses")
    return 0


if __name__ == "__main__":
    sys.exit(main())
