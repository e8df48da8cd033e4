// SPDX-License-Identifier: GPL-3.0-or-later
// Python classes of the face model: MorphTarget, IndexedFaceSet, Transform,
// FeaturePointBinding, MorphWeightChannel, MorphWeightAnimation, FaceModel.
#include <algorithm>
#include <functional>
#include <optional>
#include <utility>

#include "bindings.hpp"
#include "mpeg4face/model/feature_point_snap.hpp"
#include "mpeg4face/model/landmarks.hpp"
#include "mpeg4face/model/mesh_cut.hpp"
#include "mpeg4face/model/mesh_resample.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;

// A property over a stored array or list: the getter returns the stored object itself, the
// setter stores a checked copy made by `check(value, "Class.name")`.
template <typename C, typename M, typename Check>
void storedProperty(py::class_<C>& cls, const char* name, M C::*member, Check check,
                    const char* doc) {
  const std::string field = std::string(py::str(cls.attr("__name__"))) + "." + name;
  cls.def_property(
      name, [member](const C& self) { return self.*member; },
      [member, field, check](C& self, py::handle value) { self.*member = check(value, field); },
      doc);
}

template <typename C>
void nameProperty(py::class_<C>& cls, const char* doc) {
  cls.def_property(
      "name", [](const C& self) { return toPy(self.name); },
      [](C& self, std::string value) { self.name = std::move(value); }, doc);
}

auto rows(py::ssize_t cols) {
  return [cols](py::handle value, const std::string& field) {
    return checkedRows(value, field, cols);
  };
}
auto fixed(py::ssize_t size) {
  return [size](py::handle value, const std::string& field) {
    return checkedFixed(value, field, size);
  };
}
template <typename T>
auto objects(const char* typeName_) {
  return [typeName_](py::handle value, const std::string& field) {
    return checkedObjectList<T>(value, field, typeName_);
  };
}

// Sets `self.member` from `value` when the caller passed one (constructor keywords).
template <typename C, typename M, typename Check>
void setIfGiven(C& self, M C::*member, const py::object& value, const char* field, Check check) {
  if (!value.is_none()) self.*member = check(value, field);
}

py::array_t<double> matrix4(const Eigen::Affine3d& m) {
  py::array_t<double> out(std::vector<py::ssize_t>{4, 4});
  auto view = out.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < 4; ++r) {
    for (py::ssize_t c = 0; c < 4; ++c) view(r, c) = m.matrix()(r, c);
  }
  return out;
}

std::string quoted(const std::string& name) { return "'" + std::string(toPy(name)) + "'"; }

std::optional<int> findByName(const py::list& list, const std::string& name, bool meshes) {
  int i = 0;
  for (py::handle item : list) {
    const std::string& itemName =
        meshes ? item.cast<const PyMesh&>().name : item.cast<const PyTransform&>().name;
    if (itemName == name) return i;
    ++i;
  }
  return std::nullopt;
}

void bindMorphTarget(py::module_& m) {
  py::class_<PyMorphTarget> cls(m, "MorphTarget",
                                "A named displacement of every vertex of a mesh (glTF morph "
                                "target, Blender shape key).");
  cls.def(py::init([](std::string name, py::object displacements) {
            PyMorphTarget t;
            t.name = std::move(name);
            setIfGiven(t, &PyMorphTarget::displacements, displacements, "MorphTarget.displacements",
                       rows(3));
            return t;
          }),
          "name"_a = "", "displacements"_a = py::none());
  nameProperty(cls, "Target name.");
  storedProperty(cls, "displacements", &PyMorphTarget::displacements, rows(3),
                 "(N, 3) float64 array: one displacement per mesh vertex.");
  cls.def("__repr__", [](const PyMorphTarget& t) {
    return "<MorphTarget " + quoted(t.name) + ": " + std::to_string(t.displacements.shape(0)) +
           " displacements>";
  });
}

void bindMesh(py::module_& m) {
  py::class_<PyMesh> cls(m, "IndexedFaceSet", R"doc(
A VRML IndexedFaceSet: vertex positions and polygons given as vertex indices, each face ended
by -1. The numeric fields are numpy arrays owned by the mesh; assigning copies (and converts
any numeric dtype), reading returns the stored array, so in-place edits change the mesh.
)doc");
  cls.def(py::init([](std::string name, py::object coord, py::object coordIndex, py::object normal,
                      py::object texCoord, py::object texCoordIndex, py::object morphTargets,
                      py::object weights, py::object sourceIndex) {
            PyMesh mesh;
            mesh.name = std::move(name);
            setIfGiven(mesh, &PyMesh::coord, coord, "IndexedFaceSet.coord", rows(3));
            setIfGiven(mesh, &PyMesh::coordIndex, coordIndex, "IndexedFaceSet.coord_index",
                       checkedIndices);
            setIfGiven(mesh, &PyMesh::normal, normal, "IndexedFaceSet.normal", rows(3));
            setIfGiven(mesh, &PyMesh::texCoord, texCoord, "IndexedFaceSet.tex_coord", rows(2));
            setIfGiven(mesh, &PyMesh::texCoordIndex, texCoordIndex,
                       "IndexedFaceSet.tex_coord_index", checkedIndices);
            setIfGiven(mesh, &PyMesh::morphTargets, morphTargets, "IndexedFaceSet.morph_targets",
                       objects<PyMorphTarget>("MorphTarget"));
            setIfGiven(mesh, &PyMesh::weights, weights, "IndexedFaceSet.weights", checkedVector);
            setIfGiven(mesh, &PyMesh::sourceIndex, sourceIndex, "IndexedFaceSet.source_index",
                       checkedIndices);
            return mesh;
          }),
          "name"_a = "", "coord"_a = py::none(), "coord_index"_a = py::none(), py::kw_only(),
          "normal"_a = py::none(), "tex_coord"_a = py::none(), "tex_coord_index"_a = py::none(),
          "morph_targets"_a = py::none(), "weights"_a = py::none(), "source_index"_a = py::none());
  nameProperty(cls, "Mesh name.");
  storedProperty(cls, "coord", &PyMesh::coord, rows(3), "(N, 3) float64 vertex positions.");
  storedProperty(cls, "coord_index", &PyMesh::coordIndex, checkedIndices,
                 "1-D int32 array of polygon corners, -1 after each face.");
  storedProperty(cls, "normal", &PyMesh::normal, rows(3),
                 "(N, 3) float64 per-vertex normals, or shape (0, 3).");
  storedProperty(cls, "tex_coord", &PyMesh::texCoord, rows(2),
                 "(M, 2) float64 texture coordinates, or shape (0, 2).");
  storedProperty(cls, "tex_coord_index", &PyMesh::texCoordIndex, checkedIndices,
                 "1-D int32 array laid out like coord_index; empty: tex_coord is per vertex.");
  storedProperty(cls, "morph_targets", &PyMesh::morphTargets, objects<PyMorphTarget>("MorphTarget"),
                 "list of MorphTarget (the list itself: append/remove change the mesh).");
  storedProperty(cls, "weights", &PyMesh::weights, checkedVector,
                 "1-D float64 default morph weights: empty or one per morph target.");
  storedProperty(cls, "source_index", &PyMesh::sourceIndex, checkedIndices,
                 "1-D int32: each vertex's 0-based index in the file it was cut from (OBJ "
                 "groups), or empty.");
  cls.def_property_readonly(
      "vertex_count", [](const PyMesh& mesh) { return mesh.coord.shape(0); },
      "Number of vertices (rows of coord).");
  cls.def_property_readonly(
      "face_count",
      [](const PyMesh& mesh) {
        IndexedFaceSet core;
        core.coordIndex = indicesToCore(mesh.coordIndex, "IndexedFaceSet.coord_index");
        return core.faceCount();
      },
      "Number of faces (the -1 entries of coord_index).");
  cls.def(
      "triangles",
      [](const PyMesh& mesh) {
        IndexedFaceSet core;
        core.coordIndex = indicesToCore(mesh.coordIndex, "IndexedFaceSet.coord_index");
        const std::vector<int> triangles = core.triangles();
        const auto count = static_cast<py::ssize_t>(triangles.size() / 3);
        py::array_t<int32_t> out(std::vector<py::ssize_t>{count, 3});
        std::copy(triangles.begin(), triangles.end(), out.mutable_data());
        return out;
      },
      "The faces fan-triangulated: a (T, 3) int32 array of vertex indices.");
  cls.def("__repr__", [](const PyMesh& mesh) {
    return "<IndexedFaceSet " + quoted(mesh.name) + ": " + std::to_string(mesh.coord.shape(0)) +
           " vertices, " + std::to_string(mesh.morphTargets.size()) + " morph targets>";
  });
}

void bindTransform(py::module_& m) {
  py::class_<PyTransform> cls(m, "Transform", R"doc(
A VRML Transform node: a child's point p maps to T * C * R * S * -C * p. children and meshes
are lists of indices into FaceModel.transforms and FaceModel.meshes.
)doc");
  cls.def(py::init([](std::string name, py::object translation, py::object rotation,
                      py::object scale, py::object center, py::object children, py::object meshes) {
            PyTransform t;
            t.name = std::move(name);
            setIfGiven(t, &PyTransform::translation, translation, "Transform.translation",
                       fixed(3));
            setIfGiven(t, &PyTransform::rotation, rotation, "Transform.rotation", fixed(4));
            setIfGiven(t, &PyTransform::scale, scale, "Transform.scale", fixed(3));
            setIfGiven(t, &PyTransform::center, center, "Transform.center", fixed(3));
            setIfGiven(t, &PyTransform::children, children, "Transform.children", checkedIntList);
            setIfGiven(t, &PyTransform::meshes, meshes, "Transform.meshes", checkedIntList);
            return t;
          }),
          "name"_a = "", py::kw_only(), "translation"_a = py::none(), "rotation"_a = py::none(),
          "scale"_a = py::none(), "center"_a = py::none(), "children"_a = py::none(),
          "meshes"_a = py::none());
  nameProperty(cls, "Transform name.");
  storedProperty(cls, "translation", &PyTransform::translation, fixed(3),
                 "(3,) float64 translation.");
  storedProperty(cls, "rotation", &PyTransform::rotation, fixed(4),
                 "(4,) float64 unit quaternion in (x, y, z, w) order, as in glTF.");
  storedProperty(cls, "scale", &PyTransform::scale, fixed(3), "(3,) float64 scale.");
  storedProperty(cls, "center", &PyTransform::center, fixed(3),
                 "(3,) float64 centre of rotation and scale.");
  storedProperty(cls, "children", &PyTransform::children, checkedIntList,
                 "list of int: child transforms (indices into FaceModel.transforms).");
  storedProperty(cls, "meshes", &PyTransform::meshes, checkedIntList,
                 "list of int: meshes held (indices into FaceModel.meshes).");
  cls.def(
      "local_matrix",
      [](const PyTransform& t) { return matrix4(toCore(t, "Transform").localMatrix()); },
      "The 4x4 float64 matrix T * C * R * S * -C.");
  cls.def("__repr__", [](const PyTransform& t) {
    return "<Transform " + quoted(t.name) + ": " + std::to_string(t.children.size()) +
           " children, " + std::to_string(t.meshes.size()) + " meshes>";
  });
}

void bindFeaturePointBinding(py::module_& m) {
  py::class_<PyFeaturePointBinding> cls(m, "FeaturePointBinding", R"doc(
Where a feature point is: vertex `vertex` of mesh `mesh`, or (mesh == -1) the free model-space
coordinate `position`.
)doc");
  cls.def(py::init([](py::handle mesh, py::handle vertex, py::object position) {
            PyFeaturePointBinding b;
            b.mesh = checkedInt(mesh, "FeaturePointBinding.mesh");
            b.vertex = checkedInt(vertex, "FeaturePointBinding.vertex");
            setIfGiven(b, &PyFeaturePointBinding::position, position,
                       "FeaturePointBinding.position", fixed(3));
            return b;
          }),
          "mesh"_a = -1, "vertex"_a = -1, "position"_a = py::none());
  cls.def_readwrite("mesh", &PyFeaturePointBinding::mesh,
                    "Index into FaceModel.meshes, -1 for a free coordinate.");
  cls.def_readwrite("vertex", &PyFeaturePointBinding::vertex, "Vertex of that mesh.");
  storedProperty(cls, "position", &PyFeaturePointBinding::position, fixed(3),
                 "(3,) float64 model-space position, used when mesh == -1.");
  cls.def("__repr__", [](const PyFeaturePointBinding& b) -> std::string {
    if (b.mesh < 0) {
      return "<FeaturePointBinding position=" + std::string(py::repr(b.position.attr("tolist")())) +
             ">";
    }
    return "<FeaturePointBinding mesh=" + std::to_string(b.mesh) +
           " vertex=" + std::to_string(b.vertex) + ">";
  });
}

void bindAnimation(py::module_& m) {
  py::class_<PyMorphWeightChannel> channel(m, "MorphWeightChannel",
                                           "glTF-style keyframes of the morph weights of one "
                                           "mesh.");
  py::enum_<MorphWeightChannel::Interpolation>(channel, "Interpolation",
                                               "glTF sampler interpolation.")
      .value("LINEAR", MorphWeightChannel::Interpolation::Linear)
      .value("STEP", MorphWeightChannel::Interpolation::Step)
      .value("CUBICSPLINE", MorphWeightChannel::Interpolation::CubicSpline);
  channel.def(py::init([](py::handle mesh, MorphWeightChannel::Interpolation interpolation,
                          py::object times, py::object weights) {
                PyMorphWeightChannel c;
                c.mesh = checkedInt(mesh, "MorphWeightChannel.mesh");
                c.interpolation = interpolation;
                setIfGiven(c, &PyMorphWeightChannel::times, times, "MorphWeightChannel.times",
                           checkedVector);
                setIfGiven(c, &PyMorphWeightChannel::weights, weights, "MorphWeightChannel.weights",
                           checkedVector);
                return c;
              }),
              "mesh"_a = 0, "interpolation"_a = MorphWeightChannel::Interpolation::Linear,
              "times"_a = py::none(), "weights"_a = py::none());
  channel.def_readwrite("mesh", &PyMorphWeightChannel::mesh, "Index into FaceModel.meshes.");
  channel.def_readwrite("interpolation", &PyMorphWeightChannel::interpolation,
                        "MorphWeightChannel.Interpolation.");
  storedProperty(channel, "times", &PyMorphWeightChannel::times, checkedVector,
                 "1-D float64 key times in seconds, increasing.");
  storedProperty(channel, "weights", &PyMorphWeightChannel::weights, checkedVector,
                 "1-D float64: len(times) * morph target count values (x3 for CUBICSPLINE: "
                 "in-tangent, value, out-tangent).");
  channel.def("__repr__", [](const PyMorphWeightChannel& c) {
    return "<MorphWeightChannel mesh=" + std::to_string(c.mesh) + ": " +
           std::to_string(c.times.shape(0)) + " keys>";
  });

  py::class_<PyTransformChannel> transformChannel(
      m, "TransformChannel",
      "glTF-style keyframes of one Transform's translation, rotation or scale.");
  py::enum_<TransformChannel::Path>(transformChannel, "Path", "The animated field.")
      .value("TRANSLATION", TransformChannel::Path::Translation)
      .value("ROTATION", TransformChannel::Path::Rotation)
      .value("SCALE", TransformChannel::Path::Scale);
  transformChannel.def(
      py::init([](py::handle transform, TransformChannel::Path path,
                  MorphWeightChannel::Interpolation interpolation, py::object times,
                  py::object values) {
        PyTransformChannel c;
        c.transform = checkedInt(transform, "TransformChannel.transform");
        c.path = path;
        c.interpolation = interpolation;
        setIfGiven(c, &PyTransformChannel::times, times, "TransformChannel.times", checkedVector);
        setIfGiven(c, &PyTransformChannel::values, values, "TransformChannel.values",
                   checkedVector);
        return c;
      }),
      "transform"_a = 0, "path"_a = TransformChannel::Path::Rotation,
      "interpolation"_a = MorphWeightChannel::Interpolation::Linear, "times"_a = py::none(),
      "values"_a = py::none());
  transformChannel.def_readwrite("transform", &PyTransformChannel::transform,
                                 "Index into FaceModel.transforms.");
  transformChannel.def_readwrite("path", &PyTransformChannel::path, "TransformChannel.Path.");
  transformChannel.def_readwrite("interpolation", &PyTransformChannel::interpolation,
                                 "MorphWeightChannel.Interpolation.");
  storedProperty(transformChannel, "times", &PyTransformChannel::times, checkedVector,
                 "1-D float64 key times in seconds, increasing.");
  storedProperty(transformChannel, "values", &PyTransformChannel::values, checkedVector,
                 "1-D float64: per key x y z (translation, scale) or the quaternion x y z w "
                 "(rotation); x3 for CUBICSPLINE (in-tangent, value, out-tangent).");
  transformChannel.def("__repr__", [](const PyTransformChannel& c) {
    return "<TransformChannel transform=" + std::to_string(c.transform) + ": " +
           std::to_string(c.times.shape(0)) + " keys>";
  });

  py::class_<PyMorphWeightAnimation> animation(
      m, "MorphWeightAnimation",
      "A named animation of morph weights and Transform fields (glTF's animation).");
  animation.def(py::init([](std::string name, py::object channels, py::object transformChannels) {
                  PyMorphWeightAnimation a;
                  a.name = std::move(name);
                  setIfGiven(a, &PyMorphWeightAnimation::channels, channels,
                             "MorphWeightAnimation.channels",
                             objects<PyMorphWeightChannel>("MorphWeightChannel"));
                  setIfGiven(a, &PyMorphWeightAnimation::transformChannels, transformChannels,
                             "MorphWeightAnimation.transform_channels",
                             objects<PyTransformChannel>("TransformChannel"));
                  return a;
                }),
                "name"_a = "", "channels"_a = py::none(), "transform_channels"_a = py::none());
  nameProperty(animation, "Animation name.");
  storedProperty(animation, "channels", &PyMorphWeightAnimation::channels,
                 objects<PyMorphWeightChannel>("MorphWeightChannel"),
                 "list of MorphWeightChannel, one per animated mesh.");
  storedProperty(animation, "transform_channels", &PyMorphWeightAnimation::transformChannels,
                 objects<PyTransformChannel>("TransformChannel"),
                 "list of TransformChannel. In the shape-key grammar's name (docs/fat.md) an "
                 "animation is a pose: generate_face takes the values of its last keys.");
  animation.def("__repr__", [](const PyMorphWeightAnimation& a) {
    return "<MorphWeightAnimation " + quoted(a.name) + ": " + std::to_string(a.channels.size()) +
           " channels, " + std::to_string(a.transformChannels.size()) + " transform channels>";
  });
}

void bindFaceModel(py::module_& m) {
  py::class_<PyFaceModel> cls(m, "FaceModel", R"doc(
The face model: a scene graph of named Transforms holding named IndexedFaceSet meshes, plus the
feature-point bindings of the MPEG-4 FDP and morph-weight animations.

meshes, transforms, roots and animations are plain Python lists and feature_points a dict
(id such as "2.1" -> FeaturePointBinding), owned by the model: change them in place
(model.meshes[0].coord[:] *= 2, model.meshes.append(mesh)) or assign new ones. Objects are
shared, not copied, so a mesh appended to two models is the same mesh in both. Checks happen
in validate() and in every function that hands the model to the C++ core.
)doc");
  cls.def(py::init([](py::object meshes, py::object transforms, py::object roots,
                      py::object featurePoints, py::object animations) {
            PyFaceModel model;
            setIfGiven(model, &PyFaceModel::meshes, meshes, "FaceModel.meshes",
                       objects<PyMesh>("IndexedFaceSet"));
            setIfGiven(model, &PyFaceModel::transforms, transforms, "FaceModel.transforms",
                       objects<PyTransform>("Transform"));
            setIfGiven(model, &PyFaceModel::roots, roots, "FaceModel.roots", checkedIntList);
            setIfGiven(model, &PyFaceModel::featurePoints, featurePoints,
                       "FaceModel.feature_points", checkedFeaturePoints);
            setIfGiven(model, &PyFaceModel::animations, animations, "FaceModel.animations",
                       objects<PyMorphWeightAnimation>("MorphWeightAnimation"));
            return model;
          }),
          py::kw_only(), "meshes"_a = py::none(), "transforms"_a = py::none(),
          "roots"_a = py::none(), "feature_points"_a = py::none(), "animations"_a = py::none());
  storedProperty(cls, "meshes", &PyFaceModel::meshes, objects<PyMesh>("IndexedFaceSet"),
                 "list of IndexedFaceSet.");
  storedProperty(cls, "transforms", &PyFaceModel::transforms, objects<PyTransform>("Transform"),
                 "list of Transform.");
  storedProperty(cls, "roots", &PyFaceModel::roots, checkedIntList,
                 "list of int: the top-level transforms (the faceSceneGraph).");
  storedProperty(cls, "feature_points", &PyFaceModel::featurePoints, checkedFeaturePoints,
                 "dict of feature point id (\"2.1\") -> FeaturePointBinding.");
  storedProperty(cls, "animations", &PyFaceModel::animations,
                 objects<PyMorphWeightAnimation>("MorphWeightAnimation"),
                 "list of MorphWeightAnimation.");
  cls.def(
      "find_mesh",
      [](const PyFaceModel& model, const std::string& name) {
        (void)toCore(model, Depth::Structure);  // type-checks the lists
        return findByName(model.meshes, name, true);
      },
      "name"_a, "Index of the first mesh called `name`, or None.");
  cls.def(
      "find_transform",
      [](const PyFaceModel& model, const std::string& name) {
        (void)toCore(model, Depth::Structure);
        return findByName(model.transforms, name, false);
      },
      "name"_a, "Index of the first transform called `name`, or None.");
  cls.def(
      "feature_point_position",
      [](const PyFaceModel& model, const std::string& id) -> py::object {
        const std::optional<Eigen::Vector3d> p =
            toCore(model, Depth::Geometry).featurePointPosition(id);
        if (!p) return py::none();
        py::array_t<double> out(3);
        std::copy_n(p->data(), 3, out.mutable_data());
        return out;
      },
      "id"_a,
      "Model-space position of a bound feature point as a (3,) array; None if `id` is not "
      "bound (or bound to a vertex that does not exist).");
  cls.def(
      "mesh_world_matrices",
      [](const PyFaceModel& model) {
        const std::vector<Eigen::Affine3d> matrices =
            toCore(model, Depth::Structure).meshWorldMatrices();
        const auto count = static_cast<py::ssize_t>(matrices.size());
        py::array_t<double> out(std::vector<py::ssize_t>{count, 4, 4});
        auto view = out.mutable_unchecked<3>();
        for (py::ssize_t i = 0; i < count; ++i) {
          for (py::ssize_t r = 0; r < 4; ++r) {
            for (py::ssize_t c = 0; c < 4; ++c) {
              view(i, r, c) = matrices[static_cast<size_t>(i)].matrix()(r, c);
            }
          }
        }
        return out;
      },
      "Model-space matrix of each mesh as an (M, 4, 4) array: the product of the transforms "
      "above its first use (identity for a mesh no transform holds).");
  cls.def(
      "add_mesh_with_transform",
      [](PyFaceModel& model, py::handle mesh) {
        if (!py::isinstance<PyMesh>(mesh)) {
          throw py::type_error("add_mesh_with_transform: expected IndexedFaceSet, got " +
                               typeName(mesh));
        }
        const auto meshIndex = static_cast<int>(model.meshes.size());
        PyTransform t;
        t.name = mesh.cast<const PyMesh&>().name;
        t.meshes.append(meshIndex);
        model.meshes.append(mesh);
        model.roots.append(static_cast<int>(model.transforms.size()));
        model.transforms.append(py::cast(std::move(t)));
        return meshIndex;
      },
      "mesh"_a,
      "Appends `mesh` (the object itself, not a copy) under a new root Transform of the same "
      "name; returns the mesh index.");
  cls.def(
      "validate", [](const PyFaceModel& model) { toCore(model).validate(); },
      R"doc(Checks every reference of the model and raises mpeg4face.Error naming the first
broken one in .field (index out of range, face index outside the mesh, morph target of the
wrong size, transform cycle). Raises TypeError or ValueError for a list item of the wrong type
or an array of the wrong shape.)doc");
  cls.def("__repr__", [](const PyFaceModel& model) {
    return "<FaceModel: " + std::to_string(model.meshes.size()) + " meshes, " +
           std::to_string(model.transforms.size()) + " transforms, " +
           std::to_string(model.featurePoints.size()) + " feature points, " +
           std::to_string(model.animations.size()) + " animations>";
  });
}

Eigen::Vector3d vector3(py::handle value, const char* field) {
  const py::array_t<double> a = checkedFixed(value, field, 3);
  return {a.at(0), a.at(1), a.at(2)};
}

void bindCut(py::module_& m) {
  m.def(
      "cut_face_model",
      [](const PyFaceModel& model, py::handle point, py::handle normal,
         std::optional<std::vector<std::string>> meshes) {
        const FaceModel core = toCore(model);
        const Eigen::Vector3d p = vector3(point, "point");
        const Eigen::Vector3d n = vector3(normal, "normal");
        std::function<bool(const IndexedFaceSet&)> keep;
        if (meshes) {
          keep = [names = *meshes](const IndexedFaceSet& mesh) {
            return std::find(names.begin(), names.end(), mesh.name) != names.end();
          };
        }
        FaceModel cut;
        {
          py::gil_scoped_release release;
          cut = cutFaceModel(core, p, n, keep);
        }
        return py::cast(fromCore(std::move(cut)));
      },
      "model"_a, "point"_a, "normal"_a, "meshes"_a = py::none(),
      R"doc(The model cut by the plane through `point` with `normal` (model space): of each mesh,
the faces whose corners all lie on the side `normal` points to, and the vertices they use, in
their old order with their morph targets and source_index. `meshes` names the meshes to keep
(all if None); the others, and meshes left without faces, are removed. Feature points on kept
vertices are renumbered, those on removed ones dropped, free coordinates kept. Returns a new
FaceModel; raises mpeg4face.Error for a model that fails validate() or a zero normal.)doc");
}

}  // namespace

void bindSnap(py::module_& m) {
  m.def(
      "snap_feature_points",
      [](const PyFaceModel& model, double tolerance) {
        FaceModel core = toCore(model);
        FeaturePointSnap snap;
        {
          py::gil_scoped_release release;
          snap = snapFeaturePointsToVertices(core, tolerance);
        }
        return py::make_tuple(fromCore(std::move(core)), snap.notes, snap.unbound);
      },
      "model"_a, "tolerance"_a = kFeaturePointSnapTolerance,
      R"doc(Free feature points (FeaturePointBinding with a position, mesh -1) bound to the vertex
they lie on, as the ARKit keys and the clone's lips need: each to the nearest corner of the
closest triangle of the closest mesh, if that is within `tolerance` of the face's size (the
diagonal of the box around the feature points). 7.1 and 7.2 stay free. Returns (model, notes,
unbound): a new FaceModel, a line per point bound and a line per free point left free.)doc");
}

// A core resampling as a Python function: the model in, a new model out, the GIL released.
template <typename Argument>
auto resampling(FaceModel (*resample)(const FaceModel&, Argument)) {
  return [resample](const PyFaceModel& model, Argument argument) {
    const FaceModel core = toCore(model);
    FaceModel out;
    {
      py::gil_scoped_release release;
      out = resample(core, argument);
    }
    return fromCore(std::move(out));
  };
}

void bindResample(py::module_& m) {
  m.def("decimate_face_model", resampling(&decimateFaceModel), "model"_a, "vertex_fraction"_a,
        R"doc(Each mesh decimated (OpenMesh quadric edge collapse) to about vertex_fraction of its
vertices, feature-point vertices locked; a neutral (morph targets dropped). Raises
mpeg4face.Error unless 0 < vertex_fraction <= 1 (docs/mesh-resample.md).)doc");
  m.def("subdivide_face_model", resampling(&subdivideFaceModel), "model"_a, "iterations"_a,
        R"doc(Each mesh subdivided `iterations` times (modified butterfly: the old vertices keep
their places and numbers, about 4x the vertices per round); a neutral. Raises mpeg4face.Error
unless 0 <= iterations <= 4 (docs/mesh-resample.md).)doc");
}

void bindLandmarks(py::module_& m) {
  m.def(
      "find_feature_points",
      [](const PyFaceModel& target, const PyFaceModel& templateHead, const py::dict& pins,
         const py::object& progress) {
        const FaceModel coreTarget = toCore(target), coreTemplate = toCore(templateHead);
        LandmarkOptions options;
        for (const auto& [key, value] : pins) {
          const std::string id = py::cast<std::string>(key);
          if (!py::isinstance<PyFeaturePointBinding>(value)) {
            throw py::type_error("pins['" + id + "']: expected FeaturePointBinding");
          }
          const auto& pin = py::cast<const PyFeaturePointBinding&>(value);
          const auto at = pin.position.unchecked<1>();  // the setter keeps it (3,)
          FeaturePointBinding& core = options.pins[id];
          core.mesh = pin.mesh;
          core.vertex = pin.vertex;
          core.position = {at(0), at(1), at(2)};
        }
        if (!progress.is_none()) {
          options.progress = [&progress](double fraction, std::string_view step) {
            py::gil_scoped_acquire acquire;
            progress(fraction, std::string(step));
          };
        }
        LandmarkResult found;
        {
          py::gil_scoped_release release;
          found = findFeaturePoints(coreTarget, coreTemplate, options);
        }
        py::dict points;
        for (const auto& [id, p] : found.points) {
          points[py::str(id)] = py::make_tuple(fromCore(p.binding), p.confidence, p.rule);
        }
        py::dict info;
        info["face_mesh"] = found.faceMesh;
        info["scale"] = found.scale;
        // Eigen is column-major: its transpose's storage is the row-major matrix numpy reads.
        const Eigen::Matrix4d rowMajor = found.alignment.matrix().transpose();
        info["alignment"] = py::array_t<double>({4, 4}, rowMajor.data());
        info["alignment_residual"] = found.alignmentResidual;
        info["fit_residual"] = found.fitResidual;
        info["not_placed"] = found.notPlaced;
        return py::make_tuple(points, info);
      },
      "target"_a, "template"_a, "pins"_a = py::dict(), "progress"_a = py::none(),
      R"doc(The MPEG-4 feature points of `target` found by registering `template` (a head with
feature points, in MPEG-4 axes) onto it: similarity alignment whatever the target's axes,
units and position, non-rigid ICP, each point carried onto the target and refined by its rule
(docs/landmarks.md). `pins` (id -> FeaturePointBinding of the target) are kept exactly and
constrain the fit; `progress(fraction, step)` is called along the way. Returns (points, info):
points maps each id to (FeaturePointBinding, confidence 0..1, rule); info has face_mesh, scale,
alignment (4x4, template to target), alignment_residual, fit_residual and not_placed (why
template points were not placed). Raises mpeg4face.Error for a target without faces, a
template without feature points, and a target with no face ("no face found").)doc");
}

void bindModel(py::module_& m) {
  bindMorphTarget(m);
  bindMesh(m);
  bindTransform(m);
  bindFeaturePointBinding(m);
  bindAnimation(m);
  bindFaceModel(m);
  bindCut(m);
  bindSnap(m);
  bindLandmarks(m);
  bindResample(m);
}

}  // namespace mpeg4face::python
