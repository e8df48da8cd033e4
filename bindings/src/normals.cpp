// SPDX-License-Identifier: GPL-3.0-or-later
// vertex_normals: the core's smooth vertex normals, for the Blender add-on's live preview.
#include <algorithm>
#include <vector>

#include "bindings.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/model/vertex_normals.hpp"

namespace mpeg4face::python {

using namespace pybind11::literals;

void bindNormals(py::module_& m) {
  using Coords = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using Indices = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  m.def(
      "vertex_normals",
      [](const Coords& coord, const Indices& triangles) {
        if (coord.ndim() != 2 || coord.shape(1) != 3) {
          throw Error({}, 0, "coord", "expected (N, 3)");
        }
        if (triangles.ndim() != 2 || triangles.shape(1) != 3) {
          throw Error({}, 0, "triangles", "expected (T, 3)");
        }
        const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> c(
            coord.data(), coord.shape(0), 3);
        const Eigen::Map<const Triangles3i> t(triangles.data(), triangles.shape(0), 3);
        Normals3f normals;
        {
          py::gil_scoped_release release;
          normals = vertexNormals(c, t);
        }
        py::array_t<float> out(std::vector<py::ssize_t>{normals.rows(), 3});
        std::copy(normals.data(), normals.data() + normals.size(), out.mutable_data());
        return out;
      },
      "coord"_a, "triangles"_a,
      "Area-weighted unit vertex normals (N, 3) float32 of triangles (T, 3) over coord (N, 3); "
      "(0, 0, 1) for a vertex on no triangle.");
}

}  // namespace mpeg4face::python
