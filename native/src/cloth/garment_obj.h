// Artist-made garments from Wavefront OBJ files, fitted onto Drape's body by ring-space
// retargeting: each garment vertex is bound to the feature rings (body/body_model.h) of a body
// like the one the garment was made for, then re-evaluated on the target body's rings, so the
// garment follows the target's height, girths and arm angle. Method, defaults and the measured
// fit: docs/garment-obj.md.
//
// Never throws, never asserts: bad input returns false with a message and leaves outputs untouched.
#pragma once

#include "body/body_model.h"
#include "cloth/garment_templates.h"
#include "common/math.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace drape {

// A triangle mesh as read from a file: positions in the file's own units and frame. Every vertex
// is used by at least one triangle (unused ones are dropped when parsing), so every particle of a
// garment built from it gets mass.
struct ObjMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;  // triangles, winding as in the file
};

// Parses OBJ text: `v x y z [w ...]` (numbers after z are ignored), `f` corners in the forms v,
// v/vt, v//vn and v/vt/vn with positive or negative (relative) indices, polygons of 3 or more
// corners (quads split along their shorter diagonal, larger polygons fanned from the first
// corner). vt, vn, vp, o, g, s, l, p, usemtl, mtllib, comments, blank lines and CRLF endings are
// ignored; any other statement is an error. Errors name the 1-based line.
bool parseObj(const char* text, size_t size, ObjMesh& out, std::string& err);
// io_error (optional) tells a file that could not be read (missing, a directory) from one that
// is not valid OBJ.
bool readObjFile(const std::string& path, ObjMesh& out, std::string& err, bool* io_error = nullptr);

// Which way the character in the file faces (+Y is up in both).
enum class ObjFacing : int {
  PlusZ = 0,   // MakeHuman, Blender's glTF export: rotated 180 degrees about Y into Drape's frame
  MinusZ = 1,  // already Drape's orientation (subject's right = +X)
};

struct ObjFitParams {
  // Metres per file unit; 0 = the largest of 1, 0.1, 0.01, 0.001 that brings the mesh's largest
  // extent to 2.5 m or less (MakeHuman's decimetres give 0.1).
  float unit_scale = 0.0f;
  ObjFacing facing = ObjFacing::PlusZ;
  // The source body in the file's frame, metres after scaling: its floor (sole) height and the z of
  // its vertical axis (front-back centre of the torso). MakeHuman: feet at -8.2 dm; the female
  // proxy's torso cross-sections are centred at z = +0.2..+0.6 dm from hip to chest.
  float source_floor_y = -0.82f;
  float source_axis_z = 0.05f;
  // The body the garment was made for. MakeHuman's default base mesh (hm08) is 1.60 m tall. Its
  // weight is the enclosed volume of the shipped body proxy body_proxy_female1605.obj (mouth part
  // stripped), 0.045844 m^3 as parseObj triangulates it, times 1010 kg/m^3 (whole-body density):
  // 46.3 kg. tests/native/test_garment_obj.cpp recomputes it from the file. Some garments were
  // made for other bodies (male_casualsuit02: about 1.76 m, see docs/garment-obj.md).
  float source_height_m = 1.60f;
  float source_weight_kg = 46.3f;
  // The source body's pose, restPose(source shape, source_arm_down_deg) with the forearms and
  // hands bent forward at the elbow by source_elbow_flex_deg and the legs turned outward about the
  // hips by source_leg_spread_deg. MakeHuman's A-pose, measured on its body proxy: upper arms
  // about 50 degrees below horizontal, elbows bent about 45 degrees forward, legs about 6 degrees
  // apart.
  float source_arm_down_deg = 50.0f;
  float source_elbow_flex_deg = 45.0f;
  float source_leg_spread_deg = 6.0f;
  // Width of the soft choice of binding segment: segments whose distance to the vertex is within a
  // few widths of the nearest blend in, so neighbouring vertices bound to different chains (armpit,
  // crotch, neck) do not tear apart on the target. 0 = the nearest segment alone.
  float blend_m = 0.015f;
};

// Step 1 alone: the file's mesh scaled, rotated and translated into Drape's frame so that it sits
// on the source body standing in the source pose (feet at y = 0, torso axis on the rest pose's
// pelvis). For comparison and for callers with their own fit.
bool placeObjOnSourceBody(const ObjMesh& mesh, const ObjFitParams& p, std::vector<Vec3>& out,
                          std::string& err);

// Fits the garment onto target_rest, a BodyModel updated with restPose(target shape) (any arm
// angle). The source body is built with the target's ring layout (ring points and rings per
// segment, recovered from the target's ring counts; BodyModel does not expose its params, so the
// fixed-shoulder-junction switch is assumed off). Output: positions in metres around
// target_rest, the file's triangles (the rotation is proper, so their winding is kept), and
// pins: for every connected component, the highest boundary loop that winds once around the
// Torso or Head chain (waistband, collar) is pinned to its nearest rings. Components without such
// a loop (decorations, a jacket whose neckline runs into its front opening) are left free.
bool fitObjGarment(const ObjMesh& mesh, const ObjFitParams& p, const BodyModel& target_rest,
                   GarmentMesh& out, std::string& err);

}  // namespace drape
