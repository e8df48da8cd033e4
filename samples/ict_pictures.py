# SPDX-License-Identifier: GPL-3.0-or-later
"""Pictures of the ICT sample head (samples/build/ict_head.glb) for docs/arkit.md and
docs/samples.md: Blender Workbench renders (orthographic) of the head deformed by the core
(each key's morph targets at weight 1, and its pose's Transforms where it has one), laid
out with matplotlib:

- ict_feature_points.png: the neutral from the front and the side, feature points marked;
- ict_arkit_shapes.png: a selection of its ARKit shapes at weight 1;
- ict_fap_keys.png, ict_visemes.png: a selection of its FAP keys (each at its amplitude)
  and its viseme and expression keys, when the head has them (mpeg4face.arkit_fap_keys).

    blender -b --factory-startup --python-exit-code 1 --python samples/ict_pictures.py -- \\
        [HEAD.glb] [--out docs/images]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mpeg4face  # noqa: E402
import numpy as np  # noqa: E402
from mpeg4face_blender.logic import feature_points  # noqa: E402
from PIL import Image  # noqa: E402  (matplotlib's own dependency)

ROOT = Path(__file__).resolve().parent.parent
SHAPES = ["eyeBlink_L", "eyeWide_R", "browInnerUp_L", "browDown_R", "jawOpen", "jawLeft",
          "mouthSmile_L", "mouthFunnel", "mouthPucker", "mouthLowerDown_R", "mouthRollLower",
          "mouthUpperUp_R", "mouthStretch_L", "cheekPuff_L", "noseSneer_R", "eyeLookOut_L"]
FAPS = (3, 4, 5, 6, 12, 16, 17, 19, 23, 25, 31, 33, 35, 37, 39, 51, 52, 53, 55, 59)
COLOURS = {"skin": (0.80, 0.62, 0.52), "eyelashes": (0.15, 0.1, 0.08),
           "eye_left": (0.92, 0.92, 0.92), "eye_right": (0.92, 0.92, 0.92),
           "teeth_upper": (0.95, 0.93, 0.85), "teeth_lower": (0.95, 0.93, 0.85),
           "gums_tongue": (0.75, 0.35, 0.38)}
FACE = (0.0, 0.005, 0.17)  # front view: centre x, y and width (metres)
HEAD_FRONT = (0.0, 0.02, 0.26)
HEAD_SIDE = (-0.02, 0.02, 0.26)  # side view: centre -z (the face looks left), y and width


class Scene:
    """The head's meshes as Blender objects (model space), an orthographic camera and
    Workbench."""

    def __init__(self, head: mpeg4face.FaceModel):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        self.head = head
        self.objects = []
        for mesh in head.meshes:
            data = bpy.data.meshes.new(mesh.name)
            faces = np.split(mesh.coord_index, np.flatnonzero(mesh.coord_index == -1) + 1)
            data.from_pydata(feature_points.to_blender_axes(mesh.coord).tolist(), [],
                             [f[:-1].tolist() for f in faces if len(f) > 1])
            data.polygons.foreach_set("use_smooth", [True] * len(data.polygons))
            material = bpy.data.materials.new(mesh.name)
            material.diffuse_color = (*COLOURS.get(mesh.name, (0.7, 0.7, 0.7)), 1.0)
            data.materials.append(material)
            if mesh.name.startswith("eye_"):  # the iris: the front cap of the cornea, 3 mm deep
                iris = bpy.data.materials.new(mesh.name + "_iris")
                iris.diffuse_color = (0.22, 0.15, 0.1, 1.0)
                data.materials.append(iris)
                front = mesh.coord[:, 2] > mesh.coord[:, 2].max() - 0.003
                for polygon in data.polygons:
                    polygon.material_index = int(all(front[i] for i in polygon.vertices))
            obj = bpy.data.objects.new(mesh.name, data)
            bpy.context.scene.collection.objects.link(obj)
            self.objects.append(obj)
        scene = bpy.context.scene
        scene.render.engine = "BLENDER_WORKBENCH"
        scene.display.shading.light = "STUDIO"
        scene.display.shading.color_type = "MATERIAL"
        scene.display.shading.show_cavity = True
        scene.render.image_settings.file_format = "PNG"
        scene.render.film_transparent = True
        camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        camera.data.type = "ORTHO"
        camera.data.sensor_fit = "HORIZONTAL"  # ortho_scale is the picture's width
        scene.collection.objects.link(camera)
        scene.camera = camera
        self.camera = camera

    def pose(self, key: str | None = None) -> list[np.ndarray]:
        """Model-space vertices with the morph targets named `key` at weight 1 and the
        Transforms of the pose named `key` (if any)."""
        transforms = [mpeg4face.Transform(t.name, translation=t.translation, rotation=t.rotation,
                                          scale=t.scale, center=t.center, children=t.children,
                                          meshes=t.meshes)
                      for t in self.head.transforms]  # copies: the head's own would change
        for animation in self.head.animations:
            if animation.name == key:
                for channel in animation.transform_channels:
                    t = transforms[channel.transform]
                    values = np.asarray(channel.values)[:len(channel.values) // len(channel.times)]
                    if channel.path == mpeg4face.TransformChannel.Path.ROTATION:
                        t.rotation = values
                    elif channel.path == mpeg4face.TransformChannel.Path.TRANSLATION:
                        t.translation = values
        model = mpeg4face.FaceModel(meshes=self.head.meshes, transforms=transforms,
                                    roots=self.head.roots)
        out = []
        for mesh, world in zip(self.head.meshes, model.mesh_world_matrices()):
            c = mesh.coord.copy()
            for target in mesh.morph_targets:
                if target.name == key:
                    c += target.displacements
            out.append(c @ world[:3, :3].T + world[:3, 3])
        return out

    def render(self, coords: list[np.ndarray], view: str, frame: tuple[float, float, float],
               path: Path, size: tuple[int, int]) -> None:
        for obj, c in zip(self.objects, coords):
            obj.data.vertices.foreach_set("co", feature_points.to_blender_axes(c).ravel())
            obj.data.update()
        scene = bpy.context.scene
        scene.render.resolution_x, scene.render.resolution_y = size
        a, b, width = frame
        self.camera.data.ortho_scale = width
        if view == "front":  # standard +z is Blender -y
            self.camera.location = (a, -1.0, b)
            self.camera.rotation_euler = (np.pi / 2, 0, 0)
        else:  # from the face's left (+x): standard -z (Blender +y) to the right
            self.camera.location = (1.0, a, b)
            self.camera.rotation_euler = (np.pi / 2, 0, np.pi / 2)
        scene.render.filepath = str(path)
        bpy.ops.render.render(write_still=True)


def to_pixels(p: np.ndarray, view: str, frame: tuple[float, float, float],
              size: tuple[int, int]) -> tuple[float, float]:
    a, b, width = frame
    u = p[0] if view == "front" else -p[2]
    scale = size[0] / width
    return (u - a) * scale + size[0] / 2, size[1] / 2 - (p[1] - b) * scale


def save(fig: plt.Figure, path: Path, dpi: int) -> None:
    """The figure as a 256-colour PNG (a third of the size, for docs/images), written to a
    .part name and renamed."""
    part = path.with_name(path.stem + ".part.png")
    fig.savefig(part, dpi=dpi)
    plt.close(fig)
    Image.open(part).convert("RGB").quantize(256).save(part, optimize=True)
    part.replace(path)


def fp_key(name: str) -> tuple[int, int]:
    a, b = name.split(".")
    return int(a), int(b)


def feature_points_sheet(scene: Scene, tmp: Path, path: Path) -> None:
    head = scene.head
    coords = scene.pose()
    size = (900, 1000)
    fig, axes = plt.subplots(1, 2, figsize=(18, 10.5))
    for ax, view, frame in zip(axes, ("front", "side"), (HEAD_FRONT, HEAD_SIDE)):
        scene.render(coords, view, frame, tmp / f"fp_{view}.png", size)
        ax.imshow(plt.imread(tmp / f"fp_{view}.png"))
        for name in sorted(head.feature_points, key=fp_key):
            p = head.feature_point_position(name)
            if view == "side" and p[0] < -1e-4:
                continue
            hidden = name.startswith(("6.", "7.", "9.8", "9.9", "9.10", "9.11", "11.5"))
            if view == "front" and name.startswith(("10.", "11.6", "2.13", "2.14")):
                hidden = True
            colour = "blue" if hidden else "red"
            u, v = to_pixels(p, view, frame, size)
            if not (0 <= u < size[0] and 0 <= v < size[1]):
                continue  # 7.2, at the neck's cut end
            ax.plot(u, v, "o", ms=2.5, color=colour)
            ax.annotate(name, (u, v), xytext=(2, 2), textcoords="offset points", fontsize=6,
                        color=colour)
        ax.set_axis_off()
    axes[0].set_title("front (blue: inside the mouth or the head, or behind it)")
    axes[1].set_title("side: the left half, from +x")
    fig.suptitle("ICT sample head: MPEG-4 feature points (samples/ict_head.py)")
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    save(fig, path, 70)


def keys_sheet(scene: Scene, keys: list[str], tmp: Path, path: Path, title: str,
               columns: int = 4) -> None:
    rows = (len(keys) + columns - 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(2.6 * columns, 2.9 * rows))
    size = (300, 300)
    for ax, key in zip(np.ravel(axes), keys):
        scene.render(scene.pose(key), "front", FACE, tmp / "key.png", size)
        ax.imshow(plt.imread(tmp / "key.png"))
        ax.set_title(key, fontsize=8)
    for ax in np.ravel(axes):
        ax.set_axis_off()
    fig.suptitle(title)
    fig.tight_layout()
    save(fig, path, 70)


def main() -> None:
    parser = argparse.ArgumentParser(prog="ict_pictures.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("head", type=Path, nargs="?", default=ROOT / "samples/build/ict_head.glb")
    parser.add_argument("--out", type=Path, default=ROOT / "docs/images")
    args = parser.parse_args(ARGS)
    head = mpeg4face.read_gltf(args.head)
    scene = Scene(head)
    args.out.mkdir(parents=True, exist_ok=True)
    names = {t.name for m in head.meshes for t in m.morph_targets}
    names |= {a.name for a in head.animations}  # poses (eyeball turns) too
    made = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        feature_points_sheet(scene, tmp, args.out / "ict_feature_points.png")
        keys_sheet(scene, SHAPES, tmp, args.out / "ict_arkit_shapes.png",
                   "ICT sample head: ARKit shapes at weight 1")
        made += ["ict_feature_points.png", "ict_arkit_shapes.png"]
        faps = {}
        for name in sorted(names):
            parsed = mpeg4face.parse_shape_key_name(name)
            if parsed and parsed["fap"] in FAPS and parsed["amplitude"] > 0:
                faps.setdefault(parsed["fap"], name)
        if faps:
            keys_sheet(scene, [faps[f] for f in sorted(faps)], tmp, args.out / "ict_fap_keys.png",
                       "ICT sample head: FAP keys made from its ARKit shapes (at their amplitude)",
                       columns=5)
            made.append("ict_fap_keys.png")
        high = sorted((n for n in names if n.startswith(("viseme", "expression"))),
                      key=lambda n: (n[0], int("".join(c for c in n.split("_")[0] if c.isdigit()))))
        if high:
            keys_sheet(scene, high, tmp, args.out / "ict_visemes.png",
                       "ICT sample head: viseme and expression keys", columns=5)
            made.append("ict_visemes.png")
    print(f"ict_pictures: {', '.join(str(args.out / m) for m in made)}")


main()
