# SPDX-License-Identifier: GPL-3.0-or-later
"""What an artist does with a freshly installed add-on, in one Blender: install the zip into
the (temporary) user folder, enable it, open the MakeHuman sample head, generate its
FaceDefTables, export .glb and .wrl, import a .fba stream and bake it, start the live preview
and evaluate its frames. Run by run_install_test.sh, with a clean environment:

    python artist_workflow.py ARGS                       (a virtual environment with bpy 4.2+)
    blender -b --factory-startup --python-exit-code 1 --python artist_workflow.py -- ARGS

ARGS: --zip ZIP --kind extension|addon --blend HEAD.blend --fba STREAM.fba --out DIR.
Prints one line per step ("install-test: <Blender> <step>: ok ..."); the first failure prints
what went wrong and exits 1. Only operators and scene data are used, as from the UI.
"""

import argparse
import sys
import time
from pathlib import Path

import bpy  # with bpy as a module, Blender starts here

import addon_utils
import numpy as np

BLENDER = "Blender " + bpy.app.version_string.split()[0]
HEAD = "MakeHuman head"  # samples/make_blend.py's head object


class StepFailed(Exception):
    pass


def check(condition: bool, message: str) -> None:
    if not condition:
        raise StepFailed(message)


def run(name: str, step, *args) -> object:
    started = time.monotonic()
    try:
        result, detail = step(*args)
    except Exception as error:  # noqa: BLE001 - any failure ends the test with its step named
        print(f"install-test: {BLENDER} {name}: FAILED: {type(error).__name__}: {error}",
              flush=True)
        sys.exit(1)
    print(f"install-test: {BLENDER} {name}: ok, {detail} ({time.monotonic() - started:.1f} s)",
          flush=True)
    return result


def install(zip_path: Path, kind: str) -> tuple[str, str]:
    """Installs and enables the zip as the UI's Install from Disk does; returns the add-on's
    module name."""
    if kind == "extension":
        result = bpy.ops.extensions.package_install_files(
            filepath=str(zip_path), repo="user_default", enable_on_install=True)
        module = "bl_ext.user_default.mpeg4face"
    else:
        result = bpy.ops.preferences.addon_install(filepath=str(zip_path))
        module = "mpeg4face_blender"
        if result == {"FINISHED"}:
            addon_utils.enable(module, default_set=True)
    check(result == {"FINISHED"}, f"installing {zip_path.name} returned {result}")
    check(addon_utils.check(module) == (True, True), f"{module} is not enabled")
    check(hasattr(bpy.types, "MPEG4FACE_OT_generate_tables"),
          "the add-on registered only its preferences: " + preferences_text(module))
    import mpeg4face

    user = Path(bpy.utils.resource_path("USER")).resolve()
    module_file = Path(mpeg4face.__file__).resolve()
    check(user in module_file.parents,
          f"mpeg4face was imported from {module_file}, not from the user folder {user}")
    return module, f"{module} enabled, mpeg4face {mpeg4face.__version__} from " \
                   f"{module_file.parent.relative_to(user)}"


def preferences_text(module: str) -> str:
    preferences = sys.modules.get(module + ".ui.preferences")
    native = sys.modules.get(module + ".native")
    if preferences is None or native is None:
        return f"{module} was not imported"
    return " / ".join(native.problem(preferences.status))


def open_head(blend: Path) -> tuple[bpy.types.Object, str]:
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    head = bpy.data.objects.get(HEAD)
    check(head is not None, f"{blend.name} has no object {HEAD!r}")
    check(bpy.context.view_layer.objects.active == head, f"{HEAD} is not the active object")
    return head, f"{blend.name}: {len(head.data.vertices)} vertices, " \
                 f"{len(head.data.shape_keys.key_blocks)} shape keys"


def generate_tables() -> tuple[None, str]:
    result = bpy.ops.mpeg4face.generate_tables()
    check(result == {"FINISHED"}, f"Generate FaceDefTables returned {result}")
    return None, "FaceDefTables generated"


def export(operator, path: Path) -> tuple[None, str]:
    result = operator(filepath=str(path))
    check(result == {"FINISHED"}, f"the export returned {result}")
    check(path.is_file() and path.stat().st_size > 0, f"{path} was not written")
    return None, f"{path.name}, {path.stat().st_size // 1024} kB"


def keyed_range(head: bpy.types.Object) -> tuple[int, float, float]:
    """The number of animated shape keys and the frame range of their keys."""
    animation = head.data.shape_keys.animation_data
    check(animation is not None and animation.action is not None, "no shape-key animation")
    action = animation.action
    # Blender 4.4+ keeps the curves in layered actions' channel bags.
    curves = getattr(action, "fcurves", None)
    if curves is None or len(curves) == 0:
        curves = [c for layer in action.layers for strip in layer.strips
                  for bag in strip.channelbags for c in bag.fcurves]
    keyed = [c for c in curves if c.data_path.startswith("key_blocks[")]
    check(keyed, "no shape key is animated")
    return len(keyed), *keyed[0].range()


def sampled_frames() -> np.ndarray:
    scene = bpy.context.scene
    return np.linspace(scene.frame_start, scene.frame_end, 12).round().astype(int)


def import_and_bake(head: bpy.types.Object, fba: Path, out: Path) -> tuple[None, str]:
    result = bpy.ops.mpeg4face.import_fap_stream(filepath=str(fba), preview="BAKE")
    check(result == {"FINISHED"}, f"importing {fba.name} returned {result}")
    count, first, last = keyed_range(head)
    scene = bpy.context.scene
    # The baked face at the sampled frames, which run_install_test.sh compares between the
    # Blenders: the same stream must move the head the same in each.
    baked = []
    for frame in sampled_frames():
        scene.frame_set(int(frame))
        baked.append(evaluated(head))
    np.save(out / "baked.npy", np.stack(baked))
    return None, f"{fba.name} baked: {count} shape keys animated over frames " \
                 f"{first:.0f}-{last:.0f}, scene {scene.frame_start}-{scene.frame_end} " \
                 f"at {scene.render.fps / scene.render.fps_base:g} fps"


def evaluated(head: bpy.types.Object) -> np.ndarray:
    data = head.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    co = np.empty(len(data.vertices) * 3, dtype=np.float32)
    data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def live_preview(head: bpy.types.Object, out: Path) -> tuple[None, str]:
    # Without the baked animation and its last values, what moves is the live preview alone.
    head.data.shape_keys.animation_data_clear()
    for block in head.data.shape_keys.key_blocks:
        block.value = 0.0
    scene = bpy.context.scene
    scene.frame_set(scene.frame_start)
    neutral = evaluated(head)
    result = bpy.ops.mpeg4face.live_preview(action="START")
    check(result == {"FINISHED"}, f"starting the live preview returned {result}")
    frames = sampled_frames()
    moved, live = [], []
    for frame in frames:
        scene.frame_set(int(frame))
        co = evaluated(head)
        check(np.isfinite(co).all(), f"frame {frame}: coordinates not finite")
        moved.append(float(np.abs(co - neutral).max()))
        live.append(co)
    np.save(out / "live.npy", np.stack(live))
    check(max(moved) > 0, f"the head does not move in frames {frames.tolist()}")
    result = bpy.ops.mpeg4face.live_preview(action="STOP")
    check(result == {"FINISHED"}, f"stopping the live preview returned {result}")
    scene.frame_set(scene.frame_start)
    check(np.allclose(evaluated(head), neutral, atol=1e-6), "stopped, the head is not neutral")
    return None, f"{len(frames)} frames evaluated, largest move {max(moved):.4f}, stopped"


def main() -> None:
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(prog="artist_workflow.py")
    parser.add_argument("--zip", type=Path, required=True)
    parser.add_argument("--kind", choices=("extension", "addon"), required=True)
    parser.add_argument("--blend", type=Path, required=True)
    parser.add_argument("--fba", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    run(f"install {args.zip.name}", install, args.zip.resolve(), args.kind)
    head = run("open the sample head", open_head, args.blend.resolve())
    run("generate tables", generate_tables)
    run("export .glb", export, bpy.ops.mpeg4face.export_gltf, args.out / "head.glb")
    run("export .wrl", export, bpy.ops.mpeg4face.export_vrml, args.out / "head.wrl")
    run("import and bake .fba", import_and_bake, head, args.fba.resolve(), args.out)
    run("live preview", live_preview, head, args.out)


main()
