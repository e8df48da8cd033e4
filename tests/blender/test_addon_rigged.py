# SPDX-License-Identifier: GPL-3.0-or-later
"""A bone-rigged head: CANDIDE-3 skinned by an Armature modifier to a jaw bone and two eye
bones (weights computed here), with a corrective shape key driven by the jaw, posed at
grammar markers. The FaceDefTables are generated from the evaluated rig: at each marker's
amplitude they give the rig's evaluated mesh, between amplitudes the FAT rule's
interpolation; the .wrl and .glb exports validate and a coded, decoded stream plays on the
head. A Subdivision modifier, a missing armature and bones that miss a feature point are
refused with nothing written. Run through run_in_blender.py."""

import os
import re
import shlex
import subprocess
import time

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402
from mathutils import Matrix, Vector  # noqa: E402

import conftest  # noqa: E402
from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene import mesh_data, poses  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402

# marker -> frame, (jaw, left eye, right eye) rotations in radians
JAW_HALF, JAW_FULL, EYE_TURN = 0.12, 0.3, 0.25
POSES = {
    "neutral": (1, (0.0, 0.0, 0.0)),
    "fap3_open_jaw@512": (10, (JAW_HALF, 0.0, 0.0)),
    "fap3_open_jaw@1024": (20, (JAW_FULL, 0.0, 0.0)),
    "fap23_yaw_l_eyeball@50000": (30, (0.0, EYE_TURN, 0.0)),
    "fap24_yaw_r_eyeball@50000": (40, (0.0, 0.0, EYE_TURN)),
}
CORRECTIVE = 0.02  # the jaw corrective pushes the chin forward (-Y) this far at JAW_FULL


def _smooth(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def rig_head(head, fp_vertices):
    """An armature "rig" (bones head, jaw, eye.L, eye.R) skinning `head`, keyframed at the
    POSES markers, and the driven corrective key; returns the armature object."""
    coords = np.array([v.co[:] for v in head.data.vertices])
    point = {fp: coords[v] for fp, v in fp_vertices.items()}
    size = np.ptp(coords, axis=0)
    corner_z = (point["8.3"][2] + point["8.4"][2]) / 2
    pivot = Vector((0.0, point["2.1"][1] + 0.7 * size[1], corner_z + 0.05 * size[2]))
    eyes = {side: Vector(np.mean([point[f"3.{i}"] for i in ids], axis=0))
            for side, ids in (("L", (1, 3, 7, 11)), ("R", (2, 4, 8, 12)))}

    data = bpy.data.armatures.new("rig")
    rig = bpy.data.objects.new("rig", data)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    for name, at, tail in (("head", (0, 0, 0), (0, 0, 0.3 * size[2])),
                           ("jaw", pivot, Vector(point["2.1"])),
                           ("eye.L", eyes["L"], eyes["L"] + Vector((0, -0.1, 0))),
                           ("eye.R", eyes["R"], eyes["R"] + Vector((0, -0.1, 0)))):
        bone = data.edit_bones.new(name)
        bone.head, bone.tail = Vector(at), Vector(tail)
    bpy.ops.object.mode_set(mode="OBJECT")

    # Jaw: everything below the lip corners, blended over a band; eyes: a ball around each.
    jaw = _smooth((corner_z - coords[:, 2]) / (0.08 * size[2]) + 0.5)
    jaw[fp_vertices["2.2"]], jaw[fp_vertices["2.3"]] = 0.0, 1.0  # the lower lip goes along
    weights = {"jaw": jaw}
    for side, centre in eyes.items():
        weights[f"eye.{side}"] = _smooth(
            2.0 - np.linalg.norm(coords - np.array(centre), axis=1) / (0.06 * size[0]))
    weights["head"] = np.clip(1.0 - sum(weights.values()), 0.0, 1.0)
    for name, w in weights.items():
        group = head.vertex_groups.new(name=name)
        for vertex in np.flatnonzero(w > 0):
            group.add([int(vertex)], float(w[vertex]), "REPLACE")
    modifier = head.modifiers.new("Armature", "ARMATURE")
    modifier.object = rig

    bones = rig.pose.bones
    for name in ("jaw", "eye.L", "eye.R"):
        bones[name].rotation_mode = "XYZ"
    scene = bpy.context.scene
    for marker, (frame, (jaw_angle, left, right)) in POSES.items():
        scene.timeline_markers.new(marker, frame=frame)
        for name, axis, angle in (("jaw", 0, jaw_angle), ("eye.L", 2, left),
                                  ("eye.R", 2, right)):
            rotation = [0.0, 0.0, 0.0]
            rotation[axis] = angle
            bones[name].rotation_euler = rotation
            bones[name].keyframe_insert("rotation_euler", frame=frame)

    # The corrective: the chin forward as the jaw opens, driven by the jaw's rotation.
    head.shape_key_add(name="Basis", from_mix=False)
    corrective = head.shape_key_add(name="jaw_corrective", from_mix=False)
    corrective.data[fp_vertices["2.1"]].co.y -= CORRECTIVE
    driver = corrective.driver_add("value").driver
    driver.type = "SCRIPTED"
    variable = driver.variables.new()
    variable.type = "TRANSFORMS"
    variable.targets[0].id = rig
    variable.targets[0].bone_target = "jaw"
    variable.targets[0].transform_type = "ROT_X"
    variable.targets[0].rotation_mode = "XYZ"
    variable.targets[0].transform_space = "LOCAL_SPACE"
    driver.expression = f"abs({variable.name}) / {JAW_FULL}"
    bpy.context.view_layer.objects.active = head
    head.select_set(True)
    return rig


@pytest.fixture
def rigged(candide_head):
    head, _, fp_vertices = candide_head
    rig = rig_head(head, fp_vertices)
    scene = bpy.context.scene
    scene.frame_set(5)
    yield head, rig, fp_vertices
    scene.timeline_markers.clear()
    bpy.data.objects.remove(rig)
    scene.frame_set(1)


def evaluated(head, frame):
    """The rig's own mesh at a frame, standard axes."""
    bpy.context.scene.frame_set(frame)
    return feature_points.to_standard_axes(
        poses.evaluated_coords(head, bpy.context.evaluated_depsgraph_get()))


def fap_state(face, values):
    """The evaluated face for one frame of FAP values {fap: value}, the rig's other FAPs
    sent as 0 (an unsent eyeball FAP would follow its partner): its head mesh."""
    mask, array = np.zeros((1, 68), dtype=bool), np.zeros((1, 68), dtype=np.int32)
    for fap, value in {3: 0, 23: 0, 24: 0, **values}.items():
        mask[0, fap - 1], array[0, fap - 1] = True, value
    stream = mpeg4face.FapStream.from_arrays([0], mask, array)
    return mpeg4face.FatEvaluator(face).evaluate(stream, 0)["coord"][0]


def gltf_pose(mesh, fap, value):
    """The displacement the exported glTF's morph targets give a positive FAP value: each
    interval's target (fap<N>_<name>[lower,upper], docs/fat-gltf.md) weighted by the part
    of [0, value] in the interval."""
    out = np.zeros_like(mesh.coord)
    for target in mesh.morph_targets:
        match = re.fullmatch(rf"fap{fap}_\w+\[(-?\d+),(-?\d+)\]", target.name)
        if match:
            lower, upper = int(match.group(1)), int(match.group(2))
            out += max(0, min(value, upper) - max(0, lower)) * target.displacements
    return out


def test_rig_poses_become_tables(rigged, tmp_path):
    head, _, fp_vertices = rigged
    scene = bpy.context.scene
    rig_mesh = {name: evaluated(head, frame) for name, (frame, _) in POSES.items()}
    neutral = rig_mesh["neutral"]
    size = float(np.linalg.norm(np.ptp(neutral, axis=0)))
    chin = fp_vertices["2.1"]
    opened = rig_mesh["fap3_open_jaw@1024"][chin] - neutral[chin]
    corrective = head.data.shape_keys.key_blocks["jaw_corrective"]
    corrective.mute = True
    uncorrected = evaluated(head, POSES["fap3_open_jaw@1024"][0])[chin] - neutral[chin]
    corrective.mute = False
    # The rig does what the test means: the chin down, the corrective forward (+Z).
    assert opened[1] < -0.03 * size
    # (before the armature: the jaw turns it with the chin)
    assert np.linalg.norm(opened - uncorrected) == pytest.approx(CORRECTIVE, rel=1e-4)
    assert (opened - uncorrected)[2] > 0.9 * CORRECTIVE

    wrl, glb = tmp_path / "rigged.wrl", tmp_path / "rigged.glb"
    scene.frame_set(5)
    assert bpy.ops.mpeg4face.export_vrml(filepath=str(wrl)) == {"FINISHED"}
    assert bpy.ops.mpeg4face.export_gltf(filepath=str(glb)) == {"FINISHED"}
    assert scene.frame_current == 5
    report = operators_faces.table_reports[head.name]
    assert report.ignored == ["jaw_corrective"] and report.copies == 4
    face = mpeg4face.read_vrml(wrl)
    face.validate()
    assert np.allclose(mpeg4face.FatEvaluator(face).neutral()["coord"][0], neutral, atol=1e-6)
    for name, (frame, _) in POSES.items():
        parsed = mpeg4face.parse_shape_key_name(name) if name != "neutral" else None
        if parsed is None:
            continue
        got = fap_state(face, {parsed["fap"]: parsed["amplitude"]})
        error = np.abs(got - rig_mesh[name]).max()
        assert error <= 1e-3 * size, (name, error / size)
    # Between the amplitudes, the FAT rule: piecewise linear in the FAP value.
    jaw_512, jaw_1024 = (rig_mesh[f"fap3_open_jaw@{a}"] - neutral for a in (512, 1024))
    for value, expected in ((256, jaw_512 / 2), (768, (jaw_512 + jaw_1024) / 2),
                            (1536, jaw_1024 + (jaw_1024 - jaw_512))):
        got = fap_state(face, {3: value}) - neutral
        assert np.abs(got - expected).max() <= 1e-3 * size, value
    eye = rig_mesh["fap23_yaw_l_eyeball@50000"] - neutral
    assert np.abs(fap_state(face, {23: 25000}) - neutral - eye / 2).max() <= 1e-3 * size

    # The glTF: the same copies as morph targets, and the validator's and the reader's word.
    model = mpeg4face.read_gltf(glb)
    model.validate()
    mesh = model.meshes[0]
    assert np.allclose(mesh.coord, neutral, atol=1e-6)
    for name, (frame, _) in POSES.items():
        parsed = mpeg4face.parse_shape_key_name(name) if name != "neutral" else None
        if parsed is not None:
            got = mesh.coord + gltf_pose(mesh, parsed["fap"], parsed["amplitude"])
            assert np.abs(got - rig_mesh[name]).max() <= 1e-3 * size, name
    validator = os.environ.get("MPEG4FACE_GLTF_VALIDATOR")
    if validator:
        result = subprocess.run([*shlex.split(validator), "--strict", str(glb)],
                                capture_output=True, text=True)
        assert result.returncode == 0, result.stdout + result.stderr
    result = subprocess.run(["tovrmlx3d", str(wrl)], capture_output=True, text=True)
    assert result.returncode == 0 and not result.stderr.strip(), result.stderr

    # A decoded stream plays on the rigged head: the jaw opens and closes, the eye turns.
    frames = 12
    mask = np.zeros((frames, 68), dtype=bool)
    values = np.zeros((frames, 68), dtype=np.int32)
    mask[:, [2, 22, 23]] = True
    values[:, 2] = (1024 * np.sin(np.linspace(0, np.pi, frames))).astype(np.int32)
    values[:, 22] = np.linspace(0, 50000, frames).astype(np.int32)
    stream = mpeg4face.FapStream.from_arrays(np.arange(frames), mask, values)
    decoded = mpeg4face.decode_fba(mpeg4face.encode_fba(stream).data)
    evaluator = mpeg4face.FatEvaluator(face)
    drops = [evaluator.evaluate(decoded, i)["coord"][0][chin, 1] - neutral[chin, 1]
             for i in range(frames)]
    assert min(drops) < 0.9 * (jaw_1024[chin, 1]) < 0 and abs(drops[0]) < 1e-3 * size


def test_rig_copies_are_quick(rigged, capsys):
    """60 markers on a 26k-vertex rigged head: evaluating them takes at most 5 s."""
    head, rig, _ = rigged
    scene = bpy.context.scene
    rig.animation_data_clear()  # the jaw opening from frame 1 to 61, the eyes still
    jaw = rig.pose.bones["jaw"]
    for frame, angle in ((1, 0.0), (61, JAW_FULL)):
        jaw.rotation_euler = (angle, 0.0, 0.0)
        jaw.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.object.mode_set(mode="EDIT")  # CANDIDE-3's 113 vertices, faces cut in 25, 4, 4
    bpy.ops.mesh.select_all(action="SELECT")
    for cuts in (4, 1, 1):
        bpy.ops.mesh.subdivide(number_cuts=cuts)
    bpy.ops.object.mode_set(mode="OBJECT")
    vertices = len(head.data.vertices)
    assert vertices >= 26000
    scene.timeline_markers.clear()
    scene.timeline_markers.new("neutral", frame=1)
    for i in range(60):
        scene.timeline_markers.new(f"fap3_open_jaw@{(i + 1) * 20}", frame=2 + i)
    fractions = []
    start = time.perf_counter()
    model, _ = poses.read_posed_face_model(head, operators_faces.key_names, scene, fractions.append)
    seconds = time.perf_counter() - start
    with capsys.disabled():
        print(f"\nrig copies: 60 markers x {vertices} vertices in {seconds:.2f} s")
    names = [t.name for t in model.meshes[0].morph_targets]
    assert len([n for n in names if n.startswith("fap3")]) == 60
    assert fractions[-1] == 1.0 and len(fractions) == 60
    assert seconds <= 5.0


def no_file_written(tmp_path):
    return not any(tmp_path.iterdir())


def test_subdivision_is_refused(rigged, tmp_path):
    head, _, _ = rigged
    head.modifiers.new("Subdivision", "SUBSURF")
    with pytest.raises(RuntimeError, match=r"candide3: Subsurf 'Subdivision' changes its vertex "
                                           r"count \(113 -> \d+\).*apply it or turn it off"):
        bpy.ops.mpeg4face.export_gltf(filepath=str(tmp_path / "head.glb"))
    assert no_file_written(tmp_path)


def test_missing_armature_is_refused(rigged, tmp_path):
    head, rig, _ = rigged
    head.modifiers["Armature"].object = None
    with pytest.raises(RuntimeError, match="candide3: its Armature modifier 'Armature' has no "
                                           "armature object"):
        bpy.ops.mpeg4face.export_vrml(filepath=str(tmp_path / "head.wrl"))
    assert no_file_written(tmp_path)


def test_bones_missing_the_feature_point_are_refused(rigged, tmp_path):
    head, _, fp_vertices = rigged
    # The right eye's bone posed at a marker of the left eyelid: it moves skin, not 3.1.
    bpy.context.scene.timeline_markers["fap24_yaw_r_eyeball@50000"].name = \
        "fap19_close_t_l_eyelid@512"
    with pytest.raises(RuntimeError, match=r"pose marker fap19_close_t_l_eyelid@512: the rig "
                                           r"moves the skin but not feature point 3\.1"):
        bpy.ops.mpeg4face.export_vrml(filepath=str(tmp_path / "head.wrl"))
    assert no_file_written(tmp_path)


def test_live_preview_shows_the_tables_without_the_rig_twice(rigged, tmp_path):
    """The live preview of a stream on the rigged head shows exactly the FAT result: its
    key holds the rig's motion, so the Armature modifier is off meanwhile, on again after."""
    head, _, _ = rigged
    scene = bpy.context.scene
    model, _ = poses.read_posed_face_model(head, operators_faces.key_names, scene)
    evaluator = mpeg4face.FatEvaluator(mpeg4face.generate_face(model)["face"])
    frames = 3
    mask = np.zeros((frames, 68), dtype=bool)
    values = np.zeros((frames, 68), dtype=np.int32)
    mask[:, [2, 22, 23]] = True
    values[:, 2], values[:, 22] = (0, 700, 1024), (0, 0, 30000)
    coded = mpeg4face.encode_fba(mpeg4face.FapStream.from_arrays(
        np.arange(frames), mask, values, frame_rate=scene.render.fps)).data
    path = tmp_path / "jaw.fba"  # imported as a user would, decoded by the import
    path.write_bytes(coded)
    stream = mpeg4face.decode_fba(coded)
    # The head has no grammar key to bake onto: only the live preview plays the rig.
    with pytest.raises(RuntimeError, match="only pose markers .a rig's.: choose Live preview"):
        bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="BAKE")
    start = 100
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE",
                                               start_frame=start) == {"FINISHED"}
    armature = head.modifiers["Armature"]
    assert not armature.show_viewport
    for index in range(frames):
        scene.frame_set(start + index)
        shown = poses.evaluated_coords(head, bpy.context.evaluated_depsgraph_get())
        expected = evaluator.evaluate(stream, index)["coord"][0]
        np.testing.assert_allclose(feature_points.to_standard_axes(shown), expected, atol=1e-5)
    assert np.abs(expected - model.meshes[0].coord).max() > 0.05  # the jaw open, an eye turned
    assert bpy.ops.mpeg4face.live_preview(action="STOP") == {"FINISHED"}
    assert armature.show_viewport and "mpeg4face_suspended_modifiers" not in head


def test_cloning_reads_the_rig(rigged):
    """Clone Facial Motion takes the rig's copies as the head's keys: a copy of the head
    twice its size gets the jaw's and an eye's poses as shape keys, twice as large."""
    head, _, fp_vertices = rigged
    rig_mesh = {name: evaluated(head, frame) for name, (frame, _) in POSES.items()}
    target, _, _ = conftest.make_candide_head()
    try:
        target.data.transform(Matrix.Scale(2.0, 4))
        for obj in bpy.context.view_layer.objects:
            obj.select_set(obj in (head, target))
        bpy.context.view_layer.objects.active = head
        assert bpy.ops.mpeg4face.clone_motion() == {"FINISHED"}
        blocks = target.data.shape_keys.key_blocks
        chin = fp_vertices["2.1"]
        for name in ("fap3_open_jaw@1024", "fap23_yaw_l_eyeball@50000"):
            cloned = mesh_data.shape_key_coords(blocks[name]) - mesh_data.shape_key_coords(
                target.data.shape_keys.reference_key)
            rig = feature_points.to_blender_axes(rig_mesh[name] - rig_mesh["neutral"])
            vertex = chin if name.startswith("fap3") else fp_vertices["3.1"]
            assert np.allclose(cloned[vertex], 2 * rig[vertex], atol=2e-3), name
    finally:
        data = target.data
        bpy.data.objects.remove(target)
        bpy.data.meshes.remove(data)


def test_pose_library_frames_are_poses(rigged):
    """Frames named by pose markers of the rig's action (a pose library) are poses as scene
    markers are: the same tables."""
    head, rig, _ = rigged
    scene = bpy.context.scene

    def tables():
        face, report = operators_faces.generate(head, 0.01, scene)
        return report.covered, [fap_state(face, {3: 700, 23: 20000})]

    covered, states = tables()
    assert covered == ["fap3 open_jaw", "fap23 yaw_l_eyeball", "fap24 yaw_r_eyeball"]
    action = rig.animation_data.action
    for marker in [m for m in scene.timeline_markers if m.name != "neutral"]:
        action.pose_markers.new(marker.name).frame = marker.frame
        scene.timeline_markers.remove(marker)
    again, states_again = tables()
    assert again == covered
    np.testing.assert_array_equal(states_again[0], states[0])
