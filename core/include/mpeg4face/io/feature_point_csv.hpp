// SPDX-License-Identifier: GPL-3.0-or-later
// Feature-point bindings from CSV.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// Feature points from CSV. Rows `fp,vertex`, `fp,mesh,vertex` or `fp,x,y,z`; a first row
// of column names selects columns by name instead (`fp`/`mpeg4_fp`/`feature_point`,
// `vertex`/`*_vertex`, `mesh`, `x`, `y`, `z`; other columns are ignored). A vertex number
// without a mesh refers to the model's only mesh, or with several meshes to the vertex
// numbering of the file the model was read from (IndexedFaceSet::sourceIndex) or else
// to the meshes' vertices counted one after the other. Duplicate ids: the first row wins
// and a warning names the later line. Fields may be quoted as in RFC 4180 (with ',', '""'
// and line breaks inside); blank lines and lines starting with '#' are skipped. Throws
// mpeg4face::Error naming the line and column for an id not in spec's feature point table,
// an unknown mesh, a vertex out of range, a bad number, and for a file without any rows.
struct FeaturePointCsv {
  std::map<std::string, FeaturePointBinding> featurePoints;
  std::vector<std::string> warnings;
};
FeaturePointCsv readFeaturePointCsv(const std::filesystem::path& path, const FaceModel& model);
FeaturePointCsv parseFeaturePointCsv(std::string_view text, const std::string& fileName,
                                     const FaceModel& model);

}  // namespace mpeg4face
