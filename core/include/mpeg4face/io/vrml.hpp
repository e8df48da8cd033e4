// SPDX-License-Identifier: GPL-3.0-or-later
// An MPEG-4 face as VRML97 text: the BIFS nodes Face, FDP, FaceDefTables, FaceDefMesh and
// FaceDefTransform, declared as PROTOs so that any VRML97 reader accepts the file, around the
// neutral scene graph of Transforms and IndexedFaceSets. docs/vrml.md describes the layout.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mpeg4face/fat/tables.hpp"

namespace mpeg4face {

// The VRML97 file for `face` (#VRML V2.0 utf8): PROTOs of the MPEG-4 face nodes, then one Face
// whose FDP holds featurePointsCoord (the 84 standard feature points in group/index order,
// 0 0 0 for an unbound one), faceSceneGraph (every Transform and IndexedFaceSet, DEF'd by
// name) and faceDefTables (FaceDefMesh / FaceDefTransform referring to them by USE), then a
// WorldInfo titled "mpeg4face feature points" saying which points are mesh vertices or
// unbound. Names become VRML identifiers reversibly ('%XX' escapes, '%_N' to make a repeated
// name unique). Meshes are placed among the Transforms so that they read back in their
// order (docs/vrml.md, "Scene graph"). Numbers are the shortest text that reads back to the same
// double. Rotations are written as axis-angle: a quaternion comes back within 1e-15 rad, or as -q.
// Morph targets, weights, animations and sourceIndex are not part of an MPEG-4 face and are
// not written. Throws mpeg4face::Error naming the field for a model that fails validate(),
// a table that refers to a missing mesh, vertex or transform, bad interval borders, a
// displacement count that does not match, a transform not reachable from the roots, an id
// that is not a feature point, or a number that is not finite.
std::string vrmlText(const MpegFace& face);
// vrmlText written atomically (see writeFileAtomically).
void writeVrml(const MpegFace& face, const std::filesystem::path& path);

// Reads a VRML97 file: ours, or an ordinary scene. Comments, commas, DEF/USE, PROTO,
// EXTERNPROTO and ROUTE statements (skipped), Script interface declarations, MF fields with
// or without brackets. With a Face node the face is its FDP; without one, the top-level
// Transforms, Groups, Anchors, Collisions and Shapes are the faceSceneGraph. Shapes whose
// geometry is an IndexedFaceSet become meshes (a USE'd IndexedFaceSet is one mesh; a shared
// Coordinate is copied into each); other nodes are parsed and skipped. Transforms are
// numbered depth-first, meshes in the order they first appear. Throws mpeg4face::Error
// naming the file, line and field (e.g. "Transform.translation") for anything malformed, an
// unknown field of a node it reads, a coordIndex out of range, a Transform used twice,
// a scaleOrientation with non-uniform scale, nesting deeper than 256 nodes, or USE'd
// Coordinates whose further copies would hold more than 2^24 numbers.
MpegFace readVrml(const std::filesystem::path& path);
// The same from text in memory; `fileName` is used in messages.
MpegFace parseVrml(std::string_view text, const std::string& fileName);

}  // namespace mpeg4face
