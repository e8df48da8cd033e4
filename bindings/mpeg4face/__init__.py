# SPDX-License-Identifier: GPL-3.0-or-later
"""MPEG-4 Face Animation toolkit.

The MPEG-4 face animation tables (FAPs, feature points, FAPU, FAP groups, visemes,
expressions), a face model (a scene graph of meshes with morph targets and feature-point
bindings, numpy arrays in and out), readers for glTF, OBJ, CANDIDE .wfm and feature-point
CSV, a glTF writer, FAPU measurement, FAP streams (.fap files, the FBA codec, PSNR, text to
speech), faces with Face Animation Tables (from shape keys, VRML and glTF, animated by a
stream), Facial Motion Cloning and FAP Interpolation Tables. Everything is implemented in C++ (mpeg4face._core);
errors in input files raise mpeg4face.Error, a ValueError naming the file, line and field.

    >>> import mpeg4face
    >>> mpeg4face.fap(3).name
    'open_jaw'
"""

from __future__ import annotations

try:
    from . import _core
except ImportError as _error:  # pragma: no cover - depends on the build
    import glob as _glob
    import importlib.machinery as _machinery
    import os as _os

    _here = _os.path.dirname(_os.path.abspath(__file__))
    _found = sorted(_glob.glob(_os.path.join(_here, "_core*")))
    _found = [f for f in _found if not f.endswith(".pyi")]
    if _found:
        _what = f"found {', '.join(_found)} but it could not be loaded"
    else:
        _what = (
            f"looked for {_os.path.join(_here, '_core' + _machinery.EXTENSION_SUFFIXES[0])} "
            "and found no _core extension module"
        )
    raise ImportError(
        f"mpeg4face: the native module mpeg4face._core is missing: {_what} ({_error}). "
        "Build it with scripts/build.sh (or cmake -S . -B build "
        "-DPython_EXECUTABLE=/usr/bin/python3 && cmake --build build) and put build/python on "
        "PYTHONPATH; it must be built for this interpreter (Python "
        f"{'.'.join(map(str, __import__('sys').version_info[:2]))})."
    ) from _error

from ._core import *  # noqa: F401,F403  (the names are listed in __all__)

__version__: str = _core.__version__

__all__ = [
    # errors
    "Error",
    # tables (spec)
    "FAP_COUNT",
    "FEATURE_POINT_COUNT",
    "ANGLE_UNIT",
    "FAPU_DIVISOR",
    "FapInfo",
    "FeaturePointInfo",
    "FapuInfo",
    "FapGroupInfo",
    "VisemeInfo",
    "ExpressionInfo",
    "faps",
    "fap",
    "fap_number",
    "feature_points",
    "feature_point",
    "fapu_table",
    "fap_groups",
    "visemes",
    "expressions",
    # face model
    "MorphTarget",
    "IndexedFaceSet",
    "Transform",
    "FeaturePointBinding",
    "MorphWeightChannel",
    "MorphWeightAnimation",
    "TransformChannel",
    "FaceModel",
    "cut_face_model",
    "snap_feature_points",
    "find_feature_points",
    "decimate_face_model",
    "subdivide_face_model",
    # files
    "CandideUnit",
    "CandideModel",
    "read_model",
    "read_gltf",
    "write_gltf",
    "read_obj",
    "read_wfm",
    "candide_to_face_model",
    "name_candide_fap_units",
    "read_feature_point_csv",
    # FAPU
    "FapuDistance",
    "FapuMeasurement",
    "ConstraintWarning",
    "measure_fapu",
    "check_location_constraints",
    # FAP streams, their coding and speech
    "FapStream",
    "FbaEncoding",
    "read_fap",
    "write_fap",
    "read_fap_stream",
    "write_file_atomically",
    "encode_fba",
    "decode_fba",
    "psnr",
    "robust_psnr",
    "speak",
    # faces with tables, cloning, FAP Interpolation Tables
    "parse_shape_key_name",
    "format_shape_key_name",
    "MpegFace",
    "generate_face",
    "read_vrml",
    "write_vrml",
    "write_face_gltf",
    "FatEvaluator",
    "border_weights",
    "vertex_normals",
    "clone_feature_points",
    "clone_face",
    "CloneRelaxation",
    "FitTable",
    "read_fit_json",
    "fit_table_from_json",
    "fit_preset",
    # the motion check
    "check_motion",
    "surface_bump",
    "relax_displacement",
    # ARKit blendshapes
    "arkit_shape_names",
    "arkit_shape_index",
    "find_arkit_shapes",
    "map_arkit_to_faps",
    "arkit_fap_keys",
    # face captures (Live Link Face, ARKit weights)
    "livelink_channel_names",
    "LiveLinkCapture",
    "read_livelink_csv",
    "write_livelink_csv",
    "ArkitCaptureFace",
    "prepare_arkit_capture_face",
    "arkit_capture_to_faps",
    "faps_to_arkit",
    "capture_fidelity",
    # the 2D mesh object
    "read_mesh2d",
    "write_mesh2d",
    "mesh2d_triangles",
    "mesh2d_traversal",
    "encode_mesh2d",
    "decode_mesh2d",
    "design_mesh2d",
    "render_mesh2d",
    "portrait_mesh2d",
]
