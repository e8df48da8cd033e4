// SPDX-License-Identifier: GPL-3.0-or-later
// VRML97 reader: the fields of the nodes a face needs, read into their structs, and the
// checks that need a whole node.
#include <algorithm>

#include "io/vrml_reader.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::vrml_reader {

void Parser::initialize(Node& node) {
  const std::string_view type = node.type;
  if (type == "Coordinate" || type == "Normal") {
    node.data = PointsNode{3, {}};
  } else if (type == "TextureCoordinate") {
    node.data = PointsNode{2, {}};
  } else if (type == "IndexedFaceSet") {
    node.data = IndexedFaceSetNode{};
  } else if (type == "Shape") {
    node.data = ShapeNode{};
  } else if (type == "Transform" || type == "Group" || type == "Anchor" || type == "Collision") {
    GroupNode group;
    group.isTransform = type == "Transform";
    group.transform.name = nameFromDef(node.def);
    node.data = std::move(group);
  } else if (type == "Face") {
    node.data = FaceNode{};
  } else if (type == "FDP") {
    node.data = FdpNode{};
  } else if (type == "FaceDefTables") {
    node.data = FaceDefTablesNode{};
  } else if (type == "FaceDefMesh") {
    node.data = FaceDefMeshNode{};
  } else if (type == "FaceDefTransform") {
    node.data = FaceDefTransformNode{};
  } else if (type == "FIT") {
    node.data = FitNode{};
  } else if (type == "WorldInfo") {
    node.data = WorldInfoNode{};
  }
}

// Reads field `f` of a node we read; false if that node has no such field. Fields that
// do not matter for a face (appearance, colours, bounding boxes, ...) are skipped.
bool Parser::readField(Node& node, std::string_view f, const std::string& name) {
  if (auto* n = std::get_if<PointsNode>(&node.data)) {
    if (f != (node.type == "Normal" ? "vector" : "point")) return false;
    numbers(name, n->values, n->dimension);
  } else if (auto* ifs = std::get_if<IndexedFaceSetNode>(&node.data)) {
    if (f == "coord")
      ifs->coord = nodeStatement(name);
    else if (f == "normal")
      ifs->normal = nodeStatement(name);
    else if (f == "texCoord")
      ifs->texCoord = nodeStatement(name);
    else if (f == "coordIndex")
      ints(name, ifs->coordIndex);
    else if (f == "normalIndex")
      ints(name, ifs->normalIndex);
    else if (f == "texCoordIndex")
      ints(name, ifs->texCoordIndex);
    else if (f == "normalPerVertex")
      ifs->normalPerVertex = boolean(name);
    else if (f == "ccw")
      ifs->ccw = boolean(name);
    else if (f == "color" || f == "colorIndex" || f == "colorPerVertex" || f == "convex" ||
             f == "creaseAngle" || f == "solid")
      skipValue(name);
    else
      return false;
  } else if (auto* shape = std::get_if<ShapeNode>(&node.data)) {
    if (f == "geometry")
      shape->geometry = nodeStatement(name);
    else if (f == "appearance")
      skipValue(name);
    else
      return false;
  } else if (auto* group = std::get_if<GroupNode>(&node.data)) {
    return groupField(node, *group, f, name);
  } else if (auto* face = std::get_if<FaceNode>(&node.data)) {
    if (f == "fdp")
      face->fdp = nodeStatement(name);
    else if (f == "fit")
      face->fit = nodeStatement(name);
    else if (f == "fap" || f == "ttsSource" || f == "renderedFace")
      skipValue(name);
    else
      return false;
  } else if (auto* fit = std::get_if<FitNode>(&node.data)) {
    FitNodeFields& x = fit->fields;
    const std::pair<std::string_view, std::vector<int>*> intFields[]{
        {"FAPs", &x.FAPs},
        {"Graph", &x.Graph},
        {"numeratorExp", &x.numeratorExp},
        {"denominatorExp", &x.denominatorExp},
        {"numeratorImpulse", &x.numeratorImpulse},
        {"numeratorTerms", &x.numeratorTerms},
        {"denominatorTerms", &x.denominatorTerms}};
    for (const auto& [key, values] : intFields) {
      if (f == key) {
        ints(name, *values);
        return true;
      }
    }
    if (f == "numeratorCoefs")
      numbers(name, x.numeratorCoefs, 1);
    else if (f == "denominatorCoefs")
      numbers(name, x.denominatorCoefs, 1);
    else
      return false;
  } else if (auto* fdp = std::get_if<FdpNode>(&node.data)) {
    if (f == "featurePointsCoord")
      fdp->featurePointsCoord = nodeStatement(name);
    else if (f == "faceDefTables")
      nodes(name, fdp->faceDefTables);
    else if (f == "faceSceneGraph")
      nodes(name, fdp->faceSceneGraph);
    else if (f == "textureCoord" || f == "useOrthoTexture")
      skipValue(name);
    else
      return false;
  } else if (auto* tables = std::get_if<FaceDefTablesNode>(&node.data)) {
    if (f == "fapID")
      tables->fapID = int32(name);
    else if (f == "highLevelSelect")
      tables->highLevelSelect = int32(name);
    else if (f == "faceDefMesh")
      nodes(name, tables->faceDefMesh);
    else if (f == "faceDefTransform")
      nodes(name, tables->faceDefTransform);
    else
      return false;
  } else if (auto* mesh = std::get_if<FaceDefMeshNode>(&node.data)) {
    if (f == "faceSceneGraphNode") {
      mesh->target = nodeStatement(name);
    } else if (f == "intervalBorders") {
      ints(name, mesh->def.intervalBorders);
    } else if (f == "coordIndex") {
      ints(name, mesh->def.coordIndex);
    } else if (f == "displacements") {
      std::vector<double> values;
      numbers(name, values, 3);
      mesh->def.displacements =
          Eigen::Map<const Points3>(values.data(), static_cast<Eigen::Index>(values.size() / 3), 3);
    } else {
      return false;
    }
  } else if (auto* transform = std::get_if<FaceDefTransformNode>(&node.data)) {
    if (f == "faceSceneGraphNode")
      transform->target = nodeStatement(name);
    else if (f == "fieldId")
      transform->fieldId = int32(name);
    else if (f == "rotationDef")
      transform->def.rotationDef = vector<4>(name);
    else if (f == "scaleDef")
      transform->def.scaleDef = vector<3>(name);
    else if (f == "translationDef")
      transform->def.translationDef = vector<3>(name);
    else
      return false;
  } else if (auto* info = std::get_if<WorldInfoNode>(&node.data)) {
    if (f == "title")
      info->title = string(name);
    else if (f == "info")
      info->info = strings(name);
    else
      return false;
  } else {
    return false;
  }
  return true;
}

bool Parser::groupField(const Node& node, GroupNode& group, std::string_view f,
                        const std::string& name) {
  if (f == "children") {
    nodes(name, group.children);
  } else if (f == "bboxCenter" || f == "bboxSize") {
    skipValue(name);
  } else if (group.isTransform) {
    Transform& t = group.transform;
    if (f == "translation")
      t.translation = vector<3>(name);
    else if (f == "scale")
      t.scale = vector<3>(name);
    else if (f == "center")
      t.center = vector<3>(name);
    else if (f == "rotation")
      t.rotation = rotation(name);
    else if (f == "scaleOrientation")
      group.scaleOrientation = rotation(name);
    else
      return false;
  } else if (node.type == "Anchor" && (f == "description" || f == "parameter" || f == "url")) {
    skipValue(name);
  } else if (node.type == "Collision" && (f == "collide" || f == "proxy")) {
    skipValue(name);
  } else {
    return false;
  }
  return true;
}

// Checks that need the whole node: its other fields and the nodes it refers to.
void Parser::finish(Node& node) {
  if (auto* ifs = std::get_if<IndexedFaceSetNode>(&node.data)) {
    finishIndexedFaceSet(node, *ifs);
  } else if (auto* group = std::get_if<GroupNode>(&node.data)) {
    const Eigen::Vector3d& s = group->transform.scale;
    const bool uniform = s.x() == s.y() && s.y() == s.z();
    if (!uniform && !group->scaleOrientation.vec().isZero(0)) {
      fail(node.lineOf("scaleOrientation"), node.field("scaleOrientation"),
           "a scaleOrientation with a non-uniform scale shears; the face model has no shear");
    }
  } else if (auto* fdm = std::get_if<FaceDefMeshNode>(&node.data)) {
    finishFaceDefMesh(node, *fdm);
  } else if (auto* fdt = std::get_if<FaceDefTransformNode>(&node.data)) {
    finishFaceDefTransform(node, *fdt);
  } else if (auto* tables = std::get_if<FaceDefTablesNode>(&node.data)) {
    finishFaceDefTables(node, *tables);
  } else if (auto* fdp = std::get_if<FdpNode>(&node.data)) {
    finishFdp(node, *fdp);
  } else if (auto* face = std::get_if<FaceNode>(&node.data)) {
    requireType(node, "fdp", face->fdp, "FDP");
    requireType(node, "fit", face->fit, "FIT");
  }
}

// The node in `slot` must be of type `type` (or absent).
void Parser::requireType(const Node& node, std::string_view slot, const NodePtr& value,
                         std::string_view type) {
  if (value && value->type != type) {
    fail(node.lineOf(slot), node.field(slot),
         std::string(type) + " expected, found " + std::string(value->type));
  }
}

void Parser::finishIndexedFaceSet(const Node& node, IndexedFaceSetNode& ifs) {
  requireType(node, "coord", ifs.coord, "Coordinate");
  requireType(node, "normal", ifs.normal, "Normal");
  requireType(node, "texCoord", ifs.texCoord, "TextureCoordinate");
  const Eigen::Index vertexCount = ifs.coord ? as<PointsNode>(ifs.coord)->count() : 0;
  for (int index : ifs.coordIndex) {
    if (index < -1 || index >= vertexCount) {
      fail(node.lineOf("coordIndex"), node.field("coordIndex"),
           "vertex " + std::to_string(index) + " out of range (the coord has " +
               std::to_string(vertexCount) + " points)");
    }
  }
  const std::size_t corners = ifs.coordIndex.size();
  // VRML97: an index list of texture coordinates or normals has at least the entries of
  // coordIndex, with -1 in the same places.
  const auto checkLayout = [&](std::vector<int>& indices, std::string_view slot,
                               Eigen::Index count) {
    if (indices.empty()) return;
    if (indices.size() < corners) {
      fail(node.lineOf(slot), node.field(slot),
           "has " + std::to_string(indices.size()) + " entries, coordIndex " +
               std::to_string(corners));
    }
    indices.resize(corners);
    for (std::size_t i = 0; i < corners; ++i) {
      if ((indices[i] == -1) != (ifs.coordIndex[i] == -1)) {
        fail(node.lineOf(slot), node.field(slot),
             "entry " + std::to_string(i) + " does not end a face where coordIndex does");
      }
      if (indices[i] < -1 || indices[i] >= count) {
        fail(node.lineOf(slot), node.field(slot),
             "index " + std::to_string(indices[i]) + " out of range (" + std::to_string(count) +
                 " values)");
      }
    }
  };
  const Eigen::Index texCount = ifs.texCoord ? as<PointsNode>(ifs.texCoord)->count() : 0;
  const Eigen::Index normalCount = ifs.normal ? as<PointsNode>(ifs.normal)->count() : 0;
  checkLayout(ifs.texCoordIndex, "texCoordIndex", texCount);
  if (ifs.normalPerVertex) checkLayout(ifs.normalIndex, "normalIndex", normalCount);
  if (ifs.texCoord && ifs.texCoordIndex.empty() && texCount != vertexCount) {
    // Texture coordinates indexed by coordIndex, but not one per vertex: say so explicitly.
    checkLayout(ifs.texCoordIndex = ifs.coordIndex, "texCoord", texCount);
  }
  // Without faces such texture coordinates belong to nothing.
  ifs.keepTexCoord = ifs.texCoord && (!ifs.texCoordIndex.empty() || texCount == vertexCount);
  // The face model holds one normal per vertex; other layouts are dropped (they can be
  // recomputed) rather than misassigned.
  ifs.keepNormals = ifs.normal && ifs.normalPerVertex && normalCount == vertexCount &&
                    (ifs.normalIndex.empty() || ifs.normalIndex == ifs.coordIndex);
  if (!ifs.ccw) {  // clockwise faces: reverse each so that the model's faces are CCW
    for (std::vector<int>* list : {&ifs.coordIndex, &ifs.texCoordIndex}) {
      if (list->empty()) continue;
      auto begin = list->begin();
      while (begin != list->end()) {
        auto end = std::find(begin, list->end(), -1);
        std::reverse(begin, end);
        begin = end == list->end() ? end : end + 1;
      }
    }
  }
}

void Parser::finishFaceDefMesh(const Node& node, FaceDefMeshNode& fdm) {
  const auto* target = as<IndexedFaceSetNode>(fdm.target);
  if (target == nullptr) {
    fail(node.lineOf("faceSceneGraphNode"), node.field("faceSceneGraphNode"),
         "an IndexedFaceSet expected, found " +
             (fdm.target ? std::string(fdm.target->type) : std::string("NULL")));
  }
  try {
    checkIntervalBorders(fdm.def.intervalBorders);
  } catch (const Error& e) {
    fail(node.lineOf("intervalBorders"), node.field("intervalBorders"), e.reason());
  }
  const Eigen::Index vertexCount = target->coord ? as<PointsNode>(target->coord)->count() : 0;
  for (int v : fdm.def.coordIndex) {
    if (v < 0 || v >= vertexCount) {
      fail(node.lineOf("coordIndex"), node.field("coordIndex"),
           "vertex " + std::to_string(v) + " out of range (the IndexedFaceSet has " +
               std::to_string(vertexCount) + " points)");
    }
  }
  const auto expected =
      static_cast<Eigen::Index>(fdm.def.coordIndex.size()) * fdm.def.intervalCount();
  if (fdm.def.displacements.rows() != expected) {
    fail(node.lineOf("displacements"), node.field("displacements"),
         std::to_string(fdm.def.displacements.rows()) + " displacements, expected " +
             std::to_string(expected) + " (one per coordIndex entry and interval)");
  }
}

void Parser::finishFaceDefTransform(const Node& node, FaceDefTransformNode& fdt) {
  const auto* target = as<GroupNode>(fdt.target);
  if (target == nullptr || !target->isTransform) {
    fail(node.lineOf("faceSceneGraphNode"), node.field("faceSceneGraphNode"),
         "a Transform expected, found " +
             (fdt.target ? std::string(fdt.target->type) : std::string("NULL")));
  }
  if (fdt.fieldId < 1 || fdt.fieldId > 3) {
    fail(node.lineOf("fieldId"), node.field("fieldId"),
         std::to_string(fdt.fieldId) + " is not 1 (rotation), 2 (scale) or 3 (translation)");
  }
  fdt.def.fieldId = static_cast<FaceDefTransform::Field>(fdt.fieldId);
  if (fdt.fieldId == 1 && fdt.def.rotationDef.head<3>().isZero(0)) {
    fail(node.lineOf("rotationDef"), node.field("rotationDef"), "the rotation axis is zero");
  }
}

void Parser::finishFaceDefTables(const Node& node, const FaceDefTablesNode& tables) {
  if (tables.fapID < 1 || tables.fapID > kFapCount) {
    fail(node.lineOf("fapID"), node.field("fapID"),
         std::to_string(tables.fapID) + " is not a FAP number (1..68)");
  }
  const int highest = tables.fapID == 1 ? static_cast<int>(visemeTable().size()) - 1
                                        : static_cast<int>(expressionTable().size()) - 1;
  if (tables.fapID <= 2 && (tables.highLevelSelect < 0 || tables.highLevelSelect > highest)) {
    fail(node.lineOf("highLevelSelect"), node.field("highLevelSelect"),
         std::to_string(tables.highLevelSelect) + " is not a" +
             (tables.fapID == 1 ? " viseme (0..14)" : "n expression (0..6)"));
  }
  for (const NodePtr& n : tables.faceDefMesh) {
    if (!as<FaceDefMeshNode>(n)) {
      fail(node.lineOf("faceDefMesh"), node.field("faceDefMesh"),
           "FaceDefMesh expected, found " + std::string(n->type));
    }
  }
  for (const NodePtr& n : tables.faceDefTransform) {
    if (!as<FaceDefTransformNode>(n)) {
      fail(node.lineOf("faceDefTransform"), node.field("faceDefTransform"),
           "FaceDefTransform expected, found " + std::string(n->type));
    }
  }
}

void Parser::finishFdp(const Node& node, const FdpNode& fdp) {
  requireType(node, "featurePointsCoord", fdp.featurePointsCoord, "Coordinate");
  if (fdp.featurePointsCoord) {
    const Eigen::Index count = as<PointsNode>(fdp.featurePointsCoord)->count();
    if (count != 0 && count != kFeaturePointCount) {
      fail(node.lineOf("featurePointsCoord"), node.field("featurePointsCoord"),
           std::to_string(count) + " points; expected the " + std::to_string(kFeaturePointCount) +
               " MPEG-4 feature points in order");
    }
  }
  for (const NodePtr& n : fdp.faceDefTables) {
    if (!as<FaceDefTablesNode>(n)) {
      fail(node.lineOf("faceDefTables"), node.field("faceDefTables"),
           "FaceDefTables expected, found " + std::string(n->type));
    }
  }
}

}  // namespace mpeg4face::vrml_reader
