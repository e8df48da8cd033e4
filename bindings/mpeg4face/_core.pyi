# SPDX-License-Identifier: GPL-3.0-or-later
"""Type hints for mpeg4face._core, the pybind11 module behind the mpeg4face package."""

import enum
import os
from typing import Any, Callable, Iterable, Literal, Mapping, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

_Path = str | os.PathLike[str]
_Float64 = npt.NDArray[np.float64]
_Int32 = npt.NDArray[np.int32]
# Anything numpy.asarray turns into numbers of the expected shape.
_ArrayLike = npt.ArrayLike

class Error(ValueError):
    """An error of the mpeg4face library; attributes are None when they do not apply."""

    file: str | None
    line: int | None
    field: str | None
    reason: str
    def __init__(
        self,
        message: str = "",
        file: str | None = None,
        line: int | None = None,
        field: str | None = None,
        reason: str | None = None,
    ) -> None: ...

# --- Tables ---------------------------------------------------------------------------------

FAP_COUNT: int  # 68
FEATURE_POINT_COUNT: int  # 84 (the table also holds 7.2)
ANGLE_UNIT: float  # 1e-5 rad
FAPU_DIVISOR: float  # 1024.0

class FapInfo:
    @property
    def number(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def bifs_name(self) -> str: ...
    @property
    def fapu(self) -> str | None: ...
    @property
    def bidirectional(self) -> bool: ...
    @property
    def positive_motion(self) -> str: ...
    @property
    def group(self) -> int: ...
    @property
    def feature_point(self) -> str: ...
    @property
    def quant_step(self) -> int: ...
    @property
    def intra_range(self) -> int: ...
    @property
    def inter_range(self) -> int: ...

class FeaturePointInfo:
    @property
    def id(self) -> str: ...
    @property
    def group(self) -> int: ...
    @property
    def index(self) -> int: ...
    @property
    def description(self) -> str: ...
    @property
    def constraint_x(self) -> str: ...
    @property
    def constraint_y(self) -> str: ...
    @property
    def constraint_z(self) -> str: ...
    @property
    def constraint_note(self) -> str: ...
    @property
    def in_standard(self) -> bool: ...

class FapuInfo:
    @property
    def name(self) -> str: ...
    @property
    def neutral_name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def definition(self) -> str: ...

class FapGroupInfo:
    @property
    def number(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def first_fap(self) -> int: ...
    @property
    def last_fap(self) -> int: ...

class VisemeInfo:
    @property
    def number(self) -> int: ...
    @property
    def phonemes(self) -> str: ...
    @property
    def example(self) -> str: ...

class ExpressionInfo:
    @property
    def number(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...

def faps() -> list[FapInfo]: ...
def fap(number: int) -> FapInfo: ...
def fap_number(name: str) -> int | None: ...
def feature_points() -> list[FeaturePointInfo]: ...
def feature_point(id: str) -> FeaturePointInfo | None: ...
def fapu_table() -> list[FapuInfo]: ...
def fap_groups() -> list[FapGroupInfo]: ...
def visemes() -> list[VisemeInfo]: ...
def expressions() -> list[ExpressionInfo]: ...

# --- Face model -----------------------------------------------------------------------------
# Array properties return the stored array (in-place edits change the object); assigning
# copies and converts any numeric dtype, and raises ValueError for a wrong shape. List and
# dict properties return the stored list/dict itself.

class MorphTarget:
    name: str
    @property
    def displacements(self) -> _Float64: ...  # (N, 3)
    @displacements.setter
    def displacements(self, value: _ArrayLike) -> None: ...
    def __init__(self, name: str = "", displacements: _ArrayLike | None = None) -> None: ...

class IndexedFaceSet:
    name: str
    @property
    def coord(self) -> _Float64: ...  # (N, 3)
    @coord.setter
    def coord(self, value: _ArrayLike | None) -> None: ...
    @property
    def coord_index(self) -> _Int32: ...  # (K,), -1 after each face
    @coord_index.setter
    def coord_index(self, value: _ArrayLike | None) -> None: ...
    @property
    def normal(self) -> _Float64: ...  # (N, 3) or (0, 3)
    @normal.setter
    def normal(self, value: _ArrayLike | None) -> None: ...
    @property
    def tex_coord(self) -> _Float64: ...  # (M, 2) or (0, 2)
    @tex_coord.setter
    def tex_coord(self, value: _ArrayLike | None) -> None: ...
    @property
    def tex_coord_index(self) -> _Int32: ...  # like coord_index, or empty
    @tex_coord_index.setter
    def tex_coord_index(self, value: _ArrayLike | None) -> None: ...
    @property
    def morph_targets(self) -> list[MorphTarget]: ...
    @morph_targets.setter
    def morph_targets(self, value: Iterable[MorphTarget] | None) -> None: ...
    @property
    def weights(self) -> _Float64: ...  # (T,) or (0,)
    @weights.setter
    def weights(self, value: _ArrayLike | None) -> None: ...
    @property
    def source_index(self) -> _Int32: ...  # (N,) or (0,)
    @source_index.setter
    def source_index(self, value: _ArrayLike | None) -> None: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    def triangles(self) -> _Int32: ...  # (T, 3)
    def __init__(
        self,
        name: str = "",
        coord: _ArrayLike | None = None,
        coord_index: _ArrayLike | None = None,
        *,
        normal: _ArrayLike | None = None,
        tex_coord: _ArrayLike | None = None,
        tex_coord_index: _ArrayLike | None = None,
        morph_targets: Iterable[MorphTarget] | None = None,
        weights: _ArrayLike | None = None,
        source_index: _ArrayLike | None = None,
    ) -> None: ...

class Transform:
    name: str
    @property
    def translation(self) -> _Float64: ...  # (3,)
    @translation.setter
    def translation(self, value: _ArrayLike) -> None: ...
    @property
    def rotation(self) -> _Float64: ...  # (4,) quaternion x, y, z, w
    @rotation.setter
    def rotation(self, value: _ArrayLike) -> None: ...
    @property
    def scale(self) -> _Float64: ...  # (3,)
    @scale.setter
    def scale(self, value: _ArrayLike) -> None: ...
    @property
    def center(self) -> _Float64: ...  # (3,)
    @center.setter
    def center(self, value: _ArrayLike) -> None: ...
    @property
    def children(self) -> list[int]: ...
    @children.setter
    def children(self, value: Iterable[int] | None) -> None: ...
    @property
    def meshes(self) -> list[int]: ...
    @meshes.setter
    def meshes(self, value: Iterable[int] | None) -> None: ...
    def local_matrix(self) -> _Float64: ...  # (4, 4)
    def __init__(
        self,
        name: str = "",
        *,
        translation: _ArrayLike | None = None,
        rotation: _ArrayLike | None = None,
        scale: _ArrayLike | None = None,
        center: _ArrayLike | None = None,
        children: Iterable[int] | None = None,
        meshes: Iterable[int] | None = None,
    ) -> None: ...

class FeaturePointBinding:
    mesh: int
    vertex: int
    @property
    def position(self) -> _Float64: ...  # (3,)
    @position.setter
    def position(self, value: _ArrayLike) -> None: ...
    def __init__(self, mesh: int = -1, vertex: int = -1, position: _ArrayLike | None = None) -> None: ...

class MorphWeightChannel:
    class Interpolation(enum.Enum):
        LINEAR = 0
        STEP = 1
        CUBICSPLINE = 2
    mesh: int
    interpolation: Interpolation
    @property
    def times(self) -> _Float64: ...
    @times.setter
    def times(self, value: _ArrayLike | None) -> None: ...
    @property
    def weights(self) -> _Float64: ...
    @weights.setter
    def weights(self, value: _ArrayLike | None) -> None: ...
    def __init__(
        self,
        mesh: int = 0,
        interpolation: Interpolation = ...,
        times: _ArrayLike | None = None,
        weights: _ArrayLike | None = None,
    ) -> None: ...

class TransformChannel:
    class Path(enum.Enum):
        TRANSLATION = 0
        ROTATION = 1
        SCALE = 2
    transform: int
    path: Path
    interpolation: MorphWeightChannel.Interpolation
    @property
    def times(self) -> _Float64: ...
    @times.setter
    def times(self, value: _ArrayLike | None) -> None: ...
    @property
    def values(self) -> _Float64: ...
    @values.setter
    def values(self, value: _ArrayLike | None) -> None: ...
    def __init__(
        self,
        transform: int = 0,
        path: Path = ...,
        interpolation: MorphWeightChannel.Interpolation = ...,
        times: _ArrayLike | None = None,
        values: _ArrayLike | None = None,
    ) -> None: ...

class MorphWeightAnimation:
    name: str
    @property
    def channels(self) -> list[MorphWeightChannel]: ...
    @channels.setter
    def channels(self, value: Iterable[MorphWeightChannel] | None) -> None: ...
    @property
    def transform_channels(self) -> list[TransformChannel]: ...
    @transform_channels.setter
    def transform_channels(self, value: Iterable[TransformChannel] | None) -> None: ...
    def __init__(
        self,
        name: str = "",
        channels: Iterable[MorphWeightChannel] | None = None,
        transform_channels: Iterable[TransformChannel] | None = None,
    ) -> None: ...

class FaceModel:
    @property
    def meshes(self) -> list[IndexedFaceSet]: ...
    @meshes.setter
    def meshes(self, value: Iterable[IndexedFaceSet] | None) -> None: ...
    @property
    def transforms(self) -> list[Transform]: ...
    @transforms.setter
    def transforms(self, value: Iterable[Transform] | None) -> None: ...
    @property
    def roots(self) -> list[int]: ...
    @roots.setter
    def roots(self, value: Iterable[int] | None) -> None: ...
    @property
    def feature_points(self) -> dict[str, FeaturePointBinding]: ...
    @feature_points.setter
    def feature_points(self, value: Mapping[str, FeaturePointBinding] | None) -> None: ...
    @property
    def animations(self) -> list[MorphWeightAnimation]: ...
    @animations.setter
    def animations(self, value: Iterable[MorphWeightAnimation] | None) -> None: ...
    def __init__(
        self,
        *,
        meshes: Iterable[IndexedFaceSet] | None = None,
        transforms: Iterable[Transform] | None = None,
        roots: Iterable[int] | None = None,
        feature_points: Mapping[str, FeaturePointBinding] | None = None,
        animations: Iterable[MorphWeightAnimation] | None = None,
    ) -> None: ...
    def find_mesh(self, name: str) -> int | None: ...
    def find_transform(self, name: str) -> int | None: ...
    def feature_point_position(self, id: str) -> _Float64 | None: ...  # (3,)
    def mesh_world_matrices(self) -> _Float64: ...  # (M, 4, 4)
    def add_mesh_with_transform(self, mesh: IndexedFaceSet) -> int: ...
    def validate(self) -> None: ...

# --- Files ----------------------------------------------------------------------------------

class CandideUnit:
    name: str
    fap: int
    fapu: str
    @property
    def vertices(self) -> _Int32: ...
    @vertices.setter
    def vertices(self, value: _ArrayLike | None) -> None: ...
    @property
    def displacements(self) -> _Float64: ...  # (len(vertices), 3)
    @displacements.setter
    def displacements(self, value: _ArrayLike | None) -> None: ...
    def __init__(
        self,
        name: str = "",
        fap: int = 0,
        fapu: str = "",
        vertices: _ArrayLike | None = None,
        displacements: _ArrayLike | None = None,
    ) -> None: ...

class CandideModel:
    model: FaceModel
    @property
    def animation_units(self) -> list[CandideUnit]: ...
    @animation_units.setter
    def animation_units(self, value: Iterable[CandideUnit] | None) -> None: ...
    @property
    def shape_units(self) -> list[CandideUnit]: ...
    @shape_units.setter
    def shape_units(self, value: Iterable[CandideUnit] | None) -> None: ...
    def __init__(
        self,
        model: FaceModel | None = None,
        animation_units: Iterable[CandideUnit] | None = None,
        shape_units: Iterable[CandideUnit] | None = None,
    ) -> None: ...

def cut_face_model(
    model: FaceModel, point: _ArrayLike, normal: _ArrayLike, meshes: Sequence[str] | None = None
) -> FaceModel: ...
def snap_feature_points(
    model: FaceModel, tolerance: float = 0.02
) -> tuple[FaceModel, list[str], list[str]]: ...
def decimate_face_model(model: FaceModel, vertex_fraction: float) -> FaceModel: ...
def subdivide_face_model(model: FaceModel, iterations: int) -> FaceModel: ...
def find_feature_points(
    target: FaceModel,
    template: FaceModel,
    pins: Mapping[str, FeaturePointBinding] = ...,
    progress: Callable[[float, str], None] | None = None,
) -> tuple[dict[str, tuple[FeaturePointBinding, float, str]], dict[str, Any]]: ...
def read_model(path: _Path) -> FaceModel: ...
def read_gltf(path: _Path) -> FaceModel: ...
def write_gltf(model: FaceModel, path: _Path) -> None: ...
def read_obj(path: _Path) -> FaceModel: ...
def read_wfm(path: _Path) -> CandideModel: ...
def candide_to_face_model(candide: CandideModel) -> FaceModel: ...
def name_candide_fap_units(model: FaceModel, candide: CandideModel) -> FaceModel: ...
def read_feature_point_csv(
    path: _Path, model: FaceModel
) -> tuple[dict[str, FeaturePointBinding], list[str]]: ...

# --- FAPU -----------------------------------------------------------------------------------

class FapuDistance:
    measured: bool
    value: float
    @property
    def points_used(self) -> tuple[str, ...]: ...
    @points_used.setter
    def points_used(self, value: Sequence[str]) -> None: ...
    method: str
    def __init__(
        self,
        measured: bool = False,
        value: float = 0.0,
        points_used: Sequence[str] = ...,
        method: str = "",
    ) -> None: ...

class FapuMeasurement:
    es0: FapuDistance
    irisd0: FapuDistance
    ens0: FapuDistance
    mns0: FapuDistance
    mw0: FapuDistance
    def __init__(self) -> None: ...
    def unit(self, fapu: str) -> float: ...
    def missing(self) -> list[str]: ...

class ConstraintWarning:
    @property
    def feature_point(self) -> str: ...
    @property
    def axis(self) -> str: ...
    @property
    def message(self) -> str: ...
    @property
    def advisory(self) -> bool: ...

def measure_fapu(model: FaceModel) -> FapuMeasurement: ...
def check_location_constraints(
    model: FaceModel, fapu: FapuMeasurement, tolerance: float = 0.02
) -> list[ConstraintWarning]: ...

# --- FAP streams, their coding and speech ---------------------------------------------------
_Bool = npt.NDArray[np.bool_]

class FapStream:
    name: str
    frame_rate: float
    def __init__(self) -> None: ...
    @staticmethod
    def from_arrays(
        frame_numbers: _ArrayLike,
        mask: _ArrayLike,
        values: _ArrayLike,
        visemes: _ArrayLike | None = None,
        expressions: _ArrayLike | None = None,
        frame_rate: float = 25.0,
        name: str = "",
    ) -> FapStream: ...
    @property
    def duration(self) -> float: ...
    def __len__(self) -> int: ...
    @property
    def frame_numbers(self) -> _Int32: ...  # (N,)
    @property
    def mask(self) -> _Bool: ...  # (N, 68), column i is FAP i + 1
    @property
    def values(self) -> _Int32: ...  # (N, 68)
    @property
    def visemes(self) -> _Int32: ...  # (N, 4) select1, select2, blend, def
    @property
    def expressions(self) -> _Int32: ...  # (N, 6) select1, intensity1, select2, intensity2, init_face, def
    def resolved(self) -> dict[str, npt.NDArray[np.generic]]: ...

class FbaEncoding:
    @property
    def data(self) -> bytes: ...
    @property
    def bits(self) -> int: ...
    @property
    def bits_per_second(self) -> float: ...
    @property
    def psnr(self) -> float | None: ...
    @property
    def robust_psnr(self) -> float | None: ...
    @property
    def intra_frames(self) -> int: ...
    @property
    def reconstruction(self) -> FapStream: ...

def read_fap(path: _Path) -> FapStream: ...
def write_fap(stream: FapStream, path: _Path) -> None: ...
def read_fap_stream(path: _Path) -> FapStream: ...
def write_file_atomically(path: _Path, data: bytes) -> None: ...
def encode_fba(
    stream: FapStream,
    mode: str = "predictive",
    fap_quant: int = 1,
    intra_period: int = 0,
    pca_temporal: str = "predictive",
    pca_basis_bits: int = 4,
    rdo_lambda: float = 0.0,
) -> FbaEncoding: ...
def decode_fba(data: bytes, source: str = "", strict: bool = False) -> FapStream: ...
def psnr(original: FapStream, decoded: FapStream) -> float | None: ...
def robust_psnr(original: FapStream, decoded: FapStream) -> float | None: ...
def speak(
    text: str,
    audio: _Path,
    frame_rate: float = 25.0,
    voice: str = "",
    transition: float = 0.08,
    program: str = "flite",
) -> FapStream: ...

# --- Faces with tables, cloning, FAP Interpolation Tables -----------------------------------

class ShapeKeyName(TypedDict):
    fap: int
    select: int
    amplitude: int
    label: str

def parse_shape_key_name(name: str) -> ShapeKeyName | None: ...
def format_shape_key_name(fap: int, amplitude: int = 63, select: int = 0, label: str = "") -> str: ...

class FitTable:
    @property
    def nodes(self) -> list[list[int]]: ...
    @property
    def link_count(self) -> int: ...
    def problems(self) -> list[str]: ...
    def interpolate(self, stream: FapStream) -> FapStream: ...
    def to_json(self) -> str: ...

def read_fit_json(path: _Path) -> FitTable: ...
def fit_table_from_json(text: str, source: str = "FIT JSON") -> FitTable: ...
def fit_preset(name: str) -> FitTable: ...

class MpegFace:
    fit: FitTable | None
    @property
    def scene_graph(self) -> FaceModel: ...
    @property
    def tables(self) -> list[dict[str, object]]: ...  # fap, select, meshes, transforms
    def validate(self) -> None: ...

class GeneratedFace(TypedDict):
    face: MpegFace
    copies: int
    warnings: list[str]
    ignored: list[str]

def generate_face(
    model: FaceModel, threshold: float = 0.01, absolute_threshold: float | None = None
) -> GeneratedFace: ...
# ARKit blendshapes (docs/arkit.md)
class ArkitShapeRef(TypedDict):
    shape: str  # Apple's spelling, e.g. "eyeBlinkLeft"
    index: int  # into the 52 (then cheekRaiserLeft/Right, pupilDilateLeft/Right: 52..55)
    half: str | None  # "left" / "right" for a half of a whole shape (browInnerUp_L)

class ArkitShape(ArkitShapeRef):
    name: str  # the head's morph-target name
    meshes: list[int]

class ArkitFapKey(TypedDict):
    fap: int
    amplitude: int
    name: str  # fap<N>_<name>@<amplitude>
    weights: dict[str, float]  # morph-target name -> weight, largest first
    reached: float
    residual: float
    worst_point: str  # the other feature point the key moves most ("" for poses)
    worst_motion: float  # its motion relative to the key's own
    transform: int | None  # eyeball turns: the eye's Transform
    rotation: tuple[float, float, float, float] | None  # x, y, z, w

class ArkitMissedFap(TypedDict):
    fap: int
    sign: int  # +1 / -1, 0 for the FAP
    reason: str

class ArkitMapping(TypedDict):
    keys: list[ArkitFapKey]
    missed: list[ArkitMissedFap]

class ArkitKeys(TypedDict):
    head: FaceModel
    mapping: list[ArkitFapKey]
    missed: list[ArkitMissedFap]
    warnings: list[str]

def arkit_shape_names() -> list[str]: ...
def arkit_shape_index(name: str) -> ArkitShapeRef | None: ...
def find_arkit_shapes(head: FaceModel) -> list[ArkitShape]: ...
def map_arkit_to_faps(head: FaceModel) -> ArkitMapping: ...
def arkit_fap_keys(head: FaceModel, visemes: bool = True, expressions: bool = True) -> ArkitKeys: ...
def read_vrml(path: _Path) -> MpegFace: ...
def write_vrml(face: MpegFace, path: _Path) -> None: ...
def write_face_gltf(face: MpegFace, path: _Path, streams: Sequence[FapStream] = ...) -> None: ...

class FatState(TypedDict):
    coord: list[_Float64]  # one (N, 3) array per mesh
    translation: _Float64  # (T, 3)
    rotation: _Float64  # (T, 4) quaternions x, y, z, w
    scale: _Float64  # (T, 3)

def vertex_normals(coord: _ArrayLike, triangles: _ArrayLike) -> npt.NDArray[np.float32]: ...

class ObjectCoordinates(TypedDict):
    coord: list[_Float64]  # one (N, 3) array per object's mesh, as FatState's
    placed: list[npt.NDArray[np.float32]]  # (N, 3) in the object's frame, turned by axes
    placement: _Float64  # (O, 4, 4): coord -> placed

class FatEvaluator:
    def __init__(self, face: MpegFace, storage: Literal["float", "int16"] = "float") -> None: ...
    def evaluate(self, stream: FapStream, index: int) -> FatState: ...
    def object_coordinates(
        self,
        stream: FapStream,
        index: int,
        chains: Sequence[Sequence[int]],
        axes: _ArrayLike | None = None,
    ) -> ObjectCoordinates: ...
    def neutral(self) -> FatState: ...
    def priority_frames(self, stream: FapStream) -> npt.NDArray[np.bool_]: ...

def border_weights(borders: Sequence[int], values: _ArrayLike) -> _Float64: ...

class MeshDisplacement(TypedDict):
    mesh: int
    vertices: _Int32  # ascending; the mesh's other vertices do not move
    displacement: _Float64  # (len(vertices), 3)

class FaceShape(TypedDict):
    name: str
    fap: int
    select: int
    amplitude: int
    meshes: list[MeshDisplacement]  # the meshes with a vertex that moves, ascending
    transforms: list[Transform]  # empty: the neutral's, unchanged

class ClonedFace(TypedDict):
    face: MpegFace
    copies: list[FaceShape]
    warnings: list[str]

def clone_feature_points() -> list[str]: ...
class CloneRelaxation:
    fap_passes: int
    fringe_passes: int
    fringe_below: float
    attached_neighbours: int
    attached_passes: int
    def __init__(
        self,
        *,
        fap_passes: int = 4,
        fringe_passes: int = 2,
        fringe_below: float = 0.2,
        attached_neighbours: int = 16,
        attached_passes: int = 4,
    ) -> None: ...

def clone_face(
    source: FaceModel | MpegFace,
    target: FaceModel,
    filter_support: float = 0.02,
    adaptive_filter: bool = True,
    rigid_parts: bool = True,
    relaxation: CloneRelaxation | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> ClonedFace: ...

# The motion check (docs/motion-check.md); the keys of `mpeg4face check --json`.
class MeshMotion(TypedDict):
    mesh: int
    moved_edges: int
    edge_ratio_max: float
    edge_ratio_p99: float
    offending_vertices: _Int32
    flipped_triangles: list[int]  # indices into the mesh's fan triangles; not contact folds
    contact_folds: int  # flipped triangles where lips or lids meet
    new_intersections: list[tuple[int, int]]  # triangle pairs
    touching_self_intersections: int
    own_shape_faults: int  # flips, pairs and spikes the head's own shapes make too
    spike_vertices: _Int32  # ascending
    bump_p99_of_peak: float
    bump_ratio_max: float

class PoseMotion(TypedDict):
    name: str
    stream: int  # -1 for a key
    frame: int
    edge_ratio_max: float
    edge_ratio_p99: float
    normal_flips: int
    contact_folds: int
    new_self_intersections: int
    touching_self_intersections: int
    spikes: int
    own_shape_faults: int
    bump_p99_of_peak: float
    bump_ratio_max: float
    lip_corner_outside_mw0: float | None
    inner_lip_gap_mns0: float | None
    failures: list[str]
    meshes: list[MeshMotion]

class StreamMotion(TypedDict):
    name: str
    frames: int
    inner_lip_gap_min_mns0: float
    inner_lip_gap_max_mns0: float

class MotionCheck(TypedDict):
    passed: bool
    keys: list[PoseMotion]
    frames: list[PoseMotion]
    streams: list[StreamMotion]
    neutral_self_intersections: int
    neutral_lip_gap_mns0: float | None
    lower_lip_share: float | None
    failures: list[str]
    notes: list[str]
    own_shapes: list[str]  # the head's shape keys outside the grammar, measured first

def check_motion(
    face: FaceModel | MpegFace,
    streams: Sequence[FapStream] = ...,
    *,
    max_edge_ratio: float = 2.0,
    flip_degrees: float = 120.0,
    max_flips: int = 0,
    max_intersections: int = 0,
    max_spikes: int = 0,
    spike_ratio: float = 0.75,
    spike_of_peak: float = 0.05,
    max_lip_corner: float = 0.02,
    min_lower_lip: float = 0.5,
    lip_region: float = 0.25,
    lid_region: float = 0.2,
    own_shapes: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> MotionCheck: ...

class SurfaceBump(TypedDict):
    bump: _Float64  # (N,), NaN for a vertex on no triangle
    local_motion: _Float64  # (N,)
    peak: float
    bump_p99_of_peak: float
    bump_ratio_max: float
    spikes: _Int32  # ascending

def surface_bump(
    mesh: IndexedFaceSet,
    displacements: _ArrayLike,
    *,
    spike_ratio: float = 0.75,
    spike_of_peak: float = 0.05,
) -> SurfaceBump: ...
def relax_displacement(
    mesh: IndexedFaceSet,
    displacements: _ArrayLike,
    passes: int,
    *,
    where: _ArrayLike | None = None,
) -> _Float64: ...
# Face captures (Live Link Face, ARKit weights; docs/arkit.md)
def livelink_channel_names() -> list[str]: ...

class LiveLinkCapture:
    channels: list[str]
    times: _Float64
    values: _Float64
    frame_rate: float
    @property
    def clamped_weights(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...
    def __init__(self) -> None: ...
    def __len__(self) -> int: ...

def read_livelink_csv(path: _Path) -> LiveLinkCapture: ...
def write_livelink_csv(capture: LiveLinkCapture, path: _Path) -> None: ...

class ArkitCaptureFace:
    @property
    def has_shape(self) -> list[bool]: ...
    @property
    def area(self) -> _Int32: ...
    @property
    def shape_motion(self) -> _Float64: ...
    @property
    def fap_motion(self) -> _Float64: ...
    @property
    def column_fap(self) -> list[int]: ...
    @property
    def column_sign(self) -> list[int]: ...
    @property
    def column_reach(self) -> list[float]: ...
    @property
    def from_tables(self) -> bool: ...
    @property
    def warnings(self) -> list[str]: ...

def prepare_arkit_capture_face(head: FaceModel) -> ArkitCaptureFace: ...
def arkit_capture_to_faps(
    capture: LiveLinkCapture, head: FaceModel | ArkitCaptureFace, fps: float = 25.0
) -> FapStream: ...
def faps_to_arkit(stream: FapStream, head: FaceModel | ArkitCaptureFace) -> LiveLinkCapture: ...
def capture_fidelity(capture: LiveLinkCapture, head: FaceModel | ArkitCaptureFace, stream: FapStream) -> dict: ...

# The 2D mesh object (docs/mesh2d.md): a sequence is a dict with the JSON form's keys,
# "frames" float64 (frames, nodes, 2), "triangles" int32 (M, 3).
def read_mesh2d(path: _Path) -> dict: ...
def write_mesh2d(sequence: dict, path: _Path) -> None: ...
def mesh2d_triangles(sequence: dict) -> _Int32: ...
def mesh2d_traversal(sequence: dict) -> dict: ...
def encode_mesh2d(sequence: dict, step: float = 0.5) -> tuple[bytes, dict]: ...
def decode_mesh2d(data: bytes) -> dict: ...
def design_mesh2d(
    image: _Path,
    uniform: tuple[int, int] | None = None,
    delaunay: int | None = None,
    mask: _Path | None = None,
    topology: int = 0,
) -> dict: ...
def render_mesh2d(
    image: _Path, sequence: dict, out: _Path, audio: _Path | None = None, fps: float = 25.0
) -> None: ...
def portrait_mesh2d(
    width: int,
    height: int,
    feature_points: _Path,
    stream: _Path | None = None,
    tracks: _Path | None = None,
) -> dict: ...
