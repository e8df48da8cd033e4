#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Picks the MPEG-4 feature points of the MakeHuman hm08 base mesh.

Writes tests/data/makehuman/feature_points.csv (OBJ vertex numbers, counted from 0 as
io/feature_point_csv.hpp reads them, or a free coordinate) and, with --plot,
docs/images/makehuman_feature_points.png (front and side view with the points labelled).
Every point comes from a geometric rule on the mesh (docs/makehuman-head.md lists them);
the few that are hand-picked say how they were checked. The script asserts what the rules
rely on, so a changed mesh stops it instead of giving wrong points.

Conventions (checked below): Y up, the face looks along +Z, the face's left is +X (the
MPEG-4 convention; MakeHuman's "l" groups are at +X). The mesh is mirror-symmetric in x,
so right-side points are the mirror vertices of the left-side ones.

Usage: /usr/bin/python3 scripts/makehuman_feature_points.py [--plot]
"""
import argparse
import collections
import csv
import io
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
OBJ = ROOT / "tests/data/makehuman/base.obj"
CSV = ROOT / "tests/data/makehuman/feature_points.csv"
PNG = ROOT / "docs/images/makehuman_feature_points.png"


# --- the mesh --------------------------------------------------------------------------

def load_obj(path):
    """Vertices (N x 3) and faces per group (0-based vertex numbers), as readObj groups."""
    verts, groups, current = [], collections.defaultdict(list), None
    for line in open(path, encoding="utf-8"):
        if line.startswith("v "):
            verts.append([float(t) for t in line.split()[1:4]])
        elif line.startswith(("g ", "o ")):
            current = line.split()[1]
        elif line.startswith("f "):
            groups[current].append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(verts), dict(groups)


class Surface:
    """One group's faces with the adjacency the rules walk on."""

    def __init__(self, V, faces):
        self.V, self.faces = V, faces
        self.adj = collections.defaultdict(set)
        self.vertex_faces = collections.defaultdict(list)
        for k, f in enumerate(faces):
            for i, v in enumerate(f):
                self.adj[v].update((f[i - 1], f[(i + 1) % len(f)]))
                self.vertex_faces[v].append(k)
        self.vertices = np.array(sorted(self.adj))
        normals = np.zeros_like(V)
        for f in faces:
            p = V[f]
            normals[f] += np.cross(p[2] - p[0], p[-1] - p[1] if len(f) == 4 else p[1] - p[0])
        self.normals = normals / np.maximum(np.linalg.norm(normals, axis=1), 1e-12)[:, None]

    def edge_loop(self, u, v):
        """The closed quad edge loop through edge u-v (crossing each valence-4 vertex to
        the edge opposite the one it came in on), or None if it does not close."""
        loop = [u, v]
        while len(loop) < 1000:
            a, b = loop[-2], loop[-1]
            if len(self.adj[b]) != 4:
                return None
            beside = set()
            for k in self.vertex_faces[b]:
                f = self.faces[k]
                if a in f:
                    i = f.index(b)
                    beside.update((f[i - 1], f[(i + 1) % len(f)]))
            ahead = [n for n in self.adj[b] if n not in beside]
            if len(ahead) != 1:
                return None
            if ahead[0] == loop[0]:
                return loop
            loop.append(ahead[0])
        return None

    def loop_across_midline(self, v):
        """The closed loop through midline vertex v that leaves the midline (x = 0)."""
        for n in sorted(self.adj[v]):
            if abs(self.V[n, 0]) > 1e-6:
                loop = self.edge_loop(v, n)
                if loop:
                    return loop
        raise SystemExit(f"no closed edge loop across the midline at vertex {v}")


def midline_profile(body, start):
    """The body's midline (x = 0) vertices in order along the surface, from `start` going
    forward (the neighbour with the larger z first)."""
    V, path, seen = body.V, [start], {start}
    while True:
        ahead = [n for n in body.adj[path[-1]] if abs(V[n, 0]) < 1e-6 and n not in seen]
        if not ahead:
            return path
        nxt = max(ahead, key=lambda n: V[n, 2])
        path.append(nxt)
        seen.add(nxt)


def front_vertex(body, x, y, radius=0.06, band=0.03, x_weight=1.0):
    """The body vertex on the visible front surface nearest to (x, y) in the front view:
    among vertices within `radius` of (x, y) and facing forward, those within `band` of
    the front-most, the nearest (x distances count x_weight times: < 1 where Table 6 fixes
    the point's y)."""
    V, idx = body.V, body.vertices
    d = np.hypot(V[idx, 0] - x, V[idx, 1] - y)
    near = idx[(d < radius) & (body.normals[idx, 2] > 0.2)]
    if len(near) == 0:
        raise SystemExit(f"no front surface near x={x:.3f} y={y:.3f}")
    near = near[V[near, 2] > V[near, 2].max() - band]
    return int(near[np.argmin(np.hypot(x_weight * (V[near, 0] - x), V[near, 1] - y))])


def mirror(V, v):
    """The vertex at v's mirror position (x -> -x); the base mesh is symmetric."""
    d = np.linalg.norm(V - V[v] * [-1, 1, 1], axis=1)
    m = int(np.argmin(d))
    assert d[m] < 1e-6, f"vertex {v} has no mirror vertex"
    return m


def split_ring(V, ring, upper_vertex):
    """A closed ring around a horizontal slit split at its x extremes: (left corner at +x,
    right corner, upper arc, lower arc); the upper arc is the one holding upper_vertex."""
    left, right = ring.index(max(ring, key=lambda v: V[v, 0])), ring.index(min(ring, key=lambda v: V[v, 0]))
    rolled = ring[left:] + ring[:left]
    k = rolled.index(ring[right])
    arc1, arc2 = rolled[: k + 1], rolled[k:] + rolled[:1]
    upper, lower = (arc1, arc2) if upper_vertex in arc1 else (arc2, arc1)
    return ring[left], ring[right], upper, lower


def nearest_x(V, arc, x):
    return int(min(arc, key=lambda v: abs(V[v, 0] - x)))


def group_vertices(G, name):
    return np.unique(np.concatenate([np.array(f) for f in G[name]]))


# --- the rules -------------------------------------------------------------------------

def pick(V, G):
    """{fp: (vertex or xyz, rule)}. Left-side points first; mirrored at the end."""
    body = Surface(V, G["body"])
    fp = {}

    def put(name, where, rule):
        fp[name] = (where, rule)

    # Orientation: the eyes are in front of the head's centre, the left eye at +x.
    l_eye, r_eye = group_vertices(G, "helper-l-eye"), group_vertices(G, "helper-r-eye")
    assert V[l_eye, 0].mean() > 0 > V[r_eye, 0].mean(), "left eye not at +x"
    head = body.vertices[V[body.vertices, 1] > V[l_eye, 1].mean() - 1.3]
    assert V[l_eye, 2].mean() > V[head, 2].mean(), "face does not look along +z"

    # The midline profile from the top of the skull over the face into the mouth.
    top = int(head[np.argmax(V[head, 1] - 1e3 * np.abs(V[head, 0]))])
    assert abs(V[top, 0]) < 1e-6
    put("11.4", top, "highest midline vertex")
    profile = midline_profile(body, top)
    z = V[profile, 2]
    y = V[profile, 1]

    tip = int(np.argmax(z))
    put("9.3", profile[tip], "most forward midline vertex")
    # Past the nose tip the profile dips at the subnasale, rises over the upper lip and turns
    # back into the mouth where y starts growing again.
    stomion = next(i for i in range(tip + 1, len(profile) - 1) if y[i + 1] > y[i])
    put("2.2", profile[stomion], "upper lip's lowest midline vertex before the profile turns into the mouth")
    subnasale = tip + int(np.argmin(z[tip:stomion]))
    put("9.15", profile[subnasale], "least forward midline vertex between nose tip and upper lip")
    # The vermilion border is the ridge of the upper lip: the largest forward step of the
    # profile between subnasale and stomion; the ring there is the outer lip contour.
    steps = np.diff(z[subnasale:stomion + 1])
    vermilion = profile[subnasale + 1 + int(np.argmax(steps))]
    outer = body.loop_across_midline(vermilion)
    l83, l84, outer_up, outer_low = split_ring(V, outer, vermilion)
    put("8.1", vermilion, "upper-lip vermilion ridge: after the largest forward step of the midline profile below the nose")
    low_mid = [v for v in outer_low if abs(V[v, 0]) < 1e-6]
    assert len(low_mid) == 1
    put("8.2", low_mid[0], "lower midline vertex of 8.1's edge ring (the outer lip contour)")
    put("8.3", l83, "+x extreme of the outer lip contour ring")
    put("8.4", l84, "-x extreme of the outer lip contour ring")
    put("8.5", nearest_x(V, outer_up, (V[l83, 0] + V[vermilion, 0]) / 2),
        "upper arc of the outer lip ring, x nearest (8.3.x + 8.1.x) / 2")
    put("8.6", nearest_x(V, outer_up, (V[l84, 0] + V[vermilion, 0]) / 2),
        "upper arc of the outer lip ring, x nearest (8.4.x + 8.1.x) / 2")
    put("8.7", nearest_x(V, outer_low, (V[l83, 0] + V[low_mid[0], 0]) / 2),
        "lower arc of the outer lip ring, x nearest (8.3.x + 8.2.x) / 2")
    put("8.8", nearest_x(V, outer_low, (V[l84, 0] + V[low_mid[0], 0]) / 2),
        "lower arc of the outer lip ring, x nearest (8.4.x + 8.2.x) / 2")
    put("8.10", max((v for v in outer_up if V[v, 0] > 0), key=lambda v: V[v, 1]),
        "highest vertex of the outer lip ring's upper arc at +x (Cupid's bow)")
    put("8.9", max((v for v in outer_up if V[v, 0] < 0), key=lambda v: V[v, 1]),
        "highest vertex of the outer lip ring's upper arc at -x (Cupid's bow)")
    # The lower lip's outer contour: the lip-chin step (largest backward step of the profile
    # below the lips) must come right after 8.2, or the ring is not the lip outline.
    chin_part = range(stomion + 1, len(profile) - 1)
    lower_start = profile.index(low_mid[0])
    assert z[lower_start + 1] < z[lower_start] - 0.02, "8.2 is not at the lip-chin step"

    inner = body.loop_across_midline(profile[stomion])
    l24, l25, inner_up, inner_low = split_ring(V, inner, profile[stomion])
    low_in = [v for v in inner_low if abs(V[v, 0]) < 1e-6]
    assert len(low_in) == 1 and V[low_in[0], 1] < V[profile[stomion], 1]
    put("2.3", low_in[0], "lower midline vertex of 2.2's edge ring (the mouth slit)")
    put("2.4", l24, "+x extreme of the mouth-slit ring")
    put("2.5", l25, "-x extreme of the mouth-slit ring")
    put("2.6", nearest_x(V, inner_up, (V[l24, 0]) / 2), "upper arc of the slit ring, x nearest 2.4.x / 2")
    put("2.7", nearest_x(V, inner_up, (V[l25, 0]) / 2), "upper arc of the slit ring, x nearest 2.5.x / 2")
    put("2.8", nearest_x(V, inner_low, (V[l24, 0]) / 2), "lower arc of the slit ring, x nearest 2.4.x / 2")
    put("2.9", nearest_x(V, inner_low, (V[l25, 0]) / 2), "lower arc of the slit ring, x nearest 2.5.x / 2")

    # Chin: below the lower lip the profile dips into the labiomental fold (its first local
    # minimum of z), then bulges at the chin boss (the most forward vertex after the fold);
    # the bottom is where the profile, turning under the jaw, is extreme in the 45-degree
    # direction (0, -1, 1): the chin's lower front corner that bounds the face in the front
    # view. (The profile goes on down the neck: the chin is within 0.6 below the stomion.)
    below = [i for i in chin_part if i > lower_start and y[i] > y[stomion] - 0.6]
    fold = next(i for i in below[1:-1] if z[i] <= z[i - 1] and z[i] < z[i + 1])
    boss = max((i for i in below if i > fold), key=lambda i: z[i])
    put("2.10", profile[boss], "most forward midline vertex below the labiomental fold")
    bottom = max((i for i in below if i > boss), key=lambda i: z[i] - y[i])
    put("2.1", profile[bottom], "midline vertex below 2.10 extreme in direction (0,-1,1)")

    # Eyes (left, +x). Rings of edges around the eye opening, ordered from the eye outward.
    eye_c = (V[l_eye].min(0) + V[l_eye].max(0)) / 2
    rings = {}
    around = body.vertices[(np.hypot(V[body.vertices, 0] - eye_c[0], V[body.vertices, 1] - eye_c[1]) < 0.25)
                           & (V[body.vertices, 2] > eye_c[2])]
    for s in around:
        for n in body.adj[s]:
            ring = body.edge_loop(s, n)
            if ring and len(ring) < 100:
                P = V[ring]
                if 0 < P[:, 0].min() < eye_c[0] < P[:, 0].max() and P[:, 1].min() < eye_c[1] < P[:, 1].max():
                    rings[frozenset(ring)] = ring  # around this eye only (not across the nose)
    rings = sorted(rings.values(), key=lambda r: np.ptp(V[r, 0]))
    visible = [r for r in rings if V[r, 2].mean() > eye_c[2] + 0.1]
    # The lid margin is the crest of the lids: the ring standing furthest forward.
    margin_k = max(range(len(visible)), key=lambda k: V[visible[k], 2].mean())
    margin = visible[margin_k]
    top_v = max(margin, key=lambda v: V[v, 1])
    l37, l311, lid_up, lid_low = split_ring(V, margin, top_v)
    mid_x = (V[l37, 0] + V[l311, 0]) / 2
    put("3.7", l37, "+x (outer) extreme of the lid-margin ring (the eye ring standing furthest forward)")
    put("3.11", l311, "-x (inner) extreme of the lid-margin ring")
    put("3.1", nearest_x(V, lid_up, mid_x), "upper arc of the lid-margin ring, x nearest (3.7.x + 3.11.x) / 2")
    put("3.3", nearest_x(V, lid_low, mid_x), "lower arc of the lid-margin ring, x nearest (3.7.x + 3.11.x) / 2")
    # The outer lid contour: four rings further out (where the lids meet the orbit).
    lid_outer = visible[margin_k + 4]
    _, _, out_up, out_low = split_ring(V, lid_outer, max(lid_outer, key=lambda v: V[v, 1]))
    put("3.13", nearest_x(V, out_up, mid_x), "upper arc of the 4th eye ring outside the lid margin, x nearest 3.1.x")
    put("3.9", nearest_x(V, out_low, mid_x), "lower arc of the 4th eye ring outside the lid margin, x nearest 3.1.x")
    # Pupil: the eye's front is a flat octagon (the iris) with no centre vertex; its upper
    # inner vertex is nearest the centre in x (ES0 3.6% short, ENS0 5% long; a vertex of the
    # eye mesh so the eye is found from it).
    front = l_eye[V[l_eye, 2] > V[l_eye, 2].max() - 1e-6]
    assert len(front) == 8
    pupil = max((v for v in front if V[v, 1] > eye_c[1] and V[v, 0] < eye_c[0]), key=lambda v: V[v, 0])
    put("3.5", int(pupil), "eye mesh: upper inner vertex of the front octagon (the iris), nearest its centre in x")

    # Eyebrows (the base mesh has neither brow hair nor a marked brow ridge): placed with
    # CANDIDE-3's proportions relative to its eye (eye width W = 3.7.x - 3.11.x): the brow
    # corners 0.4 W above the eye corners (the outer one 0.15 W further out), the top 0.65 W
    # above the eye corners, halfway between the brow corners in x.
    width = V[l37, 0] - V[l311, 0]
    l41 = front_vertex(body, V[l311, 0], V[l311, 1] + 0.4 * width)
    l45 = front_vertex(body, V[l37, 0] + 0.15 * width, V[l37, 1] + 0.4 * width)
    put("4.1", l41, "front vertex at x = 3.11.x, y = 3.11.y + 0.4 W (W = 3.7.x - 3.11.x; CANDIDE-3 proportions)")
    put("4.5", l45, "front vertex at x = 3.7.x + 0.15 W, y = 3.7.y + 0.4 W (CANDIDE-3 proportions)")
    l43 = front_vertex(body, (V[l41, 0] + V[l45, 0]) / 2, (V[l311, 1] + V[l37, 1]) / 2 + 0.65 * width)
    put("4.3", l43, "front vertex at x = (4.1.x + 4.5.x) / 2, 0.65 W above the eye corners (CANDIDE-3 proportions)")

    # Nose.
    nose_top = front_vertex(body, V[l311, 0] / 2, V[l311, 1])
    put("9.7", nose_top, "front vertex at x = 3.11.x / 2, y = 3.11.y (side of the nose root)")
    bone_y = (V[nose_top, 1] + V[profile[tip], 1]) / 2
    put("9.12", profile[int(np.argmin(np.abs(y[:tip + 1] - bone_y)))], "midline profile vertex at y = (9.6.y + 9.3.y) / 2")
    put("9.13", front_vertex(body, V[nose_top, 0], bone_y), "front vertex at x = 9.7.x, y = (9.7.y + 9.3.y) / 2")
    # The nose wing (ala): the vertex furthest out in x among those facing sideways (normal
    # x > 0.6) between the subnasale and the nose tip, within 0.25 of the midline.
    wing = body.vertices[(V[body.vertices, 0] > 0) & (V[body.vertices, 0] < 0.25)
                         & (V[body.vertices, 1] > V[profile[subnasale], 1]) & (V[body.vertices, 1] < V[profile[tip], 1])
                         & (V[body.vertices, 2] > V[profile[subnasale], 2] - 0.1) & (body.normals[body.vertices, 0] > 0.6)]
    l91 = int(max(wing, key=lambda v: V[v, 0]))
    put("9.1", l91, "most lateral sideways-facing vertex of the nose wing (y between 9.15 and 9.3)")
    put("9.5", front_vertex(body, 0.8 * V[l91, 0], V[profile[subnasale], 1], band=0.05),
        "front vertex at x = 0.8 * 9.1.x, y = 9.15.y (foot of the nose wing)")

    # Cheeks.
    put("5.1", front_vertex(body, V[l37, 0], V[l83, 1], radius=0.08, x_weight=0.25),
        "front vertex at x = 3.7.x, y = 8.3.y (y preferred)")
    put("5.3", front_vertex(body, (eye_c[0] + V[l37, 0]) / 2, (V[profile[subnasale], 1] + V[fp["9.12"][0], 1]) / 2),
        "front vertex at x = (3.5.x + 3.7.x) / 2, y = (9.15.y + 9.12.y) / 2")
    # Chin corners: halfway between 8.7 and 8.3 in x, at the height of the chin boss' lower half.
    put("2.11", front_vertex(body, (V[fp["8.7"][0], 0] + V[l83, 0]) / 2, (V[profile[boss], 1] + V[profile[bottom], 1]) / 2),
        "front vertex at x = (8.7.x + 8.3.x) / 2, y = (2.10.y + 2.1.y) / 2")

    # Hairline (the base mesh is bald): by the rule of facial thirds the hairline is as far
    # above the brows as the brows are above the nose bottom.
    brow_y = V[l43, 1]
    hair_y = brow_y + (brow_y - V[profile[subnasale], 1])
    put("11.1", profile[int(np.argmin(np.abs(y[:tip] - hair_y)))],
        "midline vertex at y = 4.3.y + (4.3.y - 9.15.y) (facial thirds)")
    put("11.3", front_vertex(body, V[l45, 0], hair_y - 0.1, radius=0.05),
        "front vertex at x = 4.5.x, 0.1 below 11.1.y (temple corner of the hairline)")
    back = body.vertices[(np.abs(V[body.vertices, 0]) < 1e-6) & (V[body.vertices, 2] < V[head, 2].mean())
                         & (np.abs(V[body.vertices, 1] - eye_c[1]) < 0.2) & (body.normals[body.vertices, 2] < -0.5)]
    put("11.6", int(min(back, key=lambda v: abs(V[v, 1] - eye_c[1]))), "back-of-head midline vertex nearest y = 3.5.y")

    # Ears and jaw corner: hand-picked from the side view (scripts/makehuman_feature_points.py
    # --plot; the rims of the helix and the lobe are easy to see there). Checked: each is on
    # the ear's outline in the side view and 10.3's y is within 0.05 of (10.1.y + 10.5.y) / 2.
    put("10.1", 12034, "hand-picked: top of the helix (side view)")
    put("10.5", 12005, "hand-picked: bottom of the lobe (side view)")
    put("10.3", 12039, "hand-picked: back of the helix at mid-height (side view)")
    put("10.9", 12046, "hand-picked: upper front attachment of the helix (side view)")
    put("10.7", 12019, "hand-picked: front attachment of the lobe (side view)")
    put("2.13", 7465, "hand-picked: corner of the jaw line below the ear lobe (side view)")

    # Teeth and tongue (their own groups).
    up_t, low_t, tongue = (group_vertices(G, g) for g in ("helper-upper-teeth", "helper-lower-teeth", "helper-tongue"))

    def midline_front(vs):
        mid = vs[np.abs(V[vs, 0]) < 1e-6]
        return mid[V[mid, 2] > V[mid, 2].max() - 0.15]  # the incisors' front part
    m = midline_front(up_t)
    put("9.10", int(m[np.argmin(V[m, 1])]), "upper-teeth mesh: lowest midline vertex of the incisors")
    put("9.8", int(m[np.argmax(V[m, 1])]), "upper-teeth mesh: highest midline vertex of the incisors")
    m = midline_front(low_t)
    put("9.11", int(m[np.argmax(V[m, 1])]), "lower-teeth mesh: highest midline vertex of the incisors")
    put("9.9", int(m[np.argmin(V[m, 1])]), "lower-teeth mesh: lowest midline vertex of the incisors")
    mid = tongue[np.abs(V[tongue, 0]) < 1e-6]
    tip_t = int(mid[np.argmax(V[mid, 2])])
    put("6.1", tip_t, "tongue mesh: most forward midline vertex")
    zc = (V[tongue, 2].min() + V[tip_t, 2]) / 2
    upper_mid = mid[np.abs(V[mid, 2] - zc) < 0.1]
    body_t = int(upper_mid[np.argmax(V[upper_mid, 1])])
    put("6.2", body_t, "tongue mesh: highest midline vertex within 0.1 of the tongue's middle z")
    ring = tongue[np.abs(V[tongue, 2] - V[body_t, 2]) < 0.03]  # the coarse tongue: 0.012 finds only its top
    put("6.3", int(ring[np.argmax(V[ring, 0])]), "tongue mesh: +x extreme within 0.03 of 6.2.z")

    # Head rotation: MakeHuman's own skeleton markers (joint-* groups are small cubes).
    put("7.1", V[group_vertices(G, "joint-head")].mean(0), "centre of MakeHuman's joint-head marker (free coordinate)")
    put("7.2", V[group_vertices(G, "joint-neck")].mean(0), "centre of MakeHuman's joint-neck marker (free coordinate)")

    # Right side: mirror vertices.
    pairs = {"2.4": "2.5", "2.6": "2.7", "2.8": "2.9", "2.11": "2.12", "2.13": "2.14", "3.1": "3.2",
             "3.3": "3.4", "3.5": "3.6", "3.7": "3.12", "3.9": "3.10", "3.11": "3.8", "3.13": "3.14",
             "4.1": "4.2", "4.3": "4.4", "4.5": "4.6", "5.1": "5.2", "5.3": "5.4", "6.3": "6.4",
             "8.3": "8.4", "8.5": "8.6", "8.7": "8.8", "8.10": "8.9", "9.1": "9.2", "9.5": "9.4",
             "9.7": "9.6", "9.13": "9.14", "10.1": "10.2", "10.3": "10.4", "10.5": "10.6",
             "10.7": "10.8", "10.9": "10.10", "11.3": "11.2"}
    for left, right in pairs.items():
        where, rule = fp[left]
        assert abs(V[where, 0]) > 1e-6, f"{left} is on the midline"
        if right in fp:
            assert fp[right][0] == mirror(V, where), f"{right} is not the mirror of {left}"
        else:
            fp[right] = (mirror(V, where), f"mirror of {left}")
    return fp


def fp_key(name):
    a, b = name.split(".")
    return int(a), int(b)


def write_csv(fp, path):
    out = io.StringIO()
    out.write("# MPEG-4 feature points of tests/data/makehuman/base.obj (MakeHuman hm08).\n"
              "# Written by scripts/makehuman_feature_points.py; rules in docs/makehuman-head.md.\n"
              "# obj_vertex counts the OBJ's v lines from 0; rows without one are free coordinates.\n")
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["mpeg4_fp", "obj_vertex", "x", "y", "z", "rule"])
    for name in sorted(fp, key=fp_key):
        where, rule = fp[name]
        if isinstance(where, np.ndarray):
            w.writerow([name, "", *(f"{c:.4f}" for c in where), rule])
        else:
            w.writerow([name, int(where), "", "", "", rule])
    path.write_text(out.getvalue(), encoding="utf-8")


def plot(V, G, fp, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    def draw(ax, view, box, names):
        a, d = (0, 2) if view == "front" else (2, 0)
        faces = [f for g in ("body", "helper-l-eye", "helper-r-eye") for f in G[g]]
        centre = np.array([V[f].mean(0) for f in faces])
        keep = (centre[:, a] >= box[0]) & (centre[:, a] <= box[1]) & (centre[:, 1] >= box[2]) & (centre[:, 1] <= box[3])
        if view == "side":
            keep &= centre[:, 0] > -0.05  # the left half, seen from +x
        light = np.array([0.3, 0.4, 1.0] if view == "front" else [1.0, 0.4, 0.3])
        light /= np.linalg.norm(light)
        polys, colours = [], []
        for k in np.argsort(centre[:, d]):  # painter's order, far to near
            if not keep[k]:
                continue
            q = V[faces[k]]
            n = np.cross(q[2] - q[0], q[-1] - q[1])
            s = abs(n @ light) / max(np.linalg.norm(n), 1e-12)
            polys.append(q[:, [a, 1]])
            colours.append((0.35 + 0.6 * s,) * 3)
        ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors=(0, 0, 0, 0.12), linewidths=0.2))
        for name in names:
            where = fp[name][0]
            p = where if isinstance(where, np.ndarray) else V[where]
            hidden = view == "front" and name.startswith(("6.", "9.8", "9.9", "9.10", "9.11", "7."))
            ax.plot(p[a], p[1], "o", ms=3, color="blue" if hidden else "red")
            ax.annotate(name, (p[a], p[1]), xytext=(2, 2), textcoords="offset points", fontsize=6,
                        color="blue" if hidden else "red")
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
        ax.set_aspect("equal")
        ax.set_title(view + (" (blue: inside the mouth or head)" if view == "front" else " (left half, from +x)"))

    fig, axes = plt.subplots(1, 2, figsize=(18, 11))
    draw(axes[0], "front", (-0.95, 0.95, 5.8, 8.6), sorted(fp, key=fp_key))
    draw(axes[1], "side", (-0.45, 1.85, 5.8, 8.6),
         [n for n in sorted(fp, key=fp_key) if (fp[n][0] if isinstance(fp[n][0], np.ndarray) else V[fp[n][0]])[0] >= -1e-6])
    fig.suptitle("MPEG-4 feature points on the MakeHuman hm08 base mesh (scripts/makehuman_feature_points.py)")
    fig.savefig(path, dpi=90, bbox_inches="tight")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", action="store_true", help="also draw " + str(PNG.relative_to(ROOT)))
    args = parser.parse_args()
    V, G = load_obj(OBJ)
    fp = pick(V, G)
    write_csv(fp, CSV)
    print(f"{len(fp)} feature points -> {CSV.relative_to(ROOT)}")
    if args.plot:
        plot(V, G, fp, PNG)
        print(f"picture -> {PNG.relative_to(ROOT)}")


if __name__ == "__main__":
    sys.exit(main())
