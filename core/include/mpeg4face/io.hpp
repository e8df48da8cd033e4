// SPDX-License-Identifier: GPL-3.0-or-later
// Files: faces, tables and streams read and written, with errors that name the file and the line
// or field at fault, and writes that leave nothing half-written.
//
//   io/files.hpp              the leaf every reader and writer uses: readFile, writeFileAtomically
//   io/read_any.hpp           a model or a FAP stream in any format, by extension
//   io/gltf.hpp               glTF 2.0 faces (tinygltf)
//   io/fat_gltf.hpp           an MpegFace and baked FAP streams as glTF
//   io/vrml.hpp               an MpegFace as VRML97 (BIFS Face, FDP, FaceDefTables, FIT)
//   io/obj.hpp                Wavefront OBJ
//   io/wfm.hpp                CANDIDE-3 .wfm
//   io/feature_point_csv.hpp  feature-point bindings as CSV
//   io/fap_file.hpp           the ASCII .fap file
//   io/livelink.hpp           Live Link Face captures (CSV)
#pragma once

#include "mpeg4face/io/fap_file.hpp"           // IWYU pragma: export
#include "mpeg4face/io/fat_gltf.hpp"           // IWYU pragma: export
#include "mpeg4face/io/feature_point_csv.hpp"  // IWYU pragma: export
#include "mpeg4face/io/files.hpp"              // IWYU pragma: export
#include "mpeg4face/io/gltf.hpp"               // IWYU pragma: export
#include "mpeg4face/io/livelink.hpp"           // IWYU pragma: export
#include "mpeg4face/io/obj.hpp"                // IWYU pragma: export
#include "mpeg4face/io/read_any.hpp"           // IWYU pragma: export
#include "mpeg4face/io/vrml.hpp"               // IWYU pragma: export
#include "mpeg4face/io/wfm.hpp"                // IWYU pragma: export
