// SPDX-License-Identifier: GPL-3.0-or-later
// mpeg4face: the command-line tool for batch users and the demo.
#include <array>
#include <cstdio>
#include <exception>
#include <string_view>

#include "commands.hpp"
#include "mpeg4face/error.hpp"

namespace {

using mpeg4face::cli::Command;

constexpr std::array kCommands{
    Command{"info", "describe a face model (meshes, feature points, FAPU) or a FAP stream",
            "mpeg4face info FILE [--feature-points CSV] [--json]\n"
            "  FILE    a face model: .gltf, .glb, .obj, .wfm or .wrl\n"
            "          or a stream: .fap (version, frames, rate, FAPs and their ranges) or\n"
            "          .fba (also the coding mode, fap_quant, intra planes, bits and bits/s)\n"
            "  --feature-points CSV  bind feature points from CSV (fp,vertex | fp,mesh,vertex |\n"
            "                        fp,x,y,z, or named columns); models only. A free x,y,z\n"
            "                        within 2% of the face's size of a surface is bound to\n"
            "                        its nearest vertex (a warning says which)\n"
            "  --json  print one JSON object (a model: keys meshes, feature_points, fapu,\n"
            "          warnings; a stream: format, frames, frame_rate, faps, coding, ...)\n",
            mpeg4face::cli::runInfo},
    Command{"psnr", "compare a decoded .fap stream with its original: PSNR, per-FAP errors",
            "mpeg4face psnr ORIGINAL.fap DECODED.fap [--quality robust|tao] [--face F.wrl]\n"
            "               [--json]\n"
            "  PSNR as Tao et al. (1999) eq. (8) defines it (docs/fap-format.md), the robust\n"
            "  PSNR (docs/rate-distortion.md), and each FAP's range, largest and RMS error;\n"
            "  both streams need the same frames (a decoded stream's empty frames before the\n"
            "  original's first frame number, the bitstream's frame 0, are skipped)\n"
            "  --quality Q  robust (default) or tao: the PSNR printed first\n"
            "  --face F     a face (.wrl with tables): also the motion error at its feature\n"
            "               points, RMS and largest, in % of ES0\n"
            "  --json  print one JSON object (keys psnr_db, psnr_faps, faps, extra_faps)\n",
            mpeg4face::cli::runPsnr},
    Command{"encode", "code a .fap stream as an MPEG-4 FBA bitstream: bits, bits/s, PSNR",
            "mpeg4face encode IN.fap -o OUT.fba [--mode predictive|dct|pca] [--fap-quant Q]\n"
            "                 [--intra-period N] [--pca-temporal T] [--pca-basis-bits B] [--vos]\n"
            "                 [--rdo-lambda L [--rdo-trellis]] [--mask-zero-faps] [--json]\n"
            "                 | --mode auto --psnr DB [--quality robust|tao]  [--fit TABLE.json]\n"
            "  --mode M          predictive (default): quantised differences, arithmetic coded\n"
            "                    dct: 16-frame segments, a DCT per FAP (docs/dct-mode.md)\n"
            "                    pca: KLT per FAP group, basis in the header (docs/pca-mode.md)\n"
            "                    auto: the mode and fap_quant with the fewest bits whose PSNR\n"
            "                    reaches --psnr DB (every mode and fap_quant tried)\n"
            "  --quality Q       the PSNR auto judges by: robust (default; the worst FAPs\n"
            "                    count) or tao (eq. 8; docs/rate-distortion.md)\n"
            "  --fap-quant Q     0..31 (default 1): each FAP's step is its QP times Q; 0 is\n"
            "                    lossless for |value| <= 1860\n"
            "  --pca-temporal T  pca only: code the components predictive (default) or dct\n"
            "  --pca-basis-bits B  pca: fraction bits of the basis sent, 1..15 (default 4)\n"
            "  --intra-period N  an intra frame at least every N frames (default 0: only the\n"
            "                    first frame and where the set of FAPs changes)\n"
            "  --rdo-lambda L  predictive (and pca's predictive components): RDO quantisation,\n"
            "                  each inter value's level by e^2/R^2 + L x bits (default 0: off;\n"
            "                  try 0.001-0.005; docs/rate-distortion.md)\n"
            "  --rdo-trellis   with --rdo-lambda: each FAP's levels and inter range chosen\n"
            "                  over the whole stream at once (fewer bits, slower)\n"
            "  --mask-zero-faps  predictive: leave the FAPs that are always 0 out of the mask\n"
            "  --vos    start with visual_object_sequence and visual_object headers (a\n"
            "           14496-2 elementary stream; decode reads both forms)\n"
            "  --fit T  leave out the FAPs that FAP Interpolation Table T derives from the rest\n"
            "           (the PSNR counts them as the decoder interpolates them)\n"
            "  --json  print one JSON object (keys bits, bits_per_second, psnr_db, ...)\n",
            mpeg4face::cli::runEncode},
    Command{"decode", "decode an MPEG-4 FBA bitstream to a .fap stream",
            "mpeg4face decode IN.fba [--fit TABLE.json] [--strict] -o OUT.fap\n"
            "  --fit T  fill the FAPs a frame lacks with FAP Interpolation Table T\n"
            "  --strict  read as 14496-2's syntax reads, as a standard decoder does: start\n"
            "            codes wherever nextbits_bytealigned() sees them, and a byte-aligned\n"
            "            0x000001 that is no start code is an error (docs/bitstream.md)\n",
            mpeg4face::cli::runDecode},
    Command{"rd", "rate-distortion of a .fap stream: every mode and fap_quant, CSV and plot",
            "mpeg4face rd IN.fap --csv OUT.csv [--plot OUT.png] [--quality robust|tao]\n"
            "  --csv F   one row per encoding: mode, fap_quant, bits, bits_per_sample,\n"
            "            bits_per_second, psnr_db (Tao et al. eq. 8: inf when a FAP is exact;\n"
            "            empty if undefined), robust_psnr_db (inf only when all are exact)\n"
            "  --quality Q  robust (default) or tao: the PSNR the plot and the printed\n"
            "               cheapest encodings at 20, 25, 30, 35 dB use\n"
            "  --plot F  PSNR against bit rate, one curve per mode (scripts/rd_plot.py, needs\n"
            "            python3-matplotlib; MPEG4FACE_RD_PLOT overrides the script's path)\n",
            mpeg4face::cli::runRd},
    Command{"fat", "Face Animation Tables from a head's named morph targets, as .wrl",
            "mpeg4face fat generate HEAD.glb|.gltf|.wfm [--feature-points CSV] [--threshold T]\n"
            "                       [--fit TABLE] -o FACE.wrl\n"
            "  morph targets named fap<N>[_<name>]@<value>, viseme<N>, expression<N>[@<i>]\n"
            "  (docs/fat.md) become the tables; the basis is the neutral face; a CANDIDE-3\n"
            "  .wfm gives its MPEG-4 animation units (scaled by the FAPU measured)\n"
            "  --feature-points CSV  bind feature points (needed for the FAPU), as info\n"
            "  --threshold T  FAPU a vertex must move to be in a table (default 0.01)\n"
            "  --fit TABLE  the FAP Interpolation Table (.json) for the Face node\n",
            mpeg4face::cli::runFat},
    Command{"export", "a face with tables (.wrl) as glTF: one morph target per interval",
            "mpeg4face export FACE.wrl -o OUT.glb|.gltf\n", mpeg4face::cli::runExport},
    Command{"apply", "animate a face (.wrl) with a FAP stream: one frame, or all as glTF",
            "mpeg4face apply FACE.wrl STREAM.fap|.fba --frame N -o OUT.obj|.glb|.gltf\n"
            "mpeg4face apply FACE.wrl STREAM.fap|.fba -o OUT.glb|.gltf\n"
            "  --frame N  the frame numbered N in the file (values held, left/right mirrored)\n"
            "  without --frame the whole stream is baked as a glTF animation\n"
            "  the face's FIT, if it has one, derives the FAPs the stream does not send\n",
            mpeg4face::cli::runApply},
    Command{"clone", "Facial Motion Cloning: a face's FAP motion onto a neutral face",
            "mpeg4face clone SOURCE TARGET [--source-feature-points CSV]\n"
            "                [--target-feature-points CSV] [--filter-support X] [--fixed-filter]\n"
            "                [--no-rigid]\n"
            "                -o OUT.glb|.gltf|.wrl\n"
            "  SOURCE  a face with tables (.wrl, or .glb/.gltf written by mpeg4face) or a glTF\n"
            "          head with shape keys named fap<N>@<value>, viseme<N>, expression<N>\n"
            "  TARGET  the neutral face to animate (.glb, .gltf, .obj, .wfm, .wrl)\n"
            "  --source-feature-points, --target-feature-points CSV  bind feature points\n"
            "  --filter-support X  antialiasing filter support, alignment units (default 0.02;\n"
            "                      0: off), used where the target is coarser than the source\n"
            "  --fixed-filter  the filter at every vertex (the paper's), not only there\n"
            "  --no-rigid  no eye, teeth, tongue and head transforms: vertex motion only\n"
            "  OUT gets the target with its FaceDefTables; a glTF also the cloned copies as\n"
            "  shape keys. Progress on stderr. docs/clone.md\n",
            mpeg4face::cli::runClone},
    Command{"fit", "FAP Interpolation Tables: from a preset, learned from streams, tried",
            "mpeg4face fit preset NAME[,NAME...] [--fmax F] -o TABLE.json\n"
            "mpeg4face fit learn STREAM.fap... [--graph NAME[,NAME...] | --table T.json]\n"
            "                    [--degree D] -o TABLE.json\n"
            "mpeg4face fit try TABLE.json STREAM.fap [--fap-quant Q]\n"
            "  presets: left-right, inner-outer-lip, eyebrow, expression, viseme\n"
            "  (docs/fit.md)\n"
            "  a TABLE read (try, encode --fit, decode --fit) is .json or a face's .wrl with\n"
            "  a FIT node\n"
            "  --fmax F     inner-outer-lip: Fmax of the upper-lip thinning (default 1024)\n"
            "  learn fits every link's functions to the streams by least squares, monomials\n"
            "  of degree 1..D (default 1) of the parent FAPs; the graph is the presets'\n"
            "  (default left-right,inner-outer-lip,eyebrow) or that of --table\n"
            "  try leaves out what the table derives, codes, decodes and interpolates:\n"
            "  bits saved and the PSNR of the derived FAPs\n",
            mpeg4face::cli::runFit},
    Command{"speak", "text with bookmarks to a FAP stream (visemes, expressions) and its audio",
            "mpeg4face speak TEXT | --text-file F -o OUT.fap|.fba [--audio OUT.wav] [--fps N]\n"
            "                [--voice V] [--transition S]\n"
            "  flite speaks TEXT into the .wav (default: OUT with .wav) and gives the phones,\n"
            "  which become visemes (FAP 1); bookmarks in the text start expressions and FAPs:\n"
            "    <FAP 2 select1 intensity1 select2 intensity2 duration_ms curve>\n"
            "    <FAP n value duration_ms curve>            (n = 3..68)\n"
            "  curve 1 linear, 2 triangular (there and back), 3 Hermite (docs/speech.md)\n"
            "  --fps N         frames per second (default 25)\n"
            "  --voice V       flite's voice: kal, kal16, awb, rms, slt\n"
            "  --transition S  the longest viseme transition, seconds (default 0.08)\n",
            mpeg4face::cli::runSpeak},
    Command{
        "check", "motion check per key and frame: stretch, flips, spikes, intersections, lips",
        "mpeg4face check HEAD.glb|.gltf|FACE.wrl [--stream S.fap|.fba ...] [--json]\n"
        "                [--max-edge-ratio R] [--flip-degrees D] [--max-flips N]\n"
        "                [--max-intersections N] [--max-spikes N] [--spike-ratio R]\n"
        "                [--spike-of-peak PCT] [--max-lip-corner PCT] [--min-lower-lip PCT]\n"
        "  every shape key (a .wrl, or a glTF file written with tables by fat generate,\n"
        "  clone or animate: every table at its outermost borders) and every frame of each\n"
        "  stream through the face's tables, against the neutral (docs/motion-check.md)\n"
        "  --max-edge-ratio R     edge-length ratio max(l/l0, l0/l), p99 of the edges a\n"
        "                         pose moves (default 2)\n"
        "  --flip-degrees D       a triangle whose normal turns more is flipped (default 120)\n"
        "  --max-flips N          flipped triangles allowed per pose, lips and lids\n"
        "                         folding where they meet not counted (default 0)\n"
        "  --max-intersections N  new self-intersections allowed per pose, lips and lids\n"
        "                         touching not counted (default 0)\n"
        "  --max-spikes N         spike vertices allowed per pose (default 0)\n"
        "  --no-own-shapes        count the flips, intersections and spikes that the head's\n"
        "                         shape keys outside the grammar (its own: a scan's ARKit\n"
        "                         shapes) make too; by default they are not counted\n"
        "  --spike-ratio R        a spike's bump |d - the mean d of its one-ring| is more than\n"
        "                         R of its local motion, the largest |d| of it and its ring\n"
        "                         (default 0.75; d: displacement from the neutral)\n"
        "  --spike-of-peak PCT    and more than PCT % of the pose's largest |d| (default 5)\n"
        "  --max-lip-corner PCT   inner lip corner outside the outer one, % of MW0 (default 2)\n"
        "  --min-lower-lip PCT    the lower lip 8.2's share of the chin 2.1 under FAP 3\n"
        "                         (default 50)\n"
        "  --json  print one JSON object (keys passed, limits, keys, frames, streams, ...)\n"
        "  exit status 0 within the limits, 4 past them; progress on stderr\n",
        mpeg4face::cli::runCheck},
    Command{"arkit",
            "ARKit heads and captures in MPEG-4: FAP keys, captures to FAP streams and back",
            "mpeg4face arkit keys HEAD.glb|.gltf [--feature-points CSV] [--no-visemes]\n"
            "                     [--no-expressions] -o OUT.glb|.gltf\n"
            "  HEAD's morph targets named as ARKit's 52 blendshapes (eyeBlinkLeft, eyeBlink_L,\n"
            "  EyeBlinkLeft, blendShape1.eyeBlinkLeft ...; some of them will do) become FAP\n"
            "  keys fap<N>_<name>@<value> (the shapes' non-negative combination measured on\n"
            "  the head, both signs where they exist; eyeball turns as poses of the eyes'\n"
            "  Transforms), and viseme and expression keys made from them with the FIT\n"
            "  presets; keys already named so are replaced. Prints the FAPs made and missed.\n"
            "  OUT is ready for 'mpeg4face fat generate'. docs/arkit.md\n"
            "  --feature-points CSV  bind feature points (needed for the FAPU), as info\n"
            "  --no-visemes, --no-expressions  leave those keys out\n"
            "mpeg4face arkit to-fap CAPTURE.csv [--face HEAD.glb] [--fps N] [--report] -o OUT.fap\n"
            "mpeg4face arkit from-fap STREAM.fap|.fba [--face HEAD.glb] -o OUT.csv\n"
            "  a Live Link Face capture (CSV of ARKit weights and head / eye angles) as a FAP\n"
            "  stream at N fps (default 25), or a stream as ARKit weights in that layout:\n"
            "  per frame the FAP values or the weights (0..1) that best reproduce the other's\n"
            "  motion of the face (bounded least squares); FAPs 23-26, 48-50 from the angles\n"
            "  --face HEAD  a head with ARKit shapes (and FAP keys) (default: the ICT sample,\n"
            "               samples/build/ict_head.glb from samples/build.sh)\n"
            "  --report  to-fap: the stream's playback against the capture through the\n"
            "            face's ARKit shapes (error, bumps, spikes; docs/arkit.md, Fidelity)\n",
            mpeg4face::cli::runArkit},
    Command{"landmarks", "a head's MPEG-4 feature points found from a template head",
            "mpeg4face landmarks HEAD [--pin FP=VERTEX|FP=MESH:VERTEX|FP=x,y,z]...\n"
            "                    [--feature-points CSV] [--template T] -o OUT.csv|OUT.glb\n"
            "  Registers a template head that has feature points onto HEAD (whatever its up\n"
            "  axis, facing, units and position) and carries its points over\n"
            "  (docs/landmarks.md). The head's own points and the CSV's are kept as pins.\n"
            "  --pin P     a point you place yourself, kept exactly and constraining the fit:\n"
            "              a vertex of the face mesh (the one with the most triangles), of a\n"
            "              named mesh, or a model-space position; repeatable\n"
            "  --template T  the head whose points are carried (default: the ICT sample,\n"
            "              samples/build/ict_head.glb from samples/build.sh)\n"
            "  -o OUT      .csv (fp,mesh,vertex,x,y,z,confidence; positions in the head's\n"
            "              model space) or .glb/.gltf (the head with its points)\n",
            mpeg4face::cli::runLandmarks},
    Command{"animate", "a head made animatable: feature points, cloned shapes, tables, check",
            "mpeg4face animate HEAD -o OUT.glb|OUT.wrl [--source S] [--template T]\n"
            "                  [--pin FP=VERTEX|FP=MESH:VERTEX|FP=x,y,z]...\n"
            "                  [--feature-points CSV] [--stream S.fap]\n"
            "  The head's feature points (found as `landmarks` finds them unless it has those\n"
            "  cloning needs; its own and the pins are kept), the FAP, viseme and expression\n"
            "  shapes of S cloned onto it, its Face Animation Tables, OUT written, and the\n"
            "  motion check on a stream; one line per step with its time. Exit status 4 when\n"
            "  a frame of the stream is past a limit of the check (OUT is written).\n"
            "  --source S    the head whose shapes are cloned (default: the ICT sample,\n"
            "                samples/build/ict_head.glb)\n"
            "  --template T  the head whose feature points are carried (default: the same)\n"
            "  --stream S    the stream checked (default: the demo's sentence,\n"
            "                samples/build/streams/hello.fap)\n",
            mpeg4face::cli::runAnimate},
    Command{"mesh2d", "the 2D mesh object: design, track, code, decode, render, talking portrait",
            "mpeg4face mesh2d design IMAGE (--uniform COLSxROWS [--topology 0..3] | --delaunay N)\n"
            "                        [--mask M.png] -o MESH.json\n"
            "mpeg4face mesh2d track (VIDEO | FRAME_DIR) --mesh MESH.json -o SEQ.json\n"
            "mpeg4face mesh2d encode SEQ.json -o OUT.m2d [--step S]\n"
            "mpeg4face mesh2d decode IN.m2d -o SEQ.json\n"
            "mpeg4face mesh2d render (IMAGE | VIDEO | FRAME_DIR) SEQ.json -o OUT.mp4|DIR\n"
            "                        [--audio WAV] [--fps N]\n"
            "mpeg4face mesh2d portrait IMAGE --feature-points FP.csv STREAM.fap|.fba\n"
            "                          -o OUT.mp4|DIR [--audio WAV] [--step S] [--m2d OUT.m2d]\n"
            "mpeg4face mesh2d portrait IMAGE --feature-points FP.csv --tracks TRACKS.csv\n"
            "                          -o OUT.mp4|DIR [--audio WAV] [--step S] [--m2d OUT.m2d]\n"
            "                          [--fps N]\n"
            "  design: a uniform mesh of COLSxROWS cells (topology code of Fig. 20, default 0)\n"
            "          or a Delaunay mesh of about N nodes on corner points (inside the mask's\n"
            "          largest region with --mask)\n"
            "  track: the mesh (on the first frame) followed by optical flow, no fold-overs\n"
            "  encode: geometry and motion coded, motion in steps of S pixels (default 0.5);\n"
            "          prints the bits, bits per node of the intra plane and per node and frame\n"
            "  render: the image (a video's or a folder's first frame: the intra plane's)\n"
            "          warped by each plane; PNG frames into DIR, or an MP4 (ffmpeg)\n"
            "          with the audio muxed in; --fps N (default 25)\n"
            "  portrait: a Delaunay mesh anchored on the feature points (CSV rows fp,x,y in\n"
            "          pixels), moved by the stream's FAPs in FAPU, or along --tracks (rows\n"
            "          frame,fp,x,y: a 3D face's motion projected), coded (--m2d keeps the\n"
            "          bitstream), decoded and rendered\n"
            "  sequences are JSON (docs/mesh2d.md); progress on stderr\n",
            mpeg4face::cli::runMesh2d},
};

void printHelp(std::FILE* out) {
  std::fprintf(out,
               "mpeg4face %s: MPEG-4 face animation tools\n\nusage: mpeg4face COMMAND [ARGS]\n\n"
               "commands:\n",
               MPEG4FACE_VERSION);
  for (const Command& c : kCommands) std::fprintf(out, "  %-8s %s\n", c.name, c.summary);
  std::fprintf(out, "\n'mpeg4face COMMAND --help' shows a command's arguments.\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    printHelp(stderr);
    return 2;
  }
  const std::string_view name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    printHelp(stdout);
    return 0;
  }
  if (name == "--version") {
    std::printf("mpeg4face %s\n", MPEG4FACE_VERSION);
    return 0;
  }
  for (const Command& c : kCommands) {
    if (name != c.name) continue;
    std::vector<std::string> args(argv + 2, argv + argc);
    for (const std::string& a : args) {
      if (a == "--help" || a == "-h") {
        std::printf("usage: %s", c.usage);
        return 0;
      }
    }
    try {
      return c.run(args);
    } catch (const mpeg4face::cli::UsageError& e) {
      std::fprintf(stderr, "mpeg4face %s: %s\nusage: %s", c.name, e.what(), c.usage);
      return 2;
    } catch (const mpeg4face::Error& e) {
      std::fprintf(stderr, "mpeg4face %s: error: %s\n", c.name, e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mpeg4face %s: internal error: %s\n", c.name, e.what());
      return 3;
    }
  }
  std::fprintf(stderr, "mpeg4face: unknown command '%s'\n\n", argv[1]);
  printHelp(stderr);
  return 2;
}
