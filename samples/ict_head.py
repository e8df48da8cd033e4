#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds samples/build/ict_head.glb: the ICT-FaceKit generic head as an MPEG-4 face.

From tests/data/ict-facekit (MIT, NOTICE.md there): the neutral mesh cut into parts by the
vertex and face ranges of ICT's README, in metres (docs/samples.md, "The ICT head"), with
its 84 MPEG-4 feature points (+7.2) placed by the rules below, and its 57 expression shapes
(Apple ARKit's blendshapes with ICT's names: eyeBlink_L, jawOpen, ...) as morph targets of
the meshes each moves. When the built module has mpeg4face.arkit_fap_keys (issue 18's
mapping), the head also carries the FAP keys, viseme and expression keys and poses it makes.

Run with /usr/bin/python3 and the built module on PYTHONPATH; samples/build_samples.py
calls build() (samples/build.sh). The rules assert what they rely on, so a changed mesh
stops the build instead of giving wrong points.
"""

from __future__ import annotations

import argparse
import heapq
import json
import sys
from pathlib import Path

import mpeg4face
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ICT = ROOT / "tests/data/ict-facekit"

# ICT is in centimetres; the sample is in metres, glTF's unit (a viewer or Blender's
# importer shows the head life-size) and ARKit's.
SCALE = 0.01

# Meshes of the sample: name -> ICT face ranges (inclusive, ICT's README). The skin is one
# mesh: face, head and neck, mouth socket and the two eye sockets share vertices along the
# lip and lid margins, so one mesh keeps the surface closed there (a FAP key or a cloned
# motion cannot tear it). The lacrimal fluid, eye blend and eye occlusion meshes are
# rendering helpers of ICT's shader and are dropped.
PARTS: dict[str, list[tuple[int, int]]] = {
    "skin": [(0, 14033)],
    "eyelashes": [(25304, 26383)],
    "eye_left": [(21496, 23093)],
    "eye_right": [(23094, 24691)],
    "teeth_upper": [(17006, 21495)],  # then kept to the upper teeth's vertices
    "teeth_lower": [(17006, 21495)],
    "gums_tongue": [(14034, 17005)],
}
TEETH_VERTICES = {"teeth_upper": (17039, 19246), "teeth_lower": (19247, 21450)}
RIGID = ("eye_left", "eye_right", "teeth_upper", "teeth_lower", "gums_tongue")
# ICT's eyeLook shapes move the lids and the skin around the eyes but not the eyeballs. The
# sample adds the eyeball's turn to each: at weight 1 a rotation about the eyeball's centre
# by EYE_TURN radians, the rate at which Live Link Face's eye angles follow the eyeLook
# weights in the project's capture (yaw 0.58-0.62 rad per unit of eyeLookOut - eyeLookIn,
# pitch 0.61 per unit of eyeLookUp - eyeLookDown, correlation 0.98-1.0).
EYE_TURN = 0.61
# (axis, sign for the left eye, sign for the right eye) of each eyeLook turn in the
# standard's axes: about +x turns the front (+z) down, about +y to the face's left (+x).
EYE_LOOKS = {"eyeLookUp": ((1, 0, 0), -1, -1), "eyeLookDown": ((1, 0, 0), 1, 1),
             "eyeLookOut": ((0, 1, 0), 1, -1), "eyeLookIn": ((0, 1, 0), -1, 1)}
# Landmark numbers in the common 68-point order (ICT's idx_to_landmark_verts), by side:
# the face's left (+x) is the image's right, the second index of each pair.
LM = {"jaw_mid": 8, "nose_tip": 30, "subnasale": 33, "lip_top": 51, "lip_bottom": 57,
      "inner_top": 62, "inner_bottom": 66}
LM_SIDE = {  # name -> (left, right)
    "brow_inner": (22, 21), "brow_outer": (26, 17), "eye_inner": (42, 39),
    "eye_outer": (45, 36), "nostril": (35, 31), "lip_corner": (54, 48),
}
# The brow in the 68-point order: inner to outer.
BROW = ((22, 23, 24, 25, 26), (21, 20, 19, 18, 17))
OUTER_UPPER_LIP = ((51, 52, 53, 54), (51, 50, 49, 48))
OUTER_LOWER_LIP = ((57, 56, 55, 54), (57, 58, 59, 48))


class Surface:
    """The OBJ's vertices (cm) and the faces of one part, with edge adjacency."""

    def __init__(self, V: np.ndarray, faces: list[np.ndarray]):
        self.V = V
        self.adj: dict[int, set[int]] = {}
        for f in faces:
            for i, v in enumerate(f):
                self.adj.setdefault(int(v), set()).update((int(f[i - 1]), int(f[(i + 1) % len(f)])))
        self.vertices = np.array(sorted(self.adj))
        normals = np.zeros_like(V)
        for f in faces:
            p = V[f]
            across = p[-1] - p[1] if len(f) == 4 else p[1] - p[0]
            np.add.at(normals, f, np.cross(p[2] - p[0], across))
        self.normals = normals / np.maximum(np.linalg.norm(normals, axis=1), 1e-12)[:, None]

    def path(self, a: int, b: int) -> list[int]:
        """The shortest edge path from a to b (Dijkstra on edge lengths)."""
        dist, prev, todo = {a: 0.0}, {}, [(0.0, a)]
        while todo:
            d, v = heapq.heappop(todo)
            if v == b:
                break
            if d > dist[v]:
                continue
            for n in self.adj[v]:
                nd = d + float(np.linalg.norm(self.V[n] - self.V[v]))
                if nd < dist.get(n, np.inf):
                    dist[n], prev[n] = nd, v
                    heapq.heappush(todo, (nd, n))
        out = [b]
        while out[-1] != a:
            out.append(prev[out[-1]])
        return out[::-1]

    def contour(self, vertices: list[int]) -> list[int]:
        """The edge paths through the given vertices in turn."""
        out = [vertices[0]]
        for a, b in zip(vertices, vertices[1:]):
            out += self.path(a, b)[1:]
        return out

    def front(self, x: float, y: float, radius: float = 1.0, band: float = 0.5,
              x_weight: float = 1.0, where: np.ndarray | None = None) -> int:
        """The vertex of the visible front surface nearest to (x, y) in the front view: of
        the forward-facing vertices within `radius` (cm) of (x, y), those within `band` of
        the front-most, the nearest (x distances count x_weight times)."""
        V, idx = self.V, self.vertices if where is None else where
        d = np.hypot(V[idx, 0] - x, V[idx, 1] - y)
        near = idx[(d < radius) & (self.normals[idx, 2] > 0.2)]
        assert len(near), f"no front surface near x={x:.2f} y={y:.2f}"
        near = near[V[near, 2] > V[near, 2].max() - band]
        return int(near[np.argmin(np.hypot(x_weight * (V[near, 0] - x), V[near, 1] - y))])


def read_ict() -> tuple[np.ndarray, list[np.ndarray], list[int], dict[str, np.ndarray]]:
    """ICT's vertices (cm), faces (OBJ order, 0-based), landmark vertices and expressions."""
    obj = mpeg4face.read_obj(ICT / "generic_neutral_mesh.obj").meshes[0]
    assert (obj.source_index == np.arange(obj.vertex_count)).all()
    ci = obj.coord_index
    ends = np.flatnonzero(ci < 0)
    faces = [ci[s:e] for s, e in zip(np.r_[0, ends[:-1] + 1], ends)]
    assert len(faces) == 26384 and obj.vertex_count == 26719, "not ICT's generic neutral mesh"
    landmarks = json.loads((ICT / "vertex_indices.json").read_text())["idx_to_landmark_verts"]
    with np.load(ICT / "expressions.npz") as npz:
        expressions = {name: npz[name].astype(np.float64) for name in npz.files}
    return obj.coord, faces, landmarks, expressions


# ICT's expressions move some vertices alone, their whole one-ring still, by up to 0.03 cm:
# 26 of them (the right side's, sculpted on a slightly different neutral) move two gum
# vertices beside the tongue by 0.017 and 0.004 cm, most move dozens of vertices by float
# rounding (1e-5 cm). That is no motion, but every FAP key made of those shapes carries it:
# the tongue's sliver triangles there turned over in 734 of the sample streams' 1091 frames
# and the vertex stood out as a spike in 180 (docs/samples.md). Such offsets are dropped. A
# neighbour moving less than STILL_BELOW (0.01 mm, rounding) counts as still: the blinks and
# mouthLeft/Right move one more gum vertex by 0.02 cm among neighbours moved 1e-5 cm, and it
# turned a sliver of the tongue over in 10 frames.
ISOLATED_BELOW = 0.05  # cm
STILL_BELOW = 1e-3  # cm


def drop_isolated_offsets(faces: list[np.ndarray], expressions: dict[str, np.ndarray]) -> None:
    """Each expression's vertices that move less than ISOLATED_BELOW while every neighbour
    stays still (moves less than STILL_BELOW), left still; again until none is left (a vertex
    beside a dropped one may be left alone by the drop)."""
    edges = np.concatenate([np.c_[f, np.roll(f, -1)] for f in faces])
    for d in expressions.values():
        while True:
            size = np.linalg.norm(d, axis=1)
            ring = np.zeros(len(d))
            np.maximum.at(ring, edges[:, 0], size[edges[:, 1]])
            np.maximum.at(ring, edges[:, 1], size[edges[:, 0]])
            alone = (size > 0) & (size < ISOLATED_BELOW) & (ring < STILL_BELOW)
            if not alone.any():
                break
            d[alone] = 0


def part_faces(faces: list[np.ndarray], name: str) -> list[np.ndarray]:
    out = [f for a, b in PARTS[name] for f in faces[a:b + 1]]
    if name in TEETH_VERTICES:
        lo, hi = TEETH_VERTICES[name]
        out = [f for f in out if lo <= f.min() and f.max() <= hi]
    return out


def skin_source_index() -> np.ndarray:
    """The ICT vertex numbers of the sample's skin vertices, in order (glTF does not carry
    source_index)."""
    _, faces, _, _ = read_ict()
    return np.unique(np.concatenate(part_faces(faces, "skin")))


def rotation(axis: tuple[int, int, int], angle: float) -> np.ndarray:
    """The 3x3 rotation by `angle` about the unit `axis` (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def add_eye_turns(V: np.ndarray, faces: list[np.ndarray], expressions: dict[str, np.ndarray],
                  centres: dict[str, np.ndarray]) -> None:
    """Each eyeLook shape also turns its eyeball (EYE_TURN) about the eyeball's centre."""
    for eye, suffix, column in (("eye_left", "_L", 1), ("eye_right", "_R", 2)):
        ball = np.unique(np.concatenate(part_faces(faces, eye)))
        for look, spec in EYE_LOOKS.items():
            turn = rotation(spec[0], spec[column] * EYE_TURN)
            p = V[ball] - centres[eye]
            offsets = expressions[look + suffix]
            assert not offsets[ball].any(), f"ICT's {look + suffix} moves the eyeball"
            offsets[ball] = p @ turn.T - p


def eyeball_centre(V: np.ndarray, faces: list[np.ndarray]) -> np.ndarray:
    """The centre of the sphere fitted (least squares) to the back half of the eyeball's
    outer shell (the sclera; the shell holding the most forward vertex, the cornea apex,
    which bulges in front; the inner shell, iris and lens, is no sphere), so an eyeball
    turn about it keeps the ball in its socket."""
    surface = Surface(V, faces)
    apex = int(surface.vertices[np.argmax(V[surface.vertices, 2])])
    shell, todo = {apex}, [apex]
    while todo:
        for n in surface.adj[todo.pop()] - shell:
            shell.add(n)
            todo.append(n)
    P = V[sorted(shell)]
    P = P[P[:, 2] < np.median(P[:, 2])]
    A = np.c_[2 * P, np.ones(len(P))]
    return np.linalg.lstsq(A, (P ** 2).sum(1), rcond=None)[0][:3]


# --- feature points ---------------------------------------------------------------------

Rule = tuple[object, str]  # (OBJ vertex number or free xyz in cm, the rule in words)


def nearest_x(V: np.ndarray, arc: list[int], x: float) -> int:
    return int(min(arc, key=lambda v: abs(V[v, 0] - x)))


def pick_feature_points(V: np.ndarray, faces: list[np.ndarray], landmarks: list[int],
                        eye_centres: dict[str, np.ndarray],
                        jaw_open: np.ndarray) -> dict[str, Rule]:
    """{feature point: (OBJ vertex or free xyz in cm, rule)}; docs/samples.md lists the
    rules."""
    skin_faces = part_faces(faces, "skin")
    skin = Surface(V, skin_faces)
    lm = [int(v) for v in landmarks]
    fp: dict[str, Rule] = {}

    def put(name: str, where: object, rule: str) -> None:
        fp[name] = (where, rule)

    # Orientation: the left eye (ICT's eyeball left) at +x, in front of the head's centre.
    assert eye_centres["eye_left"][0] > 0 > eye_centres["eye_right"][0], "left eye not at +x"
    assert V[lm[LM["nose_tip"]], 2] > V[skin.vertices, 2].mean() + 5, "face does not look along +z"

    midline = skin.vertices[np.abs(V[skin.vertices, 0]) < 1e-6]
    face_mid = midline[V[midline, 2] > 0]

    # Mouth. The lips of the neutral touch: the inner lip contour is where they meet, the
    # upper lip's lowest edge loop and the lower lip's highest one, less than a millimetre
    # apart (ICT's inner lip landmarks 60-67 lie on them). The seam with the mouth socket
    # is further in, out of sight.
    inner_up = skin.contour([lm[i] for i in (64, 63, 62, 61, 60)])
    inner_low = skin.contour([lm[i] for i in (64, 65, 66, 67, 60)])
    l24, l25 = lm[64], lm[60]
    assert V[lm[62], 1] > V[lm[66], 1], "the inner lips overlap"
    put("2.2", lm[62], "landmark 62 (upper lip's inner edge, midline)")
    put("2.3", lm[66], "landmark 66 (lower lip's inner edge, midline)")
    put("2.4", l24, "landmark 64 (inner lip corner)")
    put("2.5", l25, "landmark 60 (inner lip corner)")
    for name, arc, corner in (("2.6", inner_up, l24), ("2.7", inner_up, l25),
                              ("2.8", inner_low, l24), ("2.9", inner_low, l25)):
        put(name, nearest_x(V, arc, V[corner, 0] / 2),
            f"edge path through the {'upper' if arc is inner_up else 'lower'} inner lip landmarks "
            f"(64-60 via {'62' if arc is inner_up else '66'}), "
            f"x nearest {'2.4' if corner == l24 else '2.5'}.x / 2")
    # The outer lip contour: the edge paths through the 68-point outer lip landmarks.
    put("8.1", lm[LM["lip_top"]], "landmark 51 (outer upper lip, midline)")
    put("8.2", lm[LM["lip_bottom"]], "landmark 57 (outer lower lip, midline)")
    for side, (c83, c85, c87, cupid) in enumerate((("8.3", "8.5", "8.7", "8.10"),
                                                   ("8.4", "8.6", "8.8", "8.9"))):
        corner = lm[LM_SIDE["lip_corner"][side]]
        put(c83, corner, f"landmark {LM_SIDE['lip_corner'][side]} (outer lip corner)")
        upper = skin.contour([lm[i] for i in OUTER_UPPER_LIP[side]])
        lower = skin.contour([lm[i] for i in OUTER_LOWER_LIP[side]])
        put(c85, nearest_x(V, upper, V[corner, 0] / 2),
            f"edge path through the outer upper lip landmarks 51..{OUTER_UPPER_LIP[side][-1]}, "
            f"x nearest {c83}.x / 2")
        put(c87, nearest_x(V, lower, V[corner, 0] / 2),
            f"edge path through the outer lower lip landmarks 57..{OUTER_LOWER_LIP[side][-1]}, "
            f"x nearest {c83}.x / 2")
        put(cupid, max(upper[1:-1], key=lambda v: V[v, 1]),
            "highest vertex of that upper-lip path (Cupid's bow)")

    # The midline profile of the face, top to bottom (for the chin and nose).
    profile = face_mid[np.argsort(-V[face_mid, 1])]
    y, z = V[profile, 1], V[profile, 2]
    tip = int(profile[np.argmax(z)])
    assert np.linalg.norm(V[tip] - V[lm[LM["nose_tip"]]]) < 0.5, "landmark 30 is off the nose tip"
    put("9.3", tip, "most forward midline vertex (landmark 30 is 3 mm above it)")
    sub = lm[LM["subnasale"]]
    put("9.15", sub, "landmark 33 (subnasale, bottom of the nose on the midline)")
    # Chin: below the lower lip the profile dips into the labiomental fold, then bulges at
    # the chin boss; the bottom is where the profile turning under the jaw is extreme in the
    # 45-degree direction (0, -1, 1): the chin's lower front corner, as on the MakeHuman head.
    below = [i for i in range(len(profile)) if y[i] < V[fp["8.2"][0], 1] and z[i] > z.max() - 6]
    fold = min(below[: len(below) // 2], key=lambda i: z[i])
    boss = max((i for i in below if y[i] < y[fold]), key=lambda i: z[i])
    put("2.10", int(profile[boss]), "most forward midline vertex below the labiomental fold")
    bottom = max((i for i in below if y[i] < y[boss]), key=lambda i: z[i] - y[i])
    put("2.1", int(profile[bottom]), "midline vertex below 2.10 extreme in direction (0,-1,1)")

    # Eyes. The lid margins seen from the front are the edge loops through the 68-point eye
    # landmarks (the seam with the eye socket, where the lids rest on the eyeball, lies
    # 2-3 mm further up and in, hidden behind them); eyeBlink brings them together.
    eye_names = (("eye_left", ("3.7", "3.11", "3.1", "3.3", "3.13", "3.9", "3.5")),
                 ("eye_right", ("3.12", "3.8", "3.2", "3.4", "3.14", "3.10", "3.6")))
    for side, (eye, names) in enumerate(eye_names):
        o, i, u, d, uo, do, pupil = names
        lo_, li_ = (45, 42) if side == 0 else (36, 39)
        upper_lms, lower_lms = ((42, 43, 44, 45), (42, 47, 46, 45)) if side == 0 else \
            ((39, 38, 37, 36), (39, 40, 41, 36))
        outer, inner = lm[lo_], lm[li_]
        lid_up = skin.contour([lm[k] for k in upper_lms])
        lid_low = skin.contour([lm[k] for k in lower_lms])
        put(o, outer, f"landmark {lo_} (outer eye corner)")
        put(i, inner, f"landmark {li_} (inner eye corner)")
        mid_x = (V[outer, 0] + V[inner, 0]) / 2
        put(u, nearest_x(V, lid_up, mid_x),
            f"edge path through the upper lid landmarks {upper_lms}, x nearest ({o}.x + {i}.x) / 2")
        put(d, nearest_x(V, lid_low, mid_x),
            f"edge path through the lower lid landmarks {lower_lms}, x nearest ({o}.x + {i}.x) / 2")
        # The outer lid contours: the upper lid's crease and the lower lid's border with the
        # cheek, each about 6-7 mm from the margin in adults: a quarter of the eye's width.
        width = abs(V[outer, 0] - V[inner, 0])
        put(uo, skin.front(mid_x, V[fp[u][0], 1] + 0.25 * width, x_weight=4),
            f"front vertex at x = {u}.x, 0.25 W above {u} (W = eye width)")
        put(do, skin.front(mid_x, V[fp[d][0], 1] - 0.25 * width, x_weight=4),
            f"front vertex at x = {d}.x, 0.25 W below {d}")
        ball = np.unique(np.concatenate(part_faces(faces, eye)))
        put(pupil, int(ball[np.argmax(V[ball, 2])]),
            f"{eye} mesh: the most forward vertex (cornea apex)")

    # Eyebrows: the 68-point brow landmarks sit on the brow's upper edge.
    for side, (inner, outer, top) in enumerate((("4.1", "4.5", "4.3"), ("4.2", "4.6", "4.4"))):
        put(inner, lm[BROW[side][0]], f"landmark {BROW[side][0]} (inner brow end)")
        put(outer, lm[BROW[side][-1]], f"landmark {BROW[side][-1]} (outer brow end)")
        brow = skin.contour([lm[i] for i in BROW[side]])
        put(top, max(brow, key=lambda v: V[v, 1]),
            "highest vertex of the edge path through the brow landmarks "
            "(Table 6 allows the top's x)")

    # Nose.
    for side, (n91, n95, n97, n913) in enumerate((("9.1", "9.5", "9.7", "9.13"),
                                                  ("9.2", "9.4", "9.6", "9.14"))):
        s = 1 if side == 0 else -1
        eye_inner = fp["3.11" if side == 0 else "3.8"][0]
        put(n97, skin.front(V[eye_inner, 0] / 2, V[eye_inner, 1]),
            f"front vertex at x = {'3.11' if side == 0 else '3.8'}.x / 2, same y "
            "(side of the nose root)")
        # The nose wing (ala): the vertex furthest out in x of those facing sideways between
        # the subnasale and the tip, within 2.5 cm of the midline.
        vs = skin.vertices
        wing = vs[(s * V[vs, 0] > 0) & (s * V[vs, 0] < 2.5) & (V[vs, 1] > V[sub, 1])
                  & (V[vs, 1] < V[tip, 1]) & (V[vs, 2] > V[sub, 2] - 1)
                  & (s * skin.normals[vs, 0] > 0.6)]
        put(n91, int(max(wing, key=lambda v: s * V[v, 0])),
            "most lateral sideways-facing vertex of the nose wing (y between 9.15 and 9.3)")
        put(n95, lm[LM_SIDE["nostril"][side]],
            f"landmark {LM_SIDE['nostril'][side]} (outer end of the nostril base)")
        fp[n913] = (None, "")  # placed after 9.12
    bone_y = (V[fp["9.6"][0], 1] + V[tip, 1]) / 2
    in_front = V[face_mid, 2] > V[sub, 2]
    put("9.12", int(face_mid[np.argmin(np.abs(V[face_mid, 1] - bone_y) - 1e3 * in_front)]),
        "midline front vertex at y = (9.6.y + 9.3.y) / 2")
    for n913, n97 in (("9.13", "9.7"), ("9.14", "9.6")):
        put(n913, skin.front(V[fp[n97][0], 0], bone_y, band=2, x_weight=0.25),
            f"front vertex at x = {n97}.x, y = 9.12.y (y preferred; on the nose's side)")

    # Cheeks and chin corners, as on the MakeHuman head.
    for side, names in enumerate((("5.1", "5.3", "2.11", "3.7", "3.5", "8.3", "8.7"),
                                  ("5.2", "5.4", "2.12", "3.12", "3.6", "8.4", "8.8"))):
        c51, c53, c211, eye_o, pupil, corner, lower = names
        put(c51, skin.front(V[fp[eye_o][0], 0], V[fp[corner][0], 1], radius=2, x_weight=0.25),
            f"front vertex at x = {eye_o}.x, y = {corner}.y (y preferred)")
        put(c53, skin.front((V[fp[pupil][0], 0] + V[fp[eye_o][0], 0]) / 2,
                            (V[sub, 1] + V[fp["9.12"][0], 1]) / 2),
            f"front vertex at x = ({pupil}.x + {eye_o}.x) / 2, y = (9.15.y + 9.12.y) / 2")
        put(c211, skin.front((V[fp[lower][0], 0] + V[fp[corner][0], 0]) / 2,
                             (V[fp["2.10"][0], 1] + V[fp["2.1"][0], 1]) / 2),
            f"front vertex at x = ({lower}.x + {corner}.x) / 2, y = (2.10.y + 2.1.y) / 2")

    pick_head_points(V, skin, fp, lm)
    pick_mouth_parts(V, faces, fp, jaw_open)

    # Head rotation centres (free coordinates): the top of the spine below the skull between
    # the ears, and the neck's base.
    ears = np.array([V[fp[n][0]] for n in ("10.7", "10.8", "10.9", "10.10")])
    put("7.1", np.array([0.0, (V[fp["10.7"][0], 1] + V[fp["10.8"][0], 1]) / 2, ears[:, 2].mean()]),
        "x = 0, y = the lobes' attachment (10.7, 10.8), z = the ears' attachments' mean "
        "(the atlas)")
    neck = skin.vertices[V[skin.vertices, 1] < V[skin.vertices, 1].min() + 0.5]
    put("7.2", np.array([0.0, V[neck, 1].mean(), V[neck, 2].mean()]),
        "x = 0, the mean y and z of the skin's lowest 5 mm (the neck's cut end)")
    return fp


def pick_head_points(V: np.ndarray, skin: Surface, fp: dict[str, Rule], lm: list[int]) -> None:
    """Ears, jaw corners, hairline and skull."""
    vs = skin.vertices

    def put(name: str, where: object, rule: str) -> None:
        fp[name] = (where, rule)

    for side, names in enumerate((("10.1", "10.3", "10.5", "10.7", "10.9", "2.13"),
                                  ("10.2", "10.4", "10.6", "10.8", "10.10", "2.14"))):
        s = 1 if side == 0 else -1
        top, back, lobe, low_att, up_att, jaw = names
        # The ear: the skin standing out more than 6 mm beyond landmark 16 / 0 (the face
        # contour at the ear's front; the skull is no wider there) within 6 cm behind and
        # 7 cm around it (the back of the skull is as wide only higher up).
        front_lm = lm[16 if side == 0 else 0]
        box = vs[(V[vs, 2] < V[front_lm, 2]) & (V[vs, 2] > V[front_lm, 2] - 6)
                 & (np.abs(V[vs, 1] - V[front_lm, 1] + 1) < 3.5)]
        ear = box[s * V[box, 0] > s * V[front_lm, 0] + 0.6]
        assert len(ear) > 50, "no ear found"
        put(top, int(ear[np.argmax(V[ear, 1])]),
            "highest vertex of the ear (skin 6 mm beyond landmark 16 / 0 in x, behind it)")
        put(lobe, int(ear[np.argmin(V[ear, 1])]), "lowest vertex of the ear")
        mid_y = (V[fp[top][0], 1] + V[fp[lobe][0], 1]) / 2
        band = ear[np.abs(V[ear, 1] - mid_y) < 0.3]
        put(back, int(band[np.argmin(V[band, 2])]),
            f"hindmost ear vertex within 3 mm of y = ({top}.y + {lobe}.y) / 2")
        # The attachments: the ear's most forward vertices near its upper and lower ends.
        upper = ear[V[ear, 1] > mid_y]
        lower = ear[V[ear, 1] < V[fp[lobe][0], 1] + 1.5]
        put(up_att, int(upper[np.argmax(V[upper, 2])]),
            "most forward ear vertex above the ear's mid-height (the helix root)")
        put(low_att, int(lower[np.argmax(V[lower, 2])]),
            "most forward ear vertex within 15 mm of its lowest (the lobe's attachment)")
        # Jaw corner (gonion): the skin has no edge there; anatomically it lies about 3 cm
        # below and 1 cm in front of the lobe's bottom: the outermost vertex within 5 mm of
        # that point in the side view.
        lobe_p = V[fp[lobe][0]]
        side_view = np.hypot(V[vs, 1] - lobe_p[1] + 3, V[vs, 2] - lobe_p[2] - 1)
        near = vs[(s * V[vs, 0] > 0) & (side_view < 0.5)]
        put(jaw, int(near[np.argmax(s * V[near, 0])]),
            f"outermost vertex within 5 mm of ({lobe}.y - 3 cm, {lobe}.z + 1 cm) in the side "
            "view (no edge there)")

    mid = vs[np.abs(V[vs, 0]) < 1e-6]
    ear_top_z = min(V[fp["10.1"][0], 2], V[fp["10.2"][0], 2])
    crown = mid[V[mid, 2] <= ear_top_z]
    top = int(crown[np.argmax(V[crown, 1])])
    put("11.4", top,
        "highest midline vertex not in front of the ears' tops (Table 6: 11.4.z < 10.2.z)")
    put("11.5", top, "= 11.4 (a bald scan: no hair thickness)")
    eye_y = V[fp["3.5"][0], 1]
    back = mid[(V[mid, 2] < 0) & (skin.normals[mid, 2] < -0.3)]
    put("11.6", int(back[np.argmin(np.abs(V[back, 1] - eye_y))]),
        "back-of-head midline vertex nearest y = 3.5.y")
    # Hairline (the scan is bald): by the rule of facial thirds as far above the glabella
    # (taken at the inner brow ends' height) as the glabella is above the nose bottom.
    glabella_y = (V[fp["4.1"][0], 1] + V[fp["4.2"][0], 1]) / 2
    hair_y = glabella_y + (glabella_y - V[fp["9.15"][0], 1])
    front_mid = mid[(V[mid, 2] > 0) & (skin.normals[mid, 2] > 0.2)]
    put("11.1", int(front_mid[np.argmin(np.abs(V[front_mid, 1] - hair_y))]),
        "front midline vertex at y = g + (g - 9.15.y), g = (4.1.y + 4.2.y) / 2 (facial thirds)")
    for name, brow in (("11.3", "4.5"), ("11.2", "4.6")):
        put(name, skin.front(V[fp[brow][0], 0], hair_y - 1.0, radius=1.5),
            f"front vertex at x = {brow}.x, 1 cm below 11.1.y (temple corner of the hairline)")


def pick_mouth_parts(V: np.ndarray, faces: list[np.ndarray], fp: dict[str, Rule],
                     jaw_open: np.ndarray) -> None:
    """Teeth (9.8-9.11) and tongue (6.x)."""
    def put(name: str, where: object, rule: str) -> None:
        fp[name] = (where, rule)

    for mesh, (edge, root) in (("teeth_upper", ("9.10", "9.8")), ("teeth_lower", ("9.11", "9.9"))):
        vs = np.unique(np.concatenate(part_faces(faces, mesh)))
        # The two central incisors touch the midline; their front within 1 mm of it.
        near = vs[(np.abs(V[vs, 0]) < 0.1)]
        near = near[V[near, 2] > V[near, 2].max() - 0.3]
        upper = mesh == "teeth_upper"
        crown = near[np.argmin(V[near, 1])] if upper else near[np.argmax(V[near, 1])]
        put(edge, int(crown), f"{mesh} mesh: the {'lowest' if upper else 'highest'} front "
            "vertex within 1 mm of the midline (incisal edge)")
        # The crown's other end is the gum line: going from the edge along the front, the
        # first vertex within 1 mm of the gums (the mesh goes on into the gums as the root).
        gums = V[np.unique(np.concatenate(part_faces(faces, "gums_tongue")))]
        for v in near[np.argsort(V[near, 1] if upper else -V[near, 1])]:
            if np.linalg.norm(gums - V[v], axis=1).min() < 0.1:
                break
        put(root, int(v), f"{mesh} mesh: from {edge} along the front within 1 mm of the "
            "midline, the first vertex within 1 mm of the gums (the gum line)")
    gt = np.unique(np.concatenate(part_faces(faces, "gums_tongue")))
    # The tongue: of the gums-and-tongue mesh, the vertices that jawOpen moves (the lower
    # gums and the tongue; the upper gums and palate stay) more than 5 mm behind the lower
    # incisors' edge (9.11) and not below their gum line (9.9) by more than 3 mm.
    t = gt[(np.linalg.norm(jaw_open[gt], axis=1) > 0.1) & (V[gt, 2] < V[fp["9.11"][0], 2] - 0.5)
           & (V[gt, 1] > V[fp["9.9"][0], 1] - 0.3)]
    mid = t[np.abs(V[t, 0]) < 1e-6]
    tip = int(mid[np.argmax(V[mid, 2])])
    put("6.1", tip, "gums_tongue mesh: most forward midline tongue vertex (tongue: moved by "
        "jawOpen, 5 mm behind 9.11, at most 3 mm below 9.9)")
    top = mid[np.abs(V[mid, 2] - (V[tip, 2] - 2.0)) < 0.5]
    body = int(top[np.argmax(V[top, 1])])
    put("6.2", body,
        "gums_tongue mesh: highest midline tongue vertex within 5 mm of 2 cm behind 6.1")
    # The borders: the tongue's widest vertices at 6.2's depth, within 1.5 cm below 6.2
    # and inside the lower teeth's arch there (the gums' inner side is further out).
    lower_teeth = np.unique(np.concatenate(part_faces(faces, "teeth_lower")))
    arch = lower_teeth[np.abs(V[lower_teeth, 2] - V[body, 2]) < 0.5]
    inside = 0.85 * np.abs(V[arch, 0]).min()
    ring = t[(np.abs(V[t, 2] - V[body, 2]) < 0.12) & (V[t, 1] > V[body, 1] - 1.5)
             & (np.abs(V[t, 0]) < inside)]
    put("6.3", int(ring[np.argmax(V[ring, 0])]),
        "gums_tongue mesh: +x extreme of the tongue within 1.2 mm of 6.2.z, 1.5 cm below 6.2 "
        "and within 85% of the lower teeth's inner half-width there")
    put("6.4", int(ring[np.argmin(V[ring, 0])]), "the same, -x extreme")


# --- the model --------------------------------------------------------------------------

def build(with_keys: bool = True) -> tuple[mpeg4face.FaceModel, dict[str, Rule]]:
    """The ICT head (metres) with feature points and expression shapes; with_keys: also
    the FAP keys from mpeg4face.arkit_fap_keys when the module has it."""
    V, faces, landmarks, expressions = read_ict()
    drop_isolated_offsets(faces, expressions)
    centres = {eye: eyeball_centre(V, part_faces(faces, eye)) for eye in ("eye_left", "eye_right")}
    fp = pick_feature_points(V, faces, landmarks, centres, expressions["jawOpen"])
    add_eye_turns(V, faces, expressions, centres)
    rotation_centre = np.asarray(fp["7.1"][0]) * SCALE
    meshes, lookups = [], {}
    for name in PARTS:
        fs = part_faces(faces, name)
        used = np.unique(np.concatenate(fs))
        local = np.full(len(V), -1, dtype=np.int64)
        local[used] = np.arange(len(used))
        coord_index = np.concatenate([np.r_[local[f], -1] for f in fs]).astype(np.int32)
        targets = [mpeg4face.MorphTarget(n, d[used] * SCALE) for n, d in expressions.items()
                   if np.abs(d[used]).max() > 0]
        meshes.append(mpeg4face.IndexedFaceSet(name, V[used] * SCALE, coord_index,
                                               morph_targets=targets, source_index=used))
        lookups[name] = local
    # Transforms: the root "head" at 7.1 holding the skin and the eyelashes; each rigid part
    # under its own child Transform at its centre (the eyeballs' fitted centres, so an
    # eyeball turn is a rotation; the bounding-box centre of the teeth and the gums and
    # tongue, as matchRigidParts takes them).
    part_centres = []
    for i, mesh in enumerate(meshes):
        if mesh.name in centres:
            c = centres[mesh.name] * SCALE
        elif mesh.name in RIGID:
            c = (mesh.coord.min(0) + mesh.coord.max(0)) / 2
        else:
            c = rotation_centre
        part_centres.append(c)
        mesh.coord = mesh.coord - c
    rigid = [i for i, m in enumerate(meshes) if m.name in RIGID]
    transforms = [mpeg4face.Transform("head", translation=rotation_centre,
                                      meshes=[i for i in range(len(meshes)) if i not in rigid],
                                      children=list(range(1, len(rigid) + 1)))]
    transforms += [mpeg4face.Transform(meshes[i].name, meshes=[i],
                                       translation=part_centres[i] - rotation_centre)
                   for i in rigid]
    head = mpeg4face.FaceModel(meshes=meshes, transforms=transforms, roots=[0])
    points = {}
    for name, (where, _) in fp.items():
        if isinstance(where, np.ndarray):
            points[name] = mpeg4face.FeaturePointBinding(position=where * SCALE)
            continue
        owners = [i for i, m in enumerate(meshes) if lookups[m.name][where] >= 0]
        assert len(owners) == 1, f"{name}: ICT vertex {where} is in {len(owners)} meshes"
        points[name] = mpeg4face.FeaturePointBinding(
            owners[0], int(lookups[meshes[owners[0]].name][where]))
    head.feature_points = points
    head.validate()
    if with_keys and hasattr(mpeg4face, "arkit_fap_keys"):
        head = add_fap_keys(head)
    return head, fp


def add_fap_keys(head: mpeg4face.FaceModel) -> mpeg4face.FaceModel:
    made = mpeg4face.arkit_fap_keys(head)
    for warning in made["warnings"]:
        print(f"ict_head: {warning}", file=sys.stderr)
    print(f"ict_head: {len(made['mapping'])} FAP keys from the ARKit shapes; "
          f"{len(made['missed'])} FAPs or directions missed, each with its reason (docs/arkit.md)")
    return made["head"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "samples/build")
    parser.add_argument("--no-keys", action="store_true", help="the ARKit shapes only")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    head, _ = build(not args.no_keys)
    mpeg4face.write_gltf(head, args.out / "ict_head.glb")
    targets = sum(len(m.morph_targets) for m in head.meshes)
    print(f"samples: ict_head.glb, {sum(m.vertex_count for m in head.meshes)} vertices in "
          f"{len(head.meshes)} meshes, {len(head.feature_points)} feature points, {targets} "
          f"morph targets, {len(head.animations)} poses")
    return 0


if __name__ == "__main__":
    sys.exit(main())
